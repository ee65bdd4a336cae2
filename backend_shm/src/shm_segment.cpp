// A topic's ring in a POSIX shared-memory segment (shm_segment.hpp): the namespace and mode
// rules, process liveness, opening (create, join, reclaim, or refuse with both sides named),
// reaping dead participants, detaching, the read-only view, listing and cleaning segments. The
// bridge claim and its hand-over are in segment_bridge.cpp.
#include "horus/shm/shm_segment.hpp"

#include <dirent.h>
#include <fcntl.h>
#include <signal.h>
#include <sys/file.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <new>
#include <set>
#include <sstream>
#include <thread>
#include <utility>

#include "horus/detail/process.hpp"
#include "segment_internal.hpp"

namespace horus::shm {

namespace {

constexpr std::uint64_t kPage = 4096;
constexpr auto kLockTimeout = std::chrono::seconds(5);

}  // namespace

namespace detail {

bool lock_with_deadline(int fd) {
  const auto deadline = std::chrono::steady_clock::now() + kLockTimeout;
  for (;;) {
    if (::flock(fd, LOCK_EX | LOCK_NB) == 0) return true;
    if (errno != EWOULDBLOCK && errno != EINTR) return false;
    if (std::chrono::steady_clock::now() >= deadline) return false;
    std::this_thread::sleep_for(std::chrono::microseconds(200));
  }
}

std::uint64_t now_unix_ns() {
  return static_cast<std::uint64_t>(
      std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::system_clock::now().time_since_epoch())
          .count());
}

}  // namespace detail

namespace {

std::uint64_t round_up_to(std::uint64_t v, std::uint64_t a) { return (v + a - 1) / a * a; }

std::string errno_text(int err) { return std::strerror(err); }

SegmentError io_error(const std::string& what, const std::string& name, int err) {
  return {SegmentError::Kind::Io, what + " shared-memory segment /dev/shm" + name + ": " + errno_text(err)};
}

struct FdLock {
  int fd;
  ~FdLock() { ::flock(fd, LOCK_UN); }
};

SegmentHeader* header_at(void* base) { return std::launder(reinterpret_cast<SegmentHeader*>(base)); }

// True when shm name `name` still names the file open as fd (not unlinked, not replaced by a
// newer segment of the same name): only then may we unlink the name.
bool name_is_this_file(int fd, const std::string& name) {
  struct stat by_fd{}, by_name{};
  if (::fstat(fd, &by_fd) != 0 || by_fd.st_nlink == 0) return false;
  if (::stat(("/dev/shm" + name).c_str(), &by_name) != 0) return false;
  return by_fd.st_dev == by_name.st_dev && by_fd.st_ino == by_name.st_ino;
}

// A header's ring must be where this version puts it, inside the file, and agree with it.
// Where the ring starts: after the header and the type's signature, on a page.
std::uint64_t ring_offset_for(std::uint64_t signature_size) noexcept {
  return round_up_to(sizeof(SegmentHeader) + signature_size, kPage);
}

bool ring_consistent(const SegmentHeader& h, const void* base, std::size_t size) {
  if (h.signature_offset != sizeof(SegmentHeader) || h.signature_size > kMaxSignature) return false;
  const std::uint64_t expected_offset = ring_offset_for(h.signature_size);
  if (h.ring_offset != expected_offset || h.ring_offset >= size || h.total_size > size) return false;
  const auto* ring_base = static_cast<const std::byte*>(base) + h.ring_offset;
  if (Ring::validate(ring_base, size - h.ring_offset)) return false;
  const auto* rh = reinterpret_cast<const RingHeader*>(ring_base);
  if (rh->payload_size != h.payload_size || rh->capacity != h.capacity || rh->type_hash != h.type_hash) return false;
  if (h.pool_offset == 0) return h.pool_slot_bytes == 0;
  const std::uint64_t expected_pool =
      round_up_to(h.ring_offset + Ring::required_size({h.capacity, h.payload_size, h.type_hash}), kPage);
  if (h.pool_offset != expected_pool || h.pool_offset >= size) return false;
  const auto* pool_base = static_cast<const std::byte*>(base) + h.pool_offset;
  if (Pool::validate(pool_base, size - h.pool_offset)) return false;
  const auto* ph = reinterpret_cast<const PoolHeader*>(pool_base);
  return ph->slot_bytes == h.pool_slot_bytes && ph->slots_per_lane == h.pool_slots_per_lane;
}

bool any_participant_alive(const SegmentHeader& h) {
  for (const auto& e : h.participants) {
    const auto pid = static_cast<pid_t>(e.pid.load(std::memory_order_acquire));
    if (pid != 0 && process_alive(pid, e.start_time.load(std::memory_order_relaxed))) return true;
  }
  return false;
}

bool valid_namespace_char(char c) {
  return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' || c == '-';
}

std::string describe_type(std::string_view name, std::uint64_t hash, std::uint32_t payload, bool serialized,
                          std::uint64_t pool_bytes) {
  char buf[64];
  std::snprintf(buf, sizeof(buf), "%016llx", static_cast<unsigned long long>(hash));
  std::string how;
  if (pool_bytes != 0) how = "large data in a pool, slots of " + std::to_string(pool_bytes) + " bytes";
  else if (serialized) how = "serialized, slots of " + std::to_string(max_serialized_size(payload)) + " bytes";
  else how = std::to_string(payload) + " bytes";
  return std::string(name) + " (layout hash " + buf + ", " + how + ")";
}

std::string describe_scope(std::uint32_t scope, std::string_view transport) {
  if (scope == static_cast<std::uint32_t>(SegmentScope::Fleet)) return "fleet (" + std::string(transport) + ")";
  if (scope == static_cast<std::uint32_t>(SegmentScope::Host)) return "host (shared memory)";
  return "unknown (" + std::to_string(scope) + ")";
}

}  // namespace

