// XCDR1 (plain CDR, final extensibility) driven by the reflection: the bytes a program built
// from horus-idlgen's IDL by idlc or fastddsgen reads and writes, field for field.
//
//   std::size_t n = horus::cdr::encoded_size(pose);
//   horus::cdr::encode(pose, buffer);                             // buffer.size() >= n
//   auto back = horus::cdr::decode<Pose2D>(bytes, little_endian); // std::expected<T, std::string>
//
// The bytes are the sample body, after the 4-byte encapsulation header (which the transport
// writes); alignment is counted from the body's first byte:
//   bool, char, int8, uint8            1 byte (a bool is 0 or 1)
//   16/32/64-bit integers, floats      their size, aligned to their size
//   IDL enum (horus/wire/mapping.hpp) u32, aligned to 4; other enums as their integer
//   string                             u32 length + 1, the bytes, a NUL (aligned to 4)
//   sequence                           u32 count (aligned to 4), then the elements
//   array                              the elements
//   struct                             its fields in order
// Encoding writes little endian; decoding reads either byte order. decode() checks every
// length before reading or allocating (a corrupt count costs no more memory than the bytes
// can hold), refuses bool bytes other than 0/1, enum values with no enumerator, strings
// without their NUL, and more than 3 bytes of trailing padding; the error names the field.
// This header needs no DDS library.
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

#include "horus/byte_buffer.hpp"
#include "horus/reflect.hpp"
#include "horus/wire/mapping.hpp"
#include "horus/wire/reader.hpp"
#include "horus/wire/walk.hpp"

#include "horus/export.hpp"

HORUS_API_BEGIN

namespace horus::cdr {

static_assert(std::endian::native == std::endian::little, "horus::cdr encodes on a little-endian host");

/// A decode() option: where the bytes of ByteBuffer fields go (horus/byte_buffer.hpp).
using ByteSink = horus::ByteSink;

namespace detail {
using reflect::detail::is_std_array;
using reflect::detail::is_std_vector;
using wire::is_number;
using wire::Path;
using wire::Reader;

// The wire integer of an enum: u32 for an IDL enum, else its underlying type.
template <class E>
using enum_wire_t = std::conditional_t<idlgen::is_idl_enum<E>(), std::uint32_t, std::underlying_type_t<E>>;

template <class S, class N>
void put_number(S& s, N v) {
  s.align(sizeof(N));
  s.bytes(&v, sizeof(N));
}

template <class N>
bool get_number(Reader& r, N& v, const Path& path) {
  if (!r.align(sizeof(N)) || !r.number(v, r.swap)) return r.truncated(path, sizeof(N), "sample");
  return true;
}

/// XCDR1's primitives for the shared walk (horus/wire/walk.hpp): numbers aligned to their
/// size, u32 counts, NUL-terminated strings, little endian out and either byte order in.
struct Format {
  static constexpr std::string_view kNoun = "sample";
  static constexpr std::size_t kMinString = 4;
  static constexpr std::size_t kPadding = 3;  // a writer may pad the body to 4 bytes
  static constexpr std::string_view kOutOfMemory = ": out of memory decoding ";
  static constexpr std::string_view kLeftOver =
      " bytes left over after the sample (another type or version on this topic, or a corrupt sample)";
  template <class V>
  static constexpr bool block = false;
  template <class E>
  static constexpr bool run = is_number<E>;
  template <class V>
  static constexpr std::size_t scalar_size = [] {
    if constexpr (std::is_enum_v<V>) return sizeof(enum_wire_t<V>);
    else return sizeof(V);
  }();

  template <class S, class V>
  static void put_scalar(S& s, const V& v) {
    if constexpr (std::is_same_v<V, bool>) {
      const std::uint8_t b = v ? 1 : 0;
      s.bytes(&b, 1);
    } else if constexpr (std::is_enum_v<V>) {
      put_number(s, static_cast<enum_wire_t<V>>(v));
    } else {
      put_number(s, v);
    }
  }
  template <class S>
  static void put_count(S& s, std::size_t n) {
    if (n > std::numeric_limits<std::uint32_t>::max() - 1)
      throw std::length_error("horus::cdr::encode: a sequence or string of " + std::to_string(n) +
                              " elements; XCDR1 allows at most 2^32 - 2");
    put_number(s, static_cast<std::uint32_t>(n));
  }
  template <class S>
  static void put_string(S& s, const std::string& v) {
    put_count(s, v.size() + 1);
    s.bytes(v.data(), v.size());
    const char nul = 0;
    s.bytes(&nul, 1);
  }
  template <class S, class E>
  static void put_run(S& s, const E* p, std::size_t n) {
    s.align(sizeof(E));
    s.bytes(p, n * sizeof(E));
  }

