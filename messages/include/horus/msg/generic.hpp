// GenericMessage: a dynamically typed message carrying a MessagePack payload
// (at most 4096 bytes) and an optional metadata string, for prototyping and for
// data shared with Python nodes.
//
//   auto msg = horus::msg::GenericMessage::from_value(std::map<std::string, double>{{"x", 1.0}});
//   if (!msg) log(msg.error());
//   auto back = msg->to_value<std::map<std::string, double>>();   // std::expected<T, std::string>
//
// from_value and to_value need #include <horus/msg/generic_value.hpp> (msgpack-cxx,
// which costs about two seconds of compile time; <horus/horus.hpp> leaves it out).
// Any type msgpack-cxx can pack works: integers, floats, strings, vectors,
// maps, tuples, and user structs with MSGPACK_DEFINE(...). The layout is HORUS's
// (horus_types generic.rs): a 256-byte inline buffer used for payloads up to
// 256 bytes, a 3840-byte overflow buffer for the rest of larger ones, and a
// 256-byte metadata buffer (at most 255 bytes of UTF-8). So GenericMessage is
// fixed-size (4364 bytes, trivially copyable) and travels by memcpy like every
// standard message. Nothing is ever cut: a payload over 4096 bytes or metadata
// over 255 bytes is an error naming both sizes.
//
// msgpack-cxx is used header-only, without Boost (MSGPACK_NO_BOOST), in generic_value.hpp.
#pragma once

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <exception>
#include <expected>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "horus/fixed_string.hpp"
#include "horus/reflect.hpp"

#include "horus/export.hpp"

HORUS_API_BEGIN

namespace horus::msg {

namespace detail {
/// Index of the first byte that is not part of well-formed UTF-8 (no overlong
/// forms, no surrogates, nothing above U+10FFFF), or npos when all of it is.
constexpr std::size_t generic_utf8_error(std::string_view s) noexcept {
  std::size_t i = 0;
  while (i < s.size()) {
    const auto b = static_cast<unsigned char>(s[i]);
    std::size_t n = 0;
    unsigned char lo = 0x80, hi = 0xBF;  // allowed range of the second byte
    if (b < 0x80) { ++i; continue; }
    if (b >= 0xC2 && b <= 0xDF) n = 1;
    else if (b == 0xE0) { n = 2; lo = 0xA0; }
    else if (b >= 0xE1 && b <= 0xEC) n = 2;
    else if (b == 0xED) { n = 2; hi = 0x9F; }
    else if (b >= 0xEE && b <= 0xEF) n = 2;
    else if (b == 0xF0) { n = 3; lo = 0x90; }
    else if (b >= 0xF1 && b <= 0xF3) n = 3;
    else if (b == 0xF4) { n = 3; hi = 0x8F; }
    else return i;
    if (i + n >= s.size()) return i;  // sequence cut off by the end
    for (std::size_t k = 1; k <= n; ++k) {
      const auto c = static_cast<unsigned char>(s[i + k]);
      const unsigned char min = k == 1 ? lo : 0x80, max = k == 1 ? hi : 0xBF;
      if (c < min || c > max) return i;
    }
    i += n + 1;
  }
  return std::string_view::npos;
}

/// The longest prefix of s of at most max bytes that does not split a UTF-8 sequence.
constexpr std::string_view generic_utf8_prefix(std::string_view s, std::size_t max) noexcept {
  if (s.size() <= max) return s;
  std::size_t len = max;
  while (len > 0 && (static_cast<unsigned char>(s[len]) & 0xC0u) == 0x80u) --len;
  return s.substr(0, len);
}

/// Defined by <horus/msg/generic_value.hpp>, which from_value and to_value need.
template <class T>
struct GenericValue;
}  // namespace detail

// ---------------------------------------------------------------------------
/// A MessagePack payload of at most 4096 bytes with optional metadata text.
/// Build one with make(), with_metadata() or from_value(); read it with data(),
/// metadata() and to_value<T>(). GenericMessage{} is the empty message.
class GenericMessage {
 public:
  static constexpr std::size_t kMaxPayload = 4096;      ///< bytes (HORUS MAX_GENERIC_PAYLOAD)
  static constexpr std::size_t kInlineCapacity = 256;   ///< bytes kept in the inline buffer
  static constexpr std::size_t kOverflowCapacity = kMaxPayload - kInlineCapacity;
  static constexpr std::size_t kMaxMetadata = 255;      ///< bytes of metadata text

  /// A message holding these raw bytes (HORUS's GenericMessage::new), or an
  /// error when there are more than 4096. Payloads up to 256 bytes live in the
  /// inline buffer; larger ones fill it and put the rest in the overflow buffer.
  static std::expected<GenericMessage, std::string> make(std::span<const std::uint8_t> bytes);

  /// make(bytes) with metadata text. An error when the payload is over 4096
  /// bytes, or the metadata is over 255 bytes, holds a NUL or is not UTF-8.
  static std::expected<GenericMessage, std::string> with_metadata(std::span<const std::uint8_t> bytes,
                                                                  std::string_view meta) {
    if (auto problem = metadata_problem(meta)) return std::unexpected(std::move(*problem));
    auto m = make(bytes);
    if (m) m->store_metadata(meta);
    return m;
  }