std::expected<std::string, SegmentError> shm_namespace() { return shm_namespace(horus::detail::Process::get().environment()->shm_namespace); }

std::expected<std::string, SegmentError> shm_namespace(std::string_view ns) {
  if (ns.empty()) return "u" + std::to_string(::getuid());
  if (ns.size() > 64)
    return std::unexpected(SegmentError{SegmentError::Kind::InvalidName,
                                        "HORUS_NAMESPACE '" + std::string(ns) + "' has " + std::to_string(ns.size()) +
                                            " characters; expected 1 to 64 letters, digits, '_' or '-'"});
  for (char c : ns)
    if (!valid_namespace_char(c))
      return std::unexpected(SegmentError{SegmentError::Kind::InvalidName,
                                          "HORUS_NAMESPACE '" + std::string(ns) + "' contains '" + std::string(1, c) +
                                              "'; expected 1 to 64 letters, digits, '_' or '-'"});
  return std::string(ns);
}

std::expected<mode_t, SegmentError> shm_mode_from_environment() { return shm_mode(horus::detail::Process::get().environment()->shm_mode); }

std::expected<mode_t, SegmentError> shm_mode(std::string_view v) {
  if (v.empty()) return static_cast<mode_t>(0600);
  unsigned mode = 0;
  bool ok = v.size() <= 4;
  for (char c : v) {
    if (c < '0' || c > '7') ok = false;
    else mode = mode * 8 + static_cast<unsigned>(c - '0');
  }
  // Only read and write bits make sense for shared memory; the owner needs both.
  if (!ok || (mode & ~0666u) != 0 || (mode & 0600u) != 0600u)
    return std::unexpected(SegmentError{SegmentError::Kind::InvalidName,
                                        "HORUS_SHM_MODE='" + std::string(v) +
                                            "': expected an octal mode of read/write bits that keeps the owner's "
                                            "(0600, 0640, 0660, 0666)"});
  return static_cast<mode_t>(mode);
}

std::string segment_name(std::string_view ns, std::string_view topic) {
  return "/horus." + std::string(ns) + "." + std::string(topic);
}

// ---------------------------------------------------------------------------

ShmSegment::ShmSegment(ShmSegment&& o) noexcept { *this = std::move(o); }