  template <class V>
  static bool get_scalar(Reader& r, V& v, const Path& path) {
    if constexpr (std::is_same_v<V, bool>) {
      return wire::get_strict_bool(r, v, path, kNoun);
    } else if constexpr (std::is_enum_v<V>) {
      enum_wire_t<V> raw{};
      if (!get_number(r, raw, path)) return false;
      if constexpr (idlgen::is_idl_enum<V>()) {
        if (raw >= idlgen::idl_enum_count<V>())
          return r.fail(path, ": enum value ", raw, ", expected 0..", idlgen::idl_enum_count<V>() - 1,
                        " (corrupt sample or another version of the type)");
      }
      v = static_cast<V>(raw);
      return true;
    } else {
      return get_number(r, v, path);
    }
  }
  static bool get_count(Reader& r, std::size_t& n, std::size_t min_bytes, const Path& path) {
    std::uint32_t count = 0;
    if (!get_number(r, count, path)) return false;
    if (!r.fits(count, min_bytes)) return r.too_many(path, "count", count, min_bytes, kNoun);
    n = count;
    return true;
  }
  static bool get_string(Reader& r, std::string& v, const Path& path) {
    std::size_t n = 0;
    if (!get_count(r, n, 1, path)) return false;
    if (n == 0) {  // some writers send an empty string as length 0, no NUL
      v.clear();
      return true;
    }
    const auto* p = reinterpret_cast<const char*>(r.here());
    if (p[n - 1] != '\0')
      return r.fail(path, ": a string of ", n, " bytes without its NUL terminator (corrupt sample)");
    v.assign(p, n - 1);
    r.skip(n);
    return true;
  }
  template <class E>
  static bool get_run(Reader& r, E* out, std::size_t n, const Path& path) {
    if (!r.align(sizeof(E)) || !r.numbers(out, n, r.swap)) return r.truncated(path, n * sizeof(E), kNoun);
    return true;
  }
};
}  // namespace detail

/// Bytes encode(msg) writes (the sample body, without the encapsulation header or final padding).
/// Throws std::length_error when a sequence or string is longer than XCDR1 allows.
template <Reflected T>
std::size_t encoded_size(const T& msg) {
  wire::Counter c;
  wire::put<detail::Format>(c, msg);
  return c.pos;
}

/// Writes msg into out (at least encoded_size(msg) bytes); returns the bytes written.
/// Throws std::length_error when out is too small (nothing is written past it).
template <Reflected T>
std::size_t encode(const T& msg, std::span<std::byte> out) {
  wire::Writer w(out.data(), out.size(), "horus::cdr::encode: the output buffer is smaller than encoded_size(msg)");
  wire::put<detail::Format>(w, msg);
  return w.pos;
}

/// The body of msg in a new buffer.
template <Reflected T>
std::vector<std::byte> encode(const T& msg) {
  std::vector<std::byte> out(encoded_size(msg));
  encode(msg, std::span<std::byte>(out));
  return out;
}

/// Reads a sample body (after the encapsulation header) in the given byte order. Up to 3
/// trailing bytes are accepted as padding; more are an error (a longer type, a wrong type).
/// `sink`, when given, provides the buffers of ByteBuffer fields.
template <Reflected T>
  requires std::is_default_constructible_v<T>
std::expected<T, std::string> decode(std::span<const std::byte> in, bool little_endian = true,
                                     const ByteSink* sink = nullptr) {
  detail::Reader r(in, sink, !little_endian);
  return wire::decode_message<detail::Format, T>(r, in.size());
}

}  // namespace horus::cdr

HORUS_API_END
