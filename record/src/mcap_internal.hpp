// The pieces of the MCAP writer and reader (private to record/): opcodes, little-endian
// building and parsing with bounds, and chunk compression.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <map>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "horus/error.hpp"
#include "horus/record/mcap.hpp"

namespace horus::mcap::detail {

inline constexpr std::byte kMagic[8] = {std::byte{0x89}, std::byte{'M'},  std::byte{'C'},  std::byte{'A'},
                                        std::byte{'P'},  std::byte{0x30}, std::byte{'\r'}, std::byte{'\n'}};

enum Op : std::uint8_t {
  kHeader = 0x01,
  kFooter = 0x02,
  kSchema = 0x03,
  kChannel = 0x04,
  kMessage = 0x05,
  kChunk = 0x06,
  kMessageIndex = 0x07,
  kChunkIndex = 0x08,
  kAttachment = 0x09,
  kAttachmentIndex = 0x0A,
  kStatistics = 0x0B,
  kMetadata = 0x0C,
  kMetadataIndex = 0x0D,
  kSummaryOffset = 0x0E,
  kDataEnd = 0x0F,
};

/// The record's name, for messages ("Chunk", "opcode 0x42").
std::string op_name(std::uint8_t op);

/// Appends little-endian fields to a byte vector.
class Out {
 public:
  explicit Out(std::vector<std::byte>& buf) : buf_(buf) {}
  void u8(std::uint8_t v) { buf_.push_back(std::byte{v}); }
  void u16(std::uint16_t v) { le(v, 2); }
  void u32(std::uint32_t v) { le(v, 4); }
  void u64(std::uint64_t v) { le(v, 8); }
  void bytes(std::span<const std::byte> b) { buf_.insert(buf_.end(), b.begin(), b.end()); }
  void str(std::string_view s) {
    u32(static_cast<std::uint32_t>(s.size()));
    bytes(std::as_bytes(std::span(s.data(), s.size())));
  }
  void string_map(const std::map<std::string, std::string>& m);
  /// Starts a record: opcode and a length patched by end_record().
  std::size_t begin_record(std::uint8_t op) {
    u8(op);
    const std::size_t at = buf_.size();
    u64(0);
    return at;
  }
  void end_record(std::size_t at) {
    const std::uint64_t n = buf_.size() - at - 8;
    for (int i = 0; i < 8; ++i) buf_[at + static_cast<std::size_t>(i)] = std::byte{static_cast<std::uint8_t>(n >> (8 * i))};
  }
  std::size_t size() const noexcept { return buf_.size(); }

 private:
  void le(std::uint64_t v, int n) {
    for (int i = 0; i < n; ++i) buf_.push_back(std::byte{static_cast<std::uint8_t>(v >> (8 * i))});
  }
  std::vector<std::byte>& buf_;
};

/// Reads little-endian fields from a span, every read bounded; the first failure is kept with
/// the file offset of the field and what it should have been.
class In {
 public:
  /// `base`: the file offset of bytes[0] (0 inside a decompressed chunk: then `where` says so).
  In(std::span<const std::byte> bytes, std::uint64_t base, std::string where)
      : b_(bytes), base_(base), where_(std::move(where)) {}
  std::uint8_t u8(const char* field) { return static_cast<std::uint8_t>(take(1, field)); }
  std::uint16_t u16(const char* field) { return static_cast<std::uint16_t>(take(2, field)); }
  std::uint32_t u32(const char* field) { return static_cast<std::uint32_t>(take(4, field)); }
  std::uint64_t u64(const char* field) { return take(8, field); }
  std::string str(const char* field);
  std::span<const std::byte> bytes(std::uint64_t n, const char* field);
  std::span<const std::byte> rest() {
    auto r = b_.subspan(pos_);
    pos_ = b_.size();
    return r;
  }
  std::map<std::string, std::string> string_map(const char* field);
  std::size_t pos() const noexcept { return pos_; }
  std::size_t left() const noexcept { return b_.size() - pos_; }
  std::uint64_t offset() const noexcept { return base_ + pos_; }
  bool ok() const noexcept { return !error_; }
  /// Fails (first failure wins).
  void fail(std::string what);
  const std::optional<Error>& error() const noexcept { return error_; }

 private:
  std::uint64_t take(std::size_t n, const char* field);
  std::span<const std::byte> b_;
  std::size_t pos_ = 0;
  std::uint64_t base_;
  std::string where_;
  std::optional<Error> error_;
};

/// Compresses `in` (zstd level 1, or an LZ4 frame) into `out` (replaced).
Result<void> compress(Compression c, std::span<const std::byte> in, std::vector<std::byte>& out);
/// The most a compressed stream of `n` bytes can decompress to: zstd's densest block (an RLE
/// block: 4 bytes for 128 KiB) and LZ4's densest sequence (255 bytes of match per byte), with
/// room for their frame headers.
std::uint64_t decompressed_bound(std::string_view compression, std::uint64_t n) noexcept;
/// Decompresses into exactly `size` bytes; Errc::Corrupt naming `where` when the data is not a
/// valid stream of that size, when `size` is more than the compressed bytes could hold
/// (decompressed_bound) or than the frame's own content size, and Errc::LimitReached when it is above
/// `max_size`: checked before anything is allocated.
Result<void> decompress(std::string_view compression, std::span<const std::byte> in, std::uint64_t size,
                        std::vector<std::byte>& out, const std::string& where, std::uint64_t max_size);

}  // namespace horus::mcap::detail