ShmSegment& ShmSegment::operator=(ShmSegment&& o) noexcept {
  if (this != &o) {
    detach();
    fd_ = std::exchange(o.fd_, -1);
    base_ = std::exchange(o.base_, nullptr);
    size_ = std::exchange(o.size_, 0);
    header_ = std::exchange(o.header_, nullptr);
    ring_ = o.ring_;
    pool_ = o.pool_;
    name_ = std::move(o.name_);
    slot_ = std::exchange(o.slot_, kMaxParticipants);
    owner_ = std::exchange(o.owner_, 0);
  }
  return *this;
}

ShmSegment::~ShmSegment() { detach(); }

// Where the parts of a new segment go: the ring after the header and the type's signature, the
// pool (large data) after the ring, each on a page.
struct ShmSegment::Layout {
  RingConfig ring;
  PoolConfig pool;
  bool pooled = false;
  std::uint64_t ring_offset = 0;
  std::uint64_t pool_offset = 0;
  std::uint64_t total = 0;
};

namespace {

SegmentError invalid_name(std::string text) { return {SegmentError::Kind::InvalidName, std::move(text)}; }

// The segment's file, created (with exactly `mode`, whatever the umask) or opened; -1 when it was
// unlinked between the two attempts (start again).
std::expected<int, SegmentError> open_file(const std::string& name, mode_t mode) {
  int fd = ::shm_open(name.c_str(), O_RDWR | O_CREAT | O_EXCL, mode);
  if (fd >= 0) {
    ::fchmod(fd, mode);
    return fd;
  }
  if (errno == EEXIST) {
    fd = ::shm_open(name.c_str(), O_RDWR, 0);
    if (fd >= 0) return fd;
    if (errno == ENOENT) return -1;
  }
  const int err = errno;
  if (err == EACCES)
    return std::unexpected(SegmentError{
        SegmentError::Kind::Permission,
        "cannot open shared-memory segment /dev/shm" + name +
            ": permission denied (it belongs to another user, or its mode does not admit you; use another "
            "HORUS_NAMESPACE, or have its owner widen the mode)"});
  return std::unexpected(io_error("cannot open", name, err));
}

// What refuses to open a live segment whose header is `h` with `spec`: another type, scope or
// transport, or a slot size or capacity the open requires and the segment does not have.
std::optional<SegmentError> mismatch(const SegmentHeader& h, std::string_view topic, const SegmentSpec& spec,
                                     bool pooled) {
  const bool serialized = h.serialized != 0;
  const std::string_view have_type(h.type_name, strnlen(h.type_name, kMaxTypeName));
  if (have_type != spec.type_name || h.type_hash != spec.type_hash || serialized != spec.serialized ||
      (!spec.serialized && h.payload_size != spec.payload_size) || (h.pool_offset != 0) != pooled)
    return SegmentError{SegmentError::Kind::TypeMismatch,
                        "topic '" + std::string(topic) + "' carries " +
                            describe_type(have_type, h.type_hash, h.payload_size, serialized, h.pool_slot_bytes) +
                            "; cannot open it as " +
                            describe_type(spec.type_name, spec.type_hash, spec.payload_size, spec.serialized,
                                          spec.pool_slot_bytes)};
  const std::string_view have_transport(h.transport, strnlen(h.transport, kMaxTransportName));
  if (h.scope != static_cast<std::uint32_t>(spec.scope) || have_transport != spec.transport)
    return SegmentError{SegmentError::Kind::ConfigMismatch,
                        "topic '" + std::string(topic) + "' is open on this host with scope " +
                            describe_scope(h.scope, have_transport) + "; cannot open it with scope " +
                            describe_scope(static_cast<std::uint32_t>(spec.scope), spec.transport) +
                            " (a topic has one scope on a host: open it with the same scope and backend)"};
  if (pooled && spec.pool_required && h.pool_slot_bytes != spec.pool_slot_bytes)
    return SegmentError{SegmentError::Kind::ConfigMismatch,
                        "topic '" + std::string(topic) + "' exists with pool slots of " +
                            std::to_string(h.pool_slot_bytes) + " bytes (slot_size); cannot open it with slot_size " +
                            std::to_string(spec.pool_slot_bytes)};
  if (spec.serialized && spec.payload_required && h.payload_size != spec.payload_size)
    return SegmentError{SegmentError::Kind::ConfigMismatch,
                        "topic '" + std::string(topic) + "' exists with slot_size " +
                            std::to_string(max_serialized_size(h.payload_size)) + "; cannot open it with slot_size " +
                            std::to_string(max_serialized_size(spec.payload_size))};
  if (spec.capacity_required && h.capacity != spec.capacity)
    return SegmentError{SegmentError::Kind::ConfigMismatch,
                        "topic '" + std::string(topic) + "' exists with capacity " + std::to_string(h.capacity) +
                            "; cannot open it with capacity " + std::to_string(spec.capacity)};
  return std::nullopt;
}

}  // namespace

