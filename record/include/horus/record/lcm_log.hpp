// LCM event logs: the files lcm-logger writes and lcm-logplayer reads, written and read by
// horus's own code (`horus record --format lcm`, `horus play` of an lcm-logger file).
//
// A log is a sequence of events, each
//
//   u32 sync 0xEDA1DA01 | i64 event number | i64 timestamp (us since the Unix epoch)
//   | i32 channel length | i32 data length | channel bytes | data bytes
//
// all integers big-endian; the data is one LCM message (its 8-byte type fingerprint first).
// The reader bounds every length by the bytes left and names the offset of what is wrong; a
// file that ends inside an event (a logger that was killed) reads up to its last whole event.
#pragma once

#include <cstdint>
#include <cstdio>
#include <functional>
#include <memory>
#include <span>
#include <string>
#include <string_view>

#include "horus/error.hpp"

#include "horus/export.hpp"

HORUS_API_BEGIN

namespace horus::lcmlog {

inline constexpr std::uint32_t kSync = 0xEDA1DA01u;
/// LCM's limit on a channel name (LCM_MAX_CHANNEL_NAME_LENGTH).
inline constexpr std::size_t kMaxChannel = 63;

struct Event {
  std::int64_t number = 0;
  std::int64_t timestamp_us = 0;
  std::string_view channel;
  std::span<const std::byte> data;  // valid during the call that hands it over
};

class Writer {
 public:
  /// Creates (truncates) `path`.
  static Result<std::unique_ptr<Writer>> create(const std::string& path);
  ~Writer();
  Writer(const Writer&) = delete;
  Writer& operator=(const Writer&) = delete;
  /// Appends one event (numbered from 0); a channel longer than kMaxChannel is refused.
  Result<void> write(std::string_view channel, std::int64_t timestamp_us, std::span<const std::byte> data);
  /// Hands what is buffered to the kernel.
  Result<void> flush();
  Result<void> close();
  std::uint64_t file_size() const noexcept { return bytes_; }
  std::uint64_t events() const noexcept { return static_cast<std::uint64_t>(next_); }

 private:
  Writer(std::FILE* f, std::string path) : f_(f), path_(std::move(path)) {}
  std::FILE* f_;
  std::string path_;
  std::int64_t next_ = 0;
  std::uint64_t bytes_ = 0;
};

/// Reads a log mapped into memory.
class Reader {
 public:
  static Result<std::unique_ptr<Reader>> open(const std::string& path);
  ~Reader();
  Reader(const Reader&) = delete;
  Reader& operator=(const Reader&) = delete;
  /// Every event in file order; `f` returns false to stop. A bad sync word, a negative or
  /// oversized length is Errc::Corrupt naming the offset; an event cut short at the end of the
  /// file ends the reading quietly and sets truncated().
  Result<void> read(const std::function<bool(const Event&)>& f);
  bool truncated() const noexcept { return truncated_; }
  std::uint64_t file_size() const noexcept { return size_; }

 private:
  Reader(std::string path, const std::byte* data, std::size_t size) : path_(std::move(path)), data_(data), size_(size) {}
  std::string path_;
  const std::byte* data_;
  std::size_t size_;
  bool truncated_ = false;
};

/// Whether `path` starts like an LCM log (its first four bytes are the sync word).
bool looks_like_log(const std::string& path);

}  // namespace horus::lcmlog

HORUS_API_END
