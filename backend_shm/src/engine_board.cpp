// The host's engine board (the protocol is described in engine_board.hpp).
#include "horus/shm/engine_board.hpp"

#include "horus/detail/process.hpp"

#include <fcntl.h>
#include <linux/futex.h>
#include <signal.h>
#include <sys/file.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <ctime>
#include <mutex>

namespace horus::shm {

namespace {
constexpr std::size_t kBoardBytes = sizeof(EngineBoardHeader) + sizeof(EngineSlot) * kEngineSlots;

EngineSlot* slots_at(void* base) noexcept {
  return reinterpret_cast<EngineSlot*>(static_cast<std::byte*>(base) + sizeof(EngineBoardHeader));
}
EngineBoardHeader* header_of(EngineSlot* slots) noexcept {
  return reinterpret_cast<EngineBoardHeader*>(reinterpret_cast<std::byte*>(slots) - sizeof(EngineBoardHeader));
}

// Maps an open board file, growing a new (empty) one to its size first; null on failure.
void* map_board(int fd) noexcept {
  struct stat st{};
  if (::fstat(fd, &st) != 0) return nullptr;
  if (static_cast<std::size_t>(st.st_size) < kBoardBytes && ::ftruncate(fd, static_cast<off_t>(kBoardBytes)) != 0)
    return nullptr;
  void* p = ::mmap(nullptr, kBoardBytes, PROT_READ | PROT_WRITE, MAP_SHARED, fd, 0);
  return p == MAP_FAILED ? nullptr : p;
}

void futex_wake(std::atomic<std::uint32_t>& word) noexcept {
  ::syscall(SYS_futex, &word, FUTEX_WAKE, 1, nullptr, nullptr, 0);
}

void set_bit(EngineSlot& s, std::uint32_t bit) noexcept {
  bit &= kEngineBits - 1;
  s.pending[bit / 64].fetch_or(std::uint64_t{1} << (bit % 64), std::memory_order_release);
  s.summary.fetch_or(std::uint64_t{1} << (bit / 64), std::memory_order_release);
}

void bump_and_wake(EngineSlot& s) noexcept {
  s.word.fetch_add(1, std::memory_order_acq_rel);
  futex_wake(s.word);
}

bool owner_alive(std::uint64_t owner) noexcept {
  const auto pid = static_cast<pid_t>(owner >> 32);
  return pid > 0 && (::kill(pid, 0) == 0 || errno != ESRCH);
}

// A publisher's mapping of the current board (never unmapped: other threads may hold it).
struct ProcessBoard {
  static constexpr horus::detail::PartSpec kPart{"engine board", horus::detail::PartLifetime::Process,
                                                 "a ring may ring during static destruction"};
  std::mutex mutex;
  std::atomic<EngineSlot*> slots{nullptr};
  ino_t ino = 0;  // the file `slots` maps
  std::string name;
};
ProcessBoard& process_board() { return horus::detail::Process::part<ProcessBoard>(); }

// Maps the board that exists now (a new one if the name was unlinked and created anew since).
EngineSlot* remap_board(EngineSlot* stale) noexcept {
  ProcessBoard& pb = process_board();
  std::lock_guard lock(pb.mutex);
  if (EngineSlot* cur = pb.slots.load(std::memory_order_acquire); cur != stale) return cur;  // another thread did
  try {
    if (pb.name.empty()) {
      auto ns = shm_namespace();
      if (!ns) return nullptr;
      pb.name = engine_board_name(*ns);
    }
  } catch (...) {
    return nullptr;
  }
  const int fd = ::shm_open(pb.name.c_str(), O_RDWR | O_CLOEXEC, 0);
  if (fd < 0) return nullptr;  // no engine on this host: nothing to wake
  const auto mode = shm_mode_from_environment();
  if (!mode || foreign_file(fd, *mode, pb.name)) {  // planted by another user: not ours to ring
    ::close(fd);
    return nullptr;
  }
  struct stat st{};
  void* p = nullptr;
  if (::fstat(fd, &st) == 0 && static_cast<std::size_t>(st.st_size) >= kBoardBytes)
    p = ::mmap(nullptr, kBoardBytes, PROT_READ | PROT_WRITE, MAP_SHARED, fd, 0);
  ::close(fd);
  if (p == nullptr || p == MAP_FAILED) return nullptr;
  pb.ino = st.st_ino;
  pb.slots.store(slots_at(p), std::memory_order_release);
  return slots_at(p);
}

bool notify_in(EngineSlot* slots, std::uint64_t forward) noexcept {
  if (slots == nullptr) return false;
  const auto slot = static_cast<std::uint32_t>(forward >> 48) - 1;
  if (slot >= kEngineSlots) return false;
  EngineSlot& s = slots[slot];
  const std::uint64_t owner = s.owner.load(std::memory_order_acquire);
  if (owner == 0 || static_cast<std::uint32_t>(owner) != static_cast<std::uint32_t>(forward)) return false;
  set_bit(s, static_cast<std::uint32_t>(forward >> 32) & 0xffff);
  bump_and_wake(s);
  return true;
}
}  // namespace

std::string engine_board_name(const std::string& ns) { return "/horus." + ns + "@engines.v1"; }

void note_bridge_released() noexcept {
  if (EngineSlot* slots = process_board().slots.load(std::memory_order_acquire))
    header_of(slots)->released.fetch_add(1, std::memory_order_release);
}

std::uint64_t bridge_releases() noexcept {
  EngineSlot* slots = process_board().slots.load(std::memory_order_acquire);
  return slots == nullptr ? 0 : header_of(slots)->released.load(std::memory_order_acquire);
}

bool EngineBell::admit_link(std::size_t bytes, double ns_per_byte, std::int64_t tolerance_ns) noexcept {
  if (slot_ == nullptr) return true;
  const std::int64_t now =
      std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now().time_since_epoch()).count();
  return admit_on_link(header_of(slot_ - index_)->link_tat, now,
                       static_cast<std::int64_t>(static_cast<double>(bytes) * ns_per_byte), tolerance_ns);
}