std::expected<ShmSegment::Layout, SegmentError> ShmSegment::layout_of(std::string_view topic, const SegmentSpec& spec) {
  if (topic.empty() || topic.find('/') != std::string_view::npos)
    return std::unexpected(invalid_name("topic name '" + std::string(topic) + "' cannot name a shared-memory segment"));
  if (spec.type_name.size() > kMaxTypeName)
    return std::unexpected(invalid_name("type name '" + std::string(spec.type_name) + "' is longer than " +
                                        std::to_string(kMaxTypeName) + " characters"));
  Layout l;
  l.ring = RingConfig{spec.capacity, spec.payload_size, spec.type_hash};
  if (auto err = Ring::check_config(l.ring)) return std::unexpected(SegmentError{SegmentError::Kind::ConfigMismatch, *err});
  if (spec.transport.size() > kMaxTransportName)
    return std::unexpected(invalid_name("transport name '" + std::string(spec.transport) + "' is longer than " +
                                        std::to_string(kMaxTransportName) + " characters"));
  l.pooled = spec.pool_slot_bytes != 0;
  l.pool = PoolConfig{spec.pool_slot_bytes, spec.pool_slots_per_lane};
  if (l.pooled) {
    if (auto err = Pool::check_config(l.pool))
      return std::unexpected(SegmentError{SegmentError::Kind::ConfigMismatch, *err});
  }
  if (spec.signature.size() > kMaxSignature)
    return std::unexpected(invalid_name("the signature of type '" + std::string(spec.type_name) + "' has " +
                                        std::to_string(spec.signature.size()) + " bytes; at most " +
                                        std::to_string(kMaxSignature) + " fit a segment"));
  l.ring_offset = ring_offset_for(spec.signature.size());
  l.pool_offset = l.pooled ? round_up_to(l.ring_offset + Ring::required_size(l.ring), kPage) : 0;
  l.total = l.pooled ? l.pool_offset + Pool::required_size(l.pool) : l.ring_offset + Ring::required_size(l.ring);
  return l;
}

std::expected<bool, SegmentError> ShmSegment::attach_locked(std::string_view topic, const SegmentSpec& spec, bool pooled,
                                                            std::size_t size) {
  if (size == 0 || size < sizeof(SegmentHeader)) return true;  // new, or its creator died before sizing it
  void* p = ::mmap(nullptr, size, PROT_READ | PROT_WRITE, MAP_SHARED, fd_, 0);
  if (p == MAP_FAILED) return std::unexpected(io_error("cannot map", name_, errno));
  base_ = p;
  size_ = size;
  header_ = header_at(p);
  const SegmentHeader& h = *header_;
  bool format = false;
  if (h.magic == kSegmentMagic && h.layout_version != 0 && h.layout_version != kSegmentVersion) {
    return std::unexpected(SegmentError{
        SegmentError::Kind::TypeMismatch,
        "shared-memory segment /dev/shm" + name_ + " has layout version " + std::to_string(h.layout_version) +
            "; this horus uses version " + std::to_string(kSegmentVersion) + " (stop the older processes)"});
  } else if (h.magic != kSegmentMagic || h.ready.load(std::memory_order_acquire) != 1) {
    format = true;  // unfinished: its creator died while formatting it (we hold the lock)
  } else if (!ring_consistent(h, p, size)) {
    if (any_participant_alive(h))
      return std::unexpected(SegmentError{SegmentError::Kind::Io,
                                          "shared-memory segment /dev/shm" + name_ +
                                              " has a corrupt header (its ring does not match it) and live "
                                              "users; stop them, or remove it with horus clean"});
    format = true;  // damaged and abandoned: reclaim it
  } else {
    ring_ = Ring::attach(static_cast<std::byte*>(p) + h.ring_offset);
    if (h.pool_offset != 0) pool_ = Pool::attach(static_cast<std::byte*>(p) + h.pool_offset);
    reap_dead_locked();
    if (live_participants() == 0) {
      format = true;  // every user is gone: reclaim it
    } else if (auto refused = mismatch(h, topic, spec, pooled)) {
      return std::unexpected(std::move(*refused));
    }
  }
  if (format) {
    ::munmap(p, size);
    base_ = nullptr;
    header_ = nullptr;
    ring_ = Ring();
    pool_ = Pool();
  }
  return format;
}

