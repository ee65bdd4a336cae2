// The local wire format: how a variable-size message (one with std::vector or std::string
// fields, or a large-data class such as Image) is written into a ring slot.
//
//   std::size_t n = horus::codec::encoded_size(grid);
//   horus::codec::encode(grid, buffer);                  // buffer.size() >= n
//   auto back = horus::codec::decode<OccupancyGrid>(bytes);   // std::expected<T, std::string>
//
// It is driven by the reflection, so every reflected message can be encoded with no
// hand-written code. The format is for one host (native byte order; a block of POD bytes
// keeps its in-memory padding):
//
//   bool                                                                one byte, 0 or 1
//   trivially copyable value with no bool (scalar, enum, POD message)  its bytes, as in memory
//   std::vector<E>, std::string                                         u32 count, then the elements
//   other std::array<E, N>                                              the N elements
//   other reflected message (e.g. a POD one with a bool)                its fields in order
//
// Network backends use their own codecs (CDR, LCM); this one never leaves the host.
// decode() checks every length against the bytes that remain before reading or
// allocating, so a corrupt or truncated buffer gives an error that names the field
// (never a crash, never a read past the end, never an allocation much larger than the
// buffer), checks bool bytes are 0 or 1, and refuses trailing bytes.
#pragma once

#include <bit>
#include <cstddef>
#include <cstdint>
#include <expected>
#include <limits>
#include <span>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

#include "horus/reflect.hpp"
#include "horus/wire/reader.hpp"
#include "horus/wire/walk.hpp"

#include "horus/export.hpp"

HORUS_API_BEGIN

namespace horus::codec {

static_assert(std::endian::native == std::endian::little, "the local wire format assumes a little-endian host");

namespace detail {
using reflect::detail::is_std_array;
using reflect::detail::is_std_vector;
using wire::Path;
using wire::Reader;
using wire::kTooLarge;
using wire::sat_add;

template <class V>
inline constexpr bool is_raw = std::is_trivially_copyable_v<V>;

template <class V>
inline constexpr bool is_sequence = is_std_vector<V>::value || std::is_same_v<V, std::string>;

/// True when V holds a bool somewhere: such values are decoded field by field, because a
/// bool byte other than 0 or 1 (a corrupt buffer) must be an error, not undefined behaviour.
template <class V>
constexpr bool contains_bool() {
  if constexpr (std::is_same_v<V, bool>) {
    return true;
  } else if constexpr (std::is_arithmetic_v<V> || std::is_enum_v<V> || std::is_same_v<V, std::string>) {
    return false;
  } else if constexpr (is_std_array<V>::value || is_std_vector<V>::value) {
    return contains_bool<typename V::value_type>();
  } else {
    bool any = false;
    reflect::for_each_field_desc<V>([&](const auto& fd) {
      any = any || contains_bool<typename std::remove_cvref_t<decltype(fd)>::type>();
    });
    return any;
  }
}

/// Values encoded and decoded as one block of bytes: trivially copyable, and every byte
/// pattern valid (no bool inside). Others go field by field (a bool is one byte, 0 or 1).
template <class V>
inline constexpr bool is_raw_decodable = is_raw<V> && !contains_bool<V>();

inline constexpr std::size_t kMaxCount = std::numeric_limits<std::uint32_t>::max();

/// The local format's primitives for the shared walk (horus/wire/walk.hpp): native byte
/// order, no alignment, POD values as their bytes, u32 counts.
struct Format {
  static constexpr std::string_view kNoun = "message";
  static constexpr std::size_t kMinString = 4;
  static constexpr std::size_t kPadding = 0;
  static constexpr std::string_view kOutOfMemory = ": out of memory while decoding ";
  static constexpr std::string_view kLeftOver = " bytes left over after the message (corrupt message or wrong type)";
  template <class V>
  static constexpr bool block = is_raw_decodable<V>;
  template <class E>
  static constexpr bool run = is_raw_decodable<E>;
  template <class V>
  static constexpr std::size_t scalar_size = 1;  // a bool: every other scalar is a block