bool notify_engine(std::uint64_t forward) noexcept {
  EngineSlot* slots = process_board().slots.load(std::memory_order_acquire);
  if (notify_in(slots, forward)) return true;
  // Not mapped yet, or a board that was unlinked and made anew: look at the current one.
  return notify_in(remap_board(slots), forward);
}

std::expected<EngineBell, SegmentError> EngineBell::claim(const std::string& ns, mode_t mode) {
  const std::string name = engine_board_name(ns);
  auto io = [&](const char* what) {
    return std::unexpected(SegmentError{SegmentError::Kind::Io, std::string(what) + " /dev/shm" + name + ": " +
                                                                    std::strerror(errno)});
  };
  for (int attempt = 0; attempt < 100; ++attempt) {
    const int fd = ::shm_open(name.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, mode);
    if (fd < 0) return io("cannot open the network engines' board");
    if (auto why = foreign_file(fd, mode, name)) {  // before its lock: a planted file may be held locked
      ::close(fd);
      return std::unexpected(SegmentError{SegmentError::Kind::Permission, std::move(*why)});
    }
    if (::flock(fd, LOCK_EX) != 0) {
      ::close(fd);
      return io("cannot lock the network engines' board");
    }
    struct stat st{};
    if (::fstat(fd, &st) != 0 || st.st_nlink == 0) {  // unlinked by its last engine meanwhile: again
      ::flock(fd, LOCK_UN);
      ::close(fd);
      continue;
    }

    ProcessBoard& pb = process_board();
    std::unique_lock board_lock(pb.mutex);
    // The board this process maps already (an engine of this process, or a publisher's ring).
    EngineSlot* const mapped = pb.slots.load(std::memory_order_acquire);
    void* base = mapped != nullptr && pb.ino == st.st_ino ? static_cast<void*>(header_of(mapped)) : map_board(fd);
    if (base == nullptr) {
      auto err = io("cannot map the network engines' board");
      ::flock(fd, LOCK_UN);
      ::close(fd);
      return err;
    }
    EngineSlot* slots = slots_at(base);
    for (std::uint32_t i = 0; i < kEngineSlots; ++i) {
      EngineSlot& s = slots[i];
      const std::uint64_t owner = s.owner.load(std::memory_order_acquire);
      if (owner != 0 && owner_alive(owner)) continue;
      const std::uint32_t gen = s.generation.fetch_add(1, std::memory_order_relaxed) + 1;
      s.summary.store(0, std::memory_order_relaxed);
      for (auto& p : s.pending) p.store(0, std::memory_order_relaxed);
      s.owner.store((static_cast<std::uint64_t>(::getpid()) << 32) | gen, std::memory_order_release);
      ::flock(fd, LOCK_UN);
      EngineBell bell;
      bell.fd_ = fd;
      bell.base_ = base;
      bell.slot_ = &s;
      bell.index_ = i;
      bell.generation_ = gen;
      bell.name_ = name;
      // This process's publishers ring through the same mapping from now on (never unmapped).
      pb.ino = st.st_ino;
      if (pb.name.empty()) pb.name = name;
      pb.slots.store(slots, std::memory_order_release);
      return bell;
    }
    ::flock(fd, LOCK_UN);
    if (mapped == nullptr || base != static_cast<void*>(header_of(mapped))) ::munmap(base, kBoardBytes);
    ::close(fd);
    return std::unexpected(SegmentError{SegmentError::Kind::LimitReached,
                                        "every one of the " + std::to_string(kEngineSlots) +
                                            " network engine slots of /dev/shm" + name +
                                            " is held by a running process (one per process and network backend)"});
  }
  return std::unexpected(SegmentError{SegmentError::Kind::Io, "/dev/shm" + name + " kept being replaced"});
}