std::expected<void, SegmentError> ShmSegment::format_locked(const SegmentSpec& spec, const Layout& l, pid_t self) {
  // Zero everything (a shrink to 0 discards old contents), then size and fill it.
  if (::ftruncate(fd_, 0) != 0 || ::ftruncate(fd_, static_cast<off_t>(l.total)) != 0)
    return std::unexpected(io_error("cannot size", name_, errno));
  void* p = ::mmap(nullptr, l.total, PROT_READ | PROT_WRITE, MAP_SHARED, fd_, 0);
  if (p == MAP_FAILED) return std::unexpected(io_error("cannot map", name_, errno));
  base_ = p;
  size_ = l.total;
  auto* h = new (p) SegmentHeader{};
  header_ = h;
  h->magic = kSegmentMagic;
  h->layout_version = kSegmentVersion;
  std::memcpy(h->type_name, spec.type_name.data(), spec.type_name.size());
  h->type_hash = spec.type_hash;
  h->payload_size = spec.payload_size;
  h->serialized = spec.serialized ? 1 : 0;
  h->capacity = spec.capacity;
  h->creator_pid = static_cast<std::uint32_t>(self);
  h->ring_offset = l.ring_offset;
  h->total_size = l.total;
  h->created_unix_ns = detail::now_unix_ns();
  h->scope = static_cast<std::uint32_t>(spec.scope);
  // An empty string_view may carry a null data(): copy only what there is.
  std::ranges::copy(spec.transport.substr(0, kMaxTransportName), h->transport);
  h->signature_offset = sizeof(SegmentHeader);
  h->signature_size = spec.signature.size();
  std::ranges::copy(spec.signature, static_cast<char*>(p) + sizeof(SegmentHeader));
  ring_ = Ring::format(static_cast<std::byte*>(p) + l.ring_offset, l.ring);
  if (l.pooled) {
    h->pool_offset = l.pool_offset;
    h->pool_slot_bytes = spec.pool_slot_bytes;
    h->pool_slots_per_lane = spec.pool_slots_per_lane;
    pool_ = Pool::format(static_cast<std::byte*>(p) + l.pool_offset, l.pool);
  }
  h->ready.store(1, std::memory_order_release);
  return {};
}

std::expected<void, SegmentError> ShmSegment::join_locked(std::string_view topic, pid_t self, std::uint64_t start) {
  for (std::uint32_t i = 0; i < kMaxParticipants; ++i) {
    Participant& e = header_->participants[i];
    if (e.pid.load(std::memory_order_acquire) != 0) continue;
    e.start_time.store(start, std::memory_order_relaxed);
    e.pid.store(static_cast<std::uint32_t>(self), std::memory_order_release);
    if (header_->participant_hwm.load(std::memory_order_relaxed) < i + 1)
      header_->participant_hwm.store(i + 1, std::memory_order_release);
    slot_ = i;
    if (pool_) pool_.admit(i);
    return {};
  }
  slot_ = kMaxParticipants;
  return std::unexpected(SegmentError{SegmentError::Kind::LimitReached,
                                      "topic '" + std::string(topic) + "' already has " +
                                          std::to_string(kMaxParticipants) + " processes attached"});
}