  template <class S>
  static void put_scalar(S& s, bool v) {
    const std::uint8_t b = v ? 1 : 0;
    s.bytes(&b, 1);
  }
  // More elements than a u32 can count: encoded_size() says kTooLarge, encode() throws.
  template <class S>
  static void put_count(S& s, std::size_t n) {
    if (n > kMaxCount) {
      if constexpr (S::kCounting) {
        s.saturate();
        return;
      } else {
        throw std::length_error("horus::codec::encode: a sequence of " + std::to_string(n) +
                                " elements; at most 4294967295");
      }
    }
    const auto count = static_cast<std::uint32_t>(n);
    s.bytes(&count, 4);
  }
  template <class S>
  static void put_string(S& s, const std::string& v) {
    put_count(s, v.size());
    s.bytes(v.data(), v.size());
  }
  template <class S, class E>
  static void put_run(S& s, const E* p, std::size_t n) {
    s.bytes(p, n * sizeof(E));
  }

  static bool get_scalar(Reader& r, bool& v, const Path& path) { return wire::get_strict_bool(r, v, path, kNoun); }
  static bool get_count(Reader& r, std::size_t& n, std::size_t min_bytes, const Path& path) {
    std::uint32_t count = 0;
    if (!r.take(&count, 4)) return r.fail(path, ": the element count is cut off (truncated message)");
    if (!r.fits(count, min_bytes)) return r.too_many(path, "count", count, min_bytes, kNoun);
    n = count;
    return true;
  }
  static bool get_string(Reader& r, std::string& v, const Path& path) {
    std::size_t n = 0;
    if (!get_count(r, n, 1, path)) return false;
    v.assign(reinterpret_cast<const char*>(r.here()), n);
    r.skip(n);
    return true;
  }
  template <class E>
  static bool get_run(Reader& r, E* out, std::size_t n, const Path& path) {
    if (!r.take(out, n * sizeof(E))) return r.truncated(path, n * sizeof(E), kNoun);  // checked by the count
    return true;
  }
};

/// Encoded bytes of any field value; kTooLarge when a sequence has more elements than a u32
/// count can say.
template <class V>
std::size_t size_of(const V& v) {
  wire::Counter c;
  wire::put<Format>(c, v);
  return c.pos;
}
}  // namespace detail

/// Bytes encode(msg) writes; SIZE_MAX when a sequence has more elements than the format allows.
template <Reflected T>
std::size_t encoded_size(const T& msg) {
  return detail::size_of(msg);
}

/// Writes msg into out, which must hold at least encoded_size(msg) bytes; returns the bytes
/// written. Throws std::length_error when out is too small or a sequence has more than
/// 2^32 - 1 elements (nothing is written past out).
template <Reflected T>
std::size_t encode(const T& msg, std::span<std::byte> out) {
  wire::Writer w(out.data(), out.size(), "horus::codec::encode: the output buffer is smaller than encoded_size(msg)");
  wire::put<detail::Format>(w, msg);
  return w.pos;
}

/// The bytes of msg, in a new buffer (std::length_error as above).
template <Reflected T>
std::vector<std::byte> encode(const T& msg) {
  const std::size_t n = encoded_size(msg);
  if (n == detail::kTooLarge) throw std::length_error("horus::codec::encode: a sequence has more than 2^32 - 1 elements");
  std::vector<std::byte> out(n);
  encode(msg, std::span<std::byte>(out));
  return out;
}

/// Reads a message; on a truncated, corrupt or over-long buffer, an error naming the field.
template <Reflected T>
  requires std::is_default_constructible_v<T>
std::expected<T, std::string> decode(std::span<const std::byte> in) {
  detail::Reader r(in);
  return wire::decode_message<detail::Format, T>(r, in.size());
}

}  // namespace horus::codec

HORUS_API_END