EngineBell& EngineBell::operator=(EngineBell&& o) noexcept {
  if (this != &o) {
    release();
    fd_ = std::exchange(o.fd_, -1);
    base_ = std::exchange(o.base_, nullptr);
    slot_ = std::exchange(o.slot_, nullptr);
    index_ = o.index_;
    generation_ = o.generation_;
    name_ = std::move(o.name_);
  }
  return *this;
}

EngineBell::~EngineBell() { release(); }

void EngineBell::release() noexcept {
  if (slot_ == nullptr) return;
  const bool locked = ::flock(fd_, LOCK_EX) == 0;
  slot_->owner.store(0, std::memory_order_release);
  bool empty = true;
  for (std::uint32_t i = 0; i < kEngineSlots && empty; ++i) {
    const std::uint64_t owner = slots_at(base_)[i].owner.load(std::memory_order_acquire);
    if (owner != 0 && owner_alive(owner)) empty = false;
  }
  struct stat by_fd{}, by_name{};
  if (locked && empty && ::fstat(fd_, &by_fd) == 0 && by_fd.st_nlink != 0 &&
      ::stat(("/dev/shm" + name_).c_str(), &by_name) == 0 && by_fd.st_ino == by_name.st_ino)
    ::shm_unlink(name_.c_str());
  if (locked) ::flock(fd_, LOCK_UN);
  // The mapping stays (the process board's): publishers may ring through it (remap on mismatch).
  ::close(fd_);
  fd_ = -1;
  slot_ = nullptr;
}

void EngineBell::notify(std::uint32_t bit) noexcept {
  set_bit(*slot_, bit);
  bump_and_wake(*slot_);
}

void EngineBell::poke() noexcept { bump_and_wake(*slot_); }

void EngineBell::wait(std::uint32_t seen, std::chrono::steady_clock::time_point deadline) noexcept {
  timespec ts{};
  const bool timed = deadline != std::chrono::steady_clock::time_point::max();
  if (timed) {
    const auto ns = std::chrono::duration_cast<std::chrono::nanoseconds>(deadline.time_since_epoch()).count();
    ts = timespec{static_cast<time_t>(ns / 1'000'000'000), static_cast<long>(ns % 1'000'000'000)};
  }
  ::syscall(SYS_futex, &slot_->word, FUTEX_WAIT_BITSET, seen, timed ? &ts : nullptr, nullptr, FUTEX_BITSET_MATCH_ANY);
}

}  // namespace horus::shm