// Check the spec, open the file, lock it, attach to what it holds or format it, join.
std::expected<ShmSegment, SegmentError> ShmSegment::open(std::string_view ns, std::string_view topic,
                                                         const SegmentSpec& spec) {
  const auto layout = layout_of(topic, spec);
  if (!layout) return std::unexpected(layout.error());
  const std::string name = segment_name(ns, topic);
  const pid_t self = ::getpid();
  const std::uint64_t self_start = process_start_time(self);
  for (int attempt = 0; attempt < 100; ++attempt) {
    const auto fd = open_file(name, spec.mode);
    if (!fd) return std::unexpected(fd.error());
    if (*fd < 0) continue;  // unlinked meanwhile: start again
    if (auto why = foreign_file(*fd, spec.mode, name)) {
      ::close(*fd);
      return std::unexpected(SegmentError{SegmentError::Kind::Permission, std::move(*why)});
    }
    ShmSegment seg;
    seg.fd_ = *fd;
    seg.name_ = name;
    seg.owner_ = self;
    if (!detail::lock_with_deadline(*fd))
      return std::unexpected(SegmentError{SegmentError::Kind::Io,
                                          "shared-memory segment /dev/shm" + name +
                                              " stayed locked by another process for 5 s (is it stopped?)"});
    FdLock lock{*fd};
    struct stat st{};
    if (::fstat(*fd, &st) != 0) return std::unexpected(io_error("cannot stat", name, errno));
    if (st.st_nlink == 0) continue;  // unlinked by its last user after we opened it: start again
    const auto format = seg.attach_locked(topic, spec, layout->pooled, static_cast<std::size_t>(st.st_size));
    if (!format) return std::unexpected(format.error());
    if (*format) {
      if (auto made = seg.format_locked(spec, *layout, self); !made) return std::unexpected(made.error());
    }
    if (auto joined = seg.join_locked(topic, self, self_start); !joined) return std::unexpected(joined.error());
    return seg;
  }
  return std::unexpected(SegmentError{SegmentError::Kind::Io,
                                      "shared-memory segment /dev/shm" + name +
                                          " kept disappearing while opening it (100 attempts)"});
}

std::uint32_t ShmSegment::live_participants() const {
  std::uint32_t n = 0;
  for (const auto& e : header_->participants)
    if (e.pid.load(std::memory_order_acquire) != 0) ++n;
  return n;
}

std::uint32_t ShmSegment::reap_dead() const {
  if (header_ == nullptr || fd_ < 0 || !detail::lock_with_deadline(fd_)) return 0;
  FdLock lock{fd_};
  return reap_dead_locked();
}

std::uint32_t ShmSegment::reap_dead_locked() const {
  if (header_ == nullptr) return 0;
  std::uint32_t reaped = 0;
  std::set<pid_t> live;
  for (std::uint32_t i = 0; i < kMaxParticipants; ++i) {
    auto& e = header_->participants[i];
    const auto pid = static_cast<pid_t>(e.pid.load(std::memory_order_acquire));
    if (pid == 0) continue;
    if (process_alive(pid, e.start_time.load(std::memory_order_relaxed))) {
      live.insert(pid);
    } else {
      if (pool_) pool_.release_participant(i);  // the images it held come back
      e.pid.store(0, std::memory_order_release);
      ++reaped;
    }
  }
  if (!ring_) return reaped;
  // Lanes and subscriber entries whose owner process is no longer attached; but not the
  // bridge's entry and lane: its successor adopts them (inherit_bridge).
  const std::uint64_t bridge_lane = header_->bridge.import_token.load(std::memory_order_acquire);
  const std::uint64_t bridge_entry = header_->bridge.export_token.load(std::memory_order_acquire);
  for (std::uint32_t l = 0; l < kMaxPublishers; ++l) {
    const std::uint64_t owner = ring_.lane(l).owner.load(std::memory_order_acquire);
    if (owner != 0 && owner != bridge_lane && !live.contains(token_pid(owner))) ring_.release_lane(l, owner);
  }
  for (std::uint32_t i = 0; i < kMaxSubscribers; ++i) {
    auto& s = ring_.subscriber(i);
    const std::uint64_t owner = s.owner.load(std::memory_order_acquire);
    if (s.state.load(std::memory_order_acquire) == SubscriberEntry::kActive && owner != 0 &&
        owner != bridge_entry && !live.contains(token_pid(owner)))
      ring_.remove_subscriber(i, owner);
  }
  return reaped;
}

