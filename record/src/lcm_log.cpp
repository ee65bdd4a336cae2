// LCM event logs (see lcm_log.hpp).
#include "horus/record/lcm_log.hpp"

#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <array>
#include <cerrno>
#include <cstring>

#include <fmt/format.h>

namespace horus::lcmlog {
namespace {

void put32(std::byte* p, std::uint32_t v) {
  for (int i = 0; i < 4; ++i) p[i] = static_cast<std::byte>(v >> (24 - 8 * i));
}
void put64(std::byte* p, std::uint64_t v) {
  for (int i = 0; i < 8; ++i) p[i] = static_cast<std::byte>(v >> (56 - 8 * i));
}
std::uint64_t get(const std::byte* p, int n) {
  std::uint64_t v = 0;
  for (int i = 0; i < n; ++i) v = (v << 8) | static_cast<std::uint8_t>(p[i]);
  return v;
}

constexpr std::size_t kEventHeader = 4 + 8 + 8 + 4 + 4;

}  // namespace

Result<std::unique_ptr<Writer>> Writer::create(const std::string& path) {
  std::FILE* f = std::fopen(path.c_str(), "wb");
  if (f == nullptr) return fail(Errc::Io, fmt::format("cannot create the LCM log {}: {}", path, std::strerror(errno)));
  // A large buffer: an event reaches the kernel in few writes.
  std::setvbuf(f, nullptr, _IOFBF, 1u << 20);
  return std::unique_ptr<Writer>(new Writer(f, path));
}

Writer::~Writer() { (void)close(); }

Result<void> Writer::write(std::string_view channel, std::int64_t timestamp_us, std::span<const std::byte> data) {
  if (f_ == nullptr) return fail(Errc::InvalidArgument, "the LCM log " + path_ + " is closed");
  if (channel.empty() || channel.size() > kMaxChannel)
    return fail(Errc::InvalidArgument, fmt::format("LCM channel '{}' has {} bytes; an LCM log holds 1 to {}", channel,
                                                   channel.size(), kMaxChannel));
  if (data.size() > 0x7fffffffu)
    return fail(Errc::MessageTooLarge, fmt::format("a message of {} bytes on '{}' is larger than an LCM log event holds "
                                                   "(2 GiB)",
                                                   data.size(), channel));
  std::array<std::byte, kEventHeader> h{};
  put32(h.data(), kSync);
  put64(h.data() + 4, static_cast<std::uint64_t>(next_));
  put64(h.data() + 12, static_cast<std::uint64_t>(timestamp_us));
  put32(h.data() + 20, static_cast<std::uint32_t>(channel.size()));
  put32(h.data() + 24, static_cast<std::uint32_t>(data.size()));
  if (std::fwrite(h.data(), 1, h.size(), f_) != h.size() ||
      std::fwrite(channel.data(), 1, channel.size(), f_) != channel.size() ||
      (!data.empty() && std::fwrite(data.data(), 1, data.size(), f_) != data.size()))
    return fail(Errc::Io, fmt::format("writing the LCM log {}: {}", path_, std::strerror(errno)));
  ++next_;
  bytes_ += h.size() + channel.size() + data.size();
  return {};
}

Result<void> Writer::flush() {
  if (f_ != nullptr && std::fflush(f_) != 0)
    return fail(Errc::Io, fmt::format("writing the LCM log {}: {}", path_, std::strerror(errno)));
  return {};
}

Result<void> Writer::close() {
  if (f_ == nullptr) return {};
  const bool ok = std::fflush(f_) == 0;
  const int err = errno;
  const bool closed = std::fclose(f_) == 0;
  f_ = nullptr;
  if (!ok || !closed) return fail(Errc::Io, fmt::format("closing the LCM log {}: {}", path_, std::strerror(err)));
  return {};
}

Result<std::unique_ptr<Reader>> Reader::open(const std::string& path) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) return fail(Errc::Io, fmt::format("cannot open {}: {}", path, std::strerror(errno)));
  struct stat st {};
  if (::fstat(fd, &st) != 0) {
    const int err = errno;
    ::close(fd);
    return fail(Errc::Io, fmt::format("cannot stat {}: {}", path, std::strerror(err)));
  }
  const auto size = static_cast<std::size_t>(st.st_size);
  const std::byte* data = nullptr;
  if (size > 0) {
    void* m = ::mmap(nullptr, size, PROT_READ, MAP_PRIVATE, fd, 0);
    if (m == MAP_FAILED) {
      const int err = errno;
      ::close(fd);
      return fail(Errc::Io, fmt::format("cannot map {}: {}", path, std::strerror(err)));
    }
    data = static_cast<const std::byte*>(m);
  }
  ::close(fd);
  return std::unique_ptr<Reader>(new Reader(path, data, size));
}

Reader::~Reader() {
  if (data_ != nullptr) ::munmap(const_cast<std::byte*>(data_), size_);
}

Result<void> Reader::read(const std::function<bool(const Event&)>& f) {
  truncated_ = false;
  std::size_t at = 0;
  while (at < size_) {
    if (size_ - at < kEventHeader) {
      truncated_ = true;
      return {};
    }
    const std::byte* p = data_ + at;
    if (get(p, 4) != kSync)
      return fail(Errc::Corrupt, fmt::format("{}: offset {}: expected the LCM log sync word 0xEDA1DA01, found 0x{:08X}",
                                             path_, at, get(p, 4)));
    const auto channel_len = static_cast<std::int32_t>(get(p + 20, 4));
    const auto data_len = static_cast<std::int32_t>(get(p + 24, 4));
    if (channel_len <= 0 || static_cast<std::size_t>(channel_len) > 256)
      return fail(Errc::Corrupt, fmt::format("{}: offset {}: an event's channel length is {}; expected 1 to 256", path_,
                                             at + 20, channel_len));
    if (data_len < 0)
      return fail(Errc::Corrupt, fmt::format("{}: offset {}: an event's data length is {}; expected 0 or more", path_,
                                             at + 24, data_len));
    const std::size_t need = kEventHeader + static_cast<std::size_t>(channel_len) + static_cast<std::size_t>(data_len);
    if (size_ - at < need) {
      truncated_ = true;
      return {};
    }
    Event e;
    e.number = static_cast<std::int64_t>(get(p + 4, 8));
    e.timestamp_us = static_cast<std::int64_t>(get(p + 12, 8));
    e.channel = std::string_view(reinterpret_cast<const char*>(p + kEventHeader), static_cast<std::size_t>(channel_len));
    e.data = std::span<const std::byte>(p + kEventHeader + channel_len, static_cast<std::size_t>(data_len));
    at += need;
    if (!f(e)) return {};
  }
  return {};
}

bool looks_like_log(const std::string& path) {
  std::FILE* f = std::fopen(path.c_str(), "rb");
  if (f == nullptr) return false;
  std::array<std::byte, 4> b{};
  const bool ok = std::fread(b.data(), 1, 4, f) == 4 && get(b.data(), 4) == kSync;
  std::fclose(f);
  return ok;
}

}  // namespace horus::lcmlog