  /// Packs value with MessagePack into a new message (HORUS's from_value). An
  /// error when the encoding is over 4096 bytes (the size is named) or packing
  /// fails. T is any type msgpack-cxx can pack (MSGPACK_DEFINE for your structs).
  template <class T, class Value = detail::GenericValue<T>>
  static std::expected<GenericMessage, std::string> from_value(const T& value) {
    return Value::pack(value);  // an incomplete type here: #include <horus/msg/generic_value.hpp>
  }

  /// Unpacks the payload into a T (HORUS's to_value). An error, naming T and
  /// what was found, when the payload is empty, is not valid MessagePack, holds
  /// bytes after the first value, or the value does not convert to T (a string
  /// into an int, an integer out of T's range, a map into a vector, ...).
  /// T must own its data (std::string, not std::string_view or msgpack::object):
  /// the unpacked buffer is gone when to_value returns.
  template <class T, class Value = detail::GenericValue<T>>
  std::expected<T, std::string> to_value() const {
    return Value::unpack(data());  // an incomplete type here: #include <horus/msg/generic_value.hpp>
  }

  /// The payload bytes (inline part, then overflow part).
  std::vector<std::uint8_t> data() const {
    std::vector<std::uint8_t> out;
    out.reserve(size());
    out.insert(out.end(), inline_data_.begin(), inline_data_.begin() + static_cast<std::ptrdiff_t>(inline_size()));
    out.insert(out.end(), overflow_data_.begin(),
               overflow_data_.begin() + static_cast<std::ptrdiff_t>(overflow_size()));
    return out;
  }
  /// Payload size in bytes (lengths clamped to the buffers: a received message may hold any value).
  constexpr std::size_t size() const noexcept { return inline_size() + overflow_size(); }
  constexpr bool empty() const noexcept { return size() == 0; }
  /// True when the whole payload sits in the inline buffer (at most 256 bytes).
  constexpr bool is_inline() const noexcept { return overflow_size() == 0; }

  /// The metadata text, or nullopt when none is set or the stored bytes are not
  /// text. A received message is not validated (metadata_len may be anything,
  /// the bytes may be anything), so the first metadata_len bytes (clamped to
  /// 255) are checked here: nullopt when they are not well-formed UTF-8 (as
  /// HORUS, whose metadata() gives None then) or hold a NUL byte (which
  /// set_metadata() never stores; HORUS would pass it through).
  constexpr std::optional<std::string_view> metadata() const noexcept {
    const std::string_view raw = metadata_bytes();
    if (raw.empty() || raw.find('\0') != std::string_view::npos ||
        detail::generic_utf8_error(raw) != std::string_view::npos)
      return std::nullopt;
    return raw;
  }
  /// Sets (or, with "", clears) the metadata; returns false, changing nothing,
  /// when it is over 255 bytes, holds a NUL or is not UTF-8.
  bool set_metadata(std::string_view meta) noexcept {
    if (metadata_problem(meta)) return false;
    store_metadata(meta);
    return true;
  }

  /// `GenericMessage(24 B msgpack, meta "imu", value {"x":1.5,"y":2})`: size,
  /// metadata (first 60 bytes) and the decoded value (first 80 characters).
  /// "not MessagePack" when the bytes do not decode, "empty" for no payload;
  /// metadata that is set but not text (see metadata()) shows as
  /// "meta not UTF-8 text (N B)" and its bytes are left out.
  std::string log_summary() const;

  friend constexpr bool operator==(const GenericMessage&, const GenericMessage&) = default;

 private:
  constexpr std::size_t inline_size() const noexcept { return std::min<std::size_t>(inline_len_, kInlineCapacity); }
  constexpr std::size_t overflow_size() const noexcept {
    return std::min<std::size_t>(overflow_len_, kOverflowCapacity);
  }
  /// The stored metadata bytes as they are: metadata_len (clamped to 255) bytes, unchecked.
  constexpr std::string_view metadata_bytes() const noexcept {
    return std::string_view(metadata_.data(), std::min<std::size_t>(metadata_len_, kMaxMetadata));
  }

  static std::optional<std::string> metadata_problem(std::string_view meta);
  void store_metadata(std::string_view meta) noexcept {
    set_fixed_str(metadata_, meta);
    metadata_len_ = static_cast<std::uint16_t>(meta.size());
  }

  std::array<std::uint8_t, kInlineCapacity> inline_data_{};
  std::uint16_t inline_len_{};
  std::array<std::uint8_t, kOverflowCapacity> overflow_data_{};
  std::uint32_t overflow_len_{};
  std::array<char, kMaxMetadata + 1> metadata_{};  ///< UTF-8, NUL-padded
  std::uint16_t metadata_len_{};
  std::array<std::uint8_t, 2> padding_{};          ///< alignment (as HORUS), always zero

  HORUS_REFLECT_FRIEND(GenericMessage)
};
HORUS_REFLECT_AS(GenericMessage, (inline_data, inline_data_), (inline_len, inline_len_),
                 (overflow_data, overflow_data_), (overflow_len, overflow_len_), (metadata, metadata_),
                 (metadata_len, metadata_len_), (_padding, padding_))

static_assert(horus::reflect::is_fixed_size<GenericMessage>,
              "GenericMessage must be trivially copyable and standard layout");
static_assert(sizeof(GenericMessage) == 4364, "GenericMessage must have HORUS's layout (4364 bytes)");

// The standard messages of this header (Topic<T> takes their network codecs from the library).
HORUS_STANDARD_MESSAGES(GenericMessage)

}  // namespace horus::msg

HORUS_API_END