void ShmSegment::detach() noexcept {
  if (fd_ < 0) return;
  if (header_ != nullptr && owner_ == ::getpid()) release_bridge();
  // Membership work only for a segment we joined (never on a failed open's foreign header).
  if (header_ != nullptr && owner_ == ::getpid() && slot_ < kMaxParticipants && detail::lock_with_deadline(fd_)) {
    if (pool_) pool_.release_participant(slot_);
    header_->participants[slot_].pid.store(0, std::memory_order_release);
    try {
      reap_dead_locked();
    } catch (...) {
    }
    if (live_participants() == 0 && name_is_this_file(fd_, name_)) ::shm_unlink(name_.c_str());
    ::flock(fd_, LOCK_UN);
  }
  if (base_ != nullptr) ::munmap(base_, size_);
  ::close(fd_);
  fd_ = -1;
  base_ = nullptr;
  header_ = nullptr;
  ring_ = Ring();
  slot_ = kMaxParticipants;
}

namespace {
// The signature text of a mapped segment of `mapped` bytes; empty when the header's numbers
// do not describe a text inside the mapping (a corrupt header never makes us read past it).
std::string_view signature_in(const SegmentHeader* h, std::size_t mapped) noexcept {
  if (h == nullptr || h->signature_offset != sizeof(SegmentHeader) || h->signature_size > kMaxSignature ||
      h->signature_offset + h->signature_size > mapped)
    return {};
  return {reinterpret_cast<const char*>(h) + h->signature_offset, static_cast<std::size_t>(h->signature_size)};
}
}  // namespace

std::string_view ShmSegment::signature() const noexcept { return signature_in(header_, size_); }
std::string_view SegmentView::signature() const noexcept { return signature_in(header_, size_); }

// ---------------------------------------------------------------------------

std::expected<SegmentView, SegmentError> SegmentView::open(const std::string& name) {
  const int fd = ::shm_open(name.c_str(), O_RDONLY, 0);
  if (fd < 0) {
    const int err = errno;
    if (err == ENOENT)
      return std::unexpected(SegmentError{SegmentError::Kind::InvalidName, "no shared-memory segment /dev/shm" + name});
    return std::unexpected(io_error("cannot open", name, err));
  }
  struct stat st{};
  if (::fstat(fd, &st) != 0 || static_cast<std::size_t>(st.st_size) < sizeof(SegmentHeader)) {
    ::close(fd);
    return std::unexpected(SegmentError{SegmentError::Kind::Io,
                                        "shared-memory segment /dev/shm" + name + " is empty or being created"});
  }
  const auto size = static_cast<std::size_t>(st.st_size);
  void* p = ::mmap(nullptr, size, PROT_READ, MAP_SHARED, fd, 0);
  ::close(fd);
  if (p == MAP_FAILED) return std::unexpected(io_error("cannot map", name, errno));
  SegmentView v;
  v.base_ = p;
  v.size_ = size;
  v.header_ = static_cast<const SegmentHeader*>(p);
  const SegmentHeader& h = *v.header_;
  if (h.magic != kSegmentMagic || h.layout_version != kSegmentVersion || h.ready.load(std::memory_order_acquire) != 1)
    return std::unexpected(SegmentError{SegmentError::Kind::Io, "shared-memory segment /dev/shm" + name +
                                                                    " is not a finished horus segment of version " +
                                                                    std::to_string(kSegmentVersion)});
  // The checks of an attach (offsets where this version puts them, so aligned; ring and pool
  // inside the file and agreeing with the header): a file another process left may be anything.
  if (!ring_consistent(h, p, size))
    return std::unexpected(SegmentError{SegmentError::Kind::Io, "shared-memory segment /dev/shm" + name +
                                                                    " has a corrupt header (its ring or pool does not "
                                                                    "match it)"});
  v.ring_ = Ring::attach(static_cast<std::byte*>(p) + h.ring_offset);
  if (h.pool_offset != 0) v.pool_ = Pool::attach(static_cast<std::byte*>(p) + h.pool_offset);
  return v;
}

SegmentView& SegmentView::operator=(SegmentView&& o) noexcept {
  if (this != &o) {
    if (base_ != nullptr) ::munmap(base_, size_);
    base_ = std::exchange(o.base_, nullptr);
    size_ = std::exchange(o.size_, 0);
    header_ = std::exchange(o.header_, nullptr);
    ring_ = o.ring_;
    pool_ = o.pool_;
  }
  return *this;
}

SegmentView::~SegmentView() {
  if (base_ != nullptr) ::munmap(base_, size_);
}

namespace {
template <class F>
void for_each_segment_file(std::string_view ns, F&& f) {
  const std::string prefix = "horus." + std::string(ns) + ".";
  DIR* dir = ::opendir("/dev/shm");
  if (dir == nullptr) return;
  while (dirent* ent = ::readdir(dir)) {
    const std::string_view file(ent->d_name);
    if (file.starts_with(prefix)) f(std::string(file), std::string(file.substr(prefix.size())));
  }
  ::closedir(dir);
}
}  // namespace

std::vector<SegmentInfo> list_segments(std::string_view ns) {
  std::vector<SegmentInfo> out;
  for_each_segment_file(ns, [&](const std::string& file, const std::string& topic) {
    SegmentInfo info;
    info.name = file;
    info.topic = topic;
    const int fd = ::shm_open(("/" + file).c_str(), O_RDONLY, 0);
    if (fd >= 0) {
      struct stat st{};
      if (::fstat(fd, &st) == 0) {
        info.size = static_cast<std::uint64_t>(st.st_size);
        if (info.size >= sizeof(SegmentHeader)) {
          void* p = ::mmap(nullptr, sizeof(SegmentHeader), PROT_READ, MAP_SHARED, fd, 0);
          if (p != MAP_FAILED) {
            const auto* h = static_cast<const SegmentHeader*>(p);
            if (h->magic == kSegmentMagic && h->layout_version == kSegmentVersion &&
                h->ready.load(std::memory_order_acquire) == 1) {
              info.readable = true;
              info.type_name = std::string(h->type_name, strnlen(h->type_name, kMaxTypeName));
              for (const auto& e : h->participants) {
                const auto pid = static_cast<pid_t>(e.pid.load(std::memory_order_acquire));
                if (pid != 0)
                  info.participants.emplace_back(pid, process_alive(pid, e.start_time.load(std::memory_order_relaxed)));
              }
            }
            ::munmap(p, sizeof(SegmentHeader));
          }
        }
      }
      ::close(fd);
    }
    out.push_back(std::move(info));
  });
  return out;
}

std::vector<std::string> clean_stale_segments(std::string_view ns) {
  std::vector<std::string> removed;
  for_each_segment_file(ns, [&](const std::string& file, const std::string&) {
    const std::string name = "/" + file;
    const int fd = ::shm_open(name.c_str(), O_RDWR, 0);
    if (fd < 0) return;
    if (::flock(fd, LOCK_EX | LOCK_NB) != 0) {  // someone is changing it right now: alive
      ::close(fd);
      return;
    }
    bool stale = true;
    struct stat st{};
    if (::fstat(fd, &st) == 0 && static_cast<std::size_t>(st.st_size) >= sizeof(SegmentHeader)) {
      void* p = ::mmap(nullptr, sizeof(SegmentHeader), PROT_READ, MAP_SHARED, fd, 0);
      if (p != MAP_FAILED) {
        const auto* h = static_cast<const SegmentHeader*>(p);
        if (h->magic == kSegmentMagic && h->layout_version != kSegmentVersion && h->layout_version != 0) {
          stale = false;  // another horus version's segment: not ours to judge
        } else if (h->magic == kSegmentMagic && h->ready.load(std::memory_order_acquire) == 1) {
          stale = !any_participant_alive(*h);
        }
        ::munmap(p, sizeof(SegmentHeader));
      }
    }
    if (stale && name_is_this_file(fd, name) && ::shm_unlink(name.c_str()) == 0) removed.push_back(file);
    ::flock(fd, LOCK_UN);
    ::close(fd);
  });
  return removed;
}

}  // namespace horus::shm
