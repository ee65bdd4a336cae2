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

#include <algorithm>
#include <bit>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <expected>
#include <limits>
#include <new>
#include <span>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

#include "horus/byte_buffer.hpp"
#include "horus/wire/local.hpp"
#include "horus/wire/mapping.hpp"
#include "horus/reflect.hpp"

namespace horus::cdr {

static_assert(std::endian::native == std::endian::little, "horus::cdr encodes on a little-endian host");

/// A decode() option: where the bytes of ByteBuffer fields go (horus/byte_buffer.hpp).
using ByteSink = horus::ByteSink;

namespace detail {
using reflect::detail::is_std_array;
using reflect::detail::is_std_vector;

template <class V>
inline constexpr bool is_number = std::is_arithmetic_v<V> && !std::is_same_v<V, bool>;

// The wire integer of an enum: u32 for an IDL enum, else its underlying type.
template <class E>
using enum_wire_t = std::conditional_t<idlgen::is_idl_enum<E>(), std::uint32_t, std::underlying_type_t<E>>;

// Counts bytes (Sink for sizing) or writes them (Sink for encoding); both track the position.
struct Counter {
  std::size_t pos = 0;
  void align(std::size_t a) noexcept { pos = (pos + a - 1) & ~(a - 1); }
  void bytes(const void*, std::size_t n) noexcept { pos += n; }
};

class Writer {
 public:
  Writer(std::byte* out, std::size_t size) noexcept : base_(out), size_(size) {}
  void align(std::size_t a) {
    const std::size_t to = (pos + a - 1) & ~(a - 1);
    check(to - pos);
    std::memset(base_ + pos, 0, to - pos);
    pos = to;
  }
  void bytes(const void* src, std::size_t n) {
    check(n);
    if (n != 0) std::memcpy(base_ + pos, src, n);
    pos += n;
  }
  std::size_t pos = 0;

 private:
  void check(std::size_t n) const {
    if (n > size_ - pos) throw std::length_error("horus::cdr::encode: the output buffer is smaller than encoded_size(msg)");
  }
  std::byte* base_;
  std::size_t size_;
};

template <class S, class N>
void put_number(S& s, N v) {
  s.align(sizeof(N));
  s.bytes(&v, sizeof(N));
}

template <class S>
void put_count(S& s, std::size_t n) {
  if (n > std::numeric_limits<std::uint32_t>::max() - 1)
    throw std::length_error("horus::cdr::encode: a sequence or string of " + std::to_string(n) +
                            " elements; XCDR1 allows at most 2^32 - 2");
  put_number(s, static_cast<std::uint32_t>(n));
}

template <class S, class V>
void put(S& s, const V& v) {
  if constexpr (std::is_same_v<V, bool>) {
    const std::uint8_t b = v ? 1 : 0;
    s.bytes(&b, 1);
  } else if constexpr (is_number<V>) {
    put_number(s, v);
  } else if constexpr (std::is_enum_v<V>) {
    put_number(s, static_cast<enum_wire_t<V>>(v));
  } else if constexpr (std::is_same_v<V, std::string>) {
    put_count(s, v.size() + 1);
    s.bytes(v.data(), v.size());
    const char nul = 0;
    s.bytes(&nul, 1);
  } else if constexpr (is_std_vector<V>::value) {
    using E = typename V::value_type;
    put_count(s, v.size());
    if constexpr (is_number<E>) {
      if (!v.empty()) {
        s.align(sizeof(E));
        s.bytes(v.data(), v.size() * sizeof(E));
      }
    } else {
      for (const auto& e : v) put(s, e);
    }
  } else if constexpr (is_std_array<V>::value) {
    using E = typename V::value_type;
    if constexpr (is_number<E>) {
      if constexpr (std::tuple_size_v<V> != 0) {
        s.align(sizeof(E));
        s.bytes(v.data(), std::tuple_size_v<V> * sizeof(E));
      }
    } else {
      for (const auto& e : v) put(s, e);
    }
  } else {
    static_assert(Reflected<V>, "horus::cdr: not a reflected message or supported field type");
    reflect::for_each_field(v, [&](std::string_view, const auto& f) { put(s, f); });
  }
}

// Fewest bytes an encoded V can take (ignoring alignment): bounds a corrupt count.
template <class V>
constexpr std::size_t min_size() {
  if constexpr (std::is_same_v<V, bool> || is_number<V>) {
    return sizeof(V);
  } else if constexpr (std::is_enum_v<V>) {
    return sizeof(enum_wire_t<V>);
  } else if constexpr (std::is_same_v<V, std::string> || is_std_vector<V>::value) {
    return 4;
  } else if constexpr (is_std_array<V>::value) {
    return std::tuple_size_v<V> * min_size<typename V::value_type>();
  } else {
    std::size_t n = 0;
    reflect::for_each_field_desc<V>([&](const auto& fd) { n += min_size<typename std::remove_cvref_t<decltype(fd)>::type>(); });
    return n;
  }
}

// Where a value sits ("horus::msg::LaserScan.ranges[3]"), made into text only on failure:
// the local codec's.
using Path = codec::detail::Path;

class Reader {
 public:
  Reader(std::span<const std::byte> in, bool little_endian, const ByteSink* byte_sink = nullptr) noexcept
      : base_(in.data()), size_(in.size()), swap_(!little_endian), sink(byte_sink) {}
  std::size_t remaining() const noexcept { return size_ - pos_; }
  std::size_t position() const noexcept { return pos_; }
  bool swap() const noexcept { return swap_; }
  // Skips alignment padding; false when the padding itself runs past the end.
  bool align(std::size_t a) noexcept {
    const std::size_t to = (pos_ + a - 1) & ~(a - 1);
    if (to > size_) return false;
    pos_ = to;
    return true;
  }
  bool bytes(void* dst, std::size_t n) noexcept {
    if (n > remaining()) return false;
    if (n != 0) std::memcpy(dst, base_ + pos_, n);
    pos_ += n;
    return true;
  }
  const std::byte* here() const noexcept { return base_ + pos_; }
  void skip(std::size_t n) noexcept { pos_ += n; }
  std::string error;

 private:
  const std::byte* base_;
  std::size_t size_;
  std::size_t pos_ = 0;
  bool swap_;

 public:
  const ByteSink* sink;
};

template <class N>
N byteswap_number(N v) noexcept {
  if constexpr (sizeof(N) == 1) {
    return v;
  } else {
    using U = std::conditional_t<sizeof(N) == 2, std::uint16_t, std::conditional_t<sizeof(N) == 4, std::uint32_t, std::uint64_t>>;
    return std::bit_cast<N>(std::byteswap(std::bit_cast<U>(v)));
  }
}

template <class N>
bool get_number(Reader& r, N& v, const Path& path) {
  if (!r.align(sizeof(N)) || !r.bytes(&v, sizeof(N))) {
    r.error = path.text() + ": needs " + std::to_string(sizeof(N)) + " bytes, " + std::to_string(r.remaining()) +
              " remain (truncated sample)";
    return false;
  }
  if (r.swap()) v = byteswap_number(v);
  return true;
}

// Reads a u32 count and checks that `count` elements of at least `min_bytes` each fit.
inline bool get_count(Reader& r, std::uint32_t& count, std::size_t min_bytes, const Path& path) {
  if (!get_number(r, count, path)) return false;
  if (count > r.remaining() / std::max<std::size_t>(min_bytes, 1)) {
    r.error = path.text() + ": count " + std::to_string(count) + " needs at least " +
              std::to_string(static_cast<std::uint64_t>(count) * std::max<std::size_t>(min_bytes, 1)) + " bytes, " +
              std::to_string(r.remaining()) + " remain (corrupt or truncated sample)";
    return false;
  }
  return true;
}

template <class N, class Out>
bool get_numbers(Reader& r, Out* out, std::size_t n, const Path& path) {
  if (n == 0) return true;
  if (!r.align(sizeof(N)) || n > r.remaining() / sizeof(N)) {
    r.error = path.text() + ": needs " + std::to_string(n * sizeof(N)) + " bytes, " + std::to_string(r.remaining()) +
              " remain (truncated sample)";
    return false;
  }
  r.bytes(out, n * sizeof(N));
  if (r.swap())
    for (std::size_t i = 0; i < n; ++i) out[i] = byteswap_number(out[i]);
  return true;
}

template <class V>
bool get(Reader& r, V& v, const Path& path) {
  if constexpr (std::is_same_v<V, bool>) {
    std::uint8_t b = 0;
    if (!r.bytes(&b, 1)) {
      r.error = path.text() + ": needs 1 byte, 0 remain (truncated sample)";
      return false;
    }
    if (b > 1) {
      r.error = path.text() + ": bool byte " + std::to_string(b) + ", expected 0 or 1 (corrupt sample)";
      return false;
    }
    v = b == 1;
    return true;
  } else if constexpr (is_number<V>) {
    return get_number(r, v, path);
  } else if constexpr (std::is_enum_v<V>) {
    enum_wire_t<V> raw{};
    if (!get_number(r, raw, path)) return false;
    if constexpr (idlgen::is_idl_enum<V>()) {
      if (raw >= idlgen::idl_enum_count<V>()) {
        r.error = path.text() + ": enum value " + std::to_string(raw) + ", expected 0.." +
                  std::to_string(idlgen::idl_enum_count<V>() - 1) + " (corrupt sample or another version of the type)";
        return false;
      }
    }
    v = static_cast<V>(raw);
    return true;
  } else if constexpr (std::is_same_v<V, std::string>) {
    std::uint32_t n = 0;
    if (!get_count(r, n, 1, path)) return false;
    if (n == 0) {  // some writers send an empty string as length 0, no NUL
      v.clear();
      return true;
    }
    const auto* p = reinterpret_cast<const char*>(r.here());
    if (p[n - 1] != '\0') {
      r.error = path.text() + ": a string of " + std::to_string(n) + " bytes without its NUL terminator (corrupt sample)";
      return false;
    }
    v.assign(p, n - 1);
    r.skip(n);
    return true;
  } else if constexpr (is_std_vector<V>::value) {
    using E = typename V::value_type;
    std::uint32_t n = 0;
    if (!get_count(r, n, min_size<E>(), path)) return false;
    if constexpr (is_number<E> && sizeof(E) == 1) {
      if constexpr (std::is_same_v<V, ByteBuffer>) {
        if (r.sink != nullptr && r.sink->place != nullptr && !r.sink->place(r.sink->context, n, v)) {
          r.error = path.text() + ": no buffer for " + std::to_string(n) + " bytes (every pool slot is in use)";
          return false;
        }
      }
      const auto* p = reinterpret_cast<const E*>(r.here());
      v.assign(p, p + n);  // checked by get_count
      r.skip(n);
      return true;
    } else if constexpr (is_number<E>) {
      v.resize(n);
      return get_numbers<E>(r, v.data(), n, path);
    } else {
      // Grow as elements decode: a corrupt count costs at most what the bytes can hold.
      v.clear();
      v.reserve(std::min<std::size_t>(n, 4096));
      for (std::uint32_t i = 0; i < n; ++i) {
        v.emplace_back();
        if (!get(r, v.back(), Path{&path, {}, i})) return false;
      }
      return true;
    }
  } else if constexpr (is_std_array<V>::value) {
    using E = typename V::value_type;
    if constexpr (is_number<E>) {
      return get_numbers<E>(r, v.data(), v.size(), path);
    } else {
      for (std::size_t i = 0; i < v.size(); ++i)
        if (!get(r, v[i], Path{&path, {}, i})) return false;
      return true;
    }
  } else {
    bool ok = true;
    reflect::for_each_field(v, [&](std::string_view name, auto& f) {
      if (ok) ok = get(r, f, Path{&path, name});
    });
    return ok;
  }
}

}  // namespace detail

/// Bytes encode(msg) writes (the sample body, without the encapsulation header or final padding).
/// Throws std::length_error when a sequence or string is longer than XCDR1 allows.
template <Reflected T>
std::size_t encoded_size(const T& msg) {
  detail::Counter c;
  detail::put(c, msg);
  return c.pos;
}

/// Writes msg into out (at least encoded_size(msg) bytes); returns the bytes written.
/// Throws std::length_error when out is too small (nothing is written past it).
template <Reflected T>
std::size_t encode(const T& msg, std::span<std::byte> out) {
  detail::Writer w(out.data(), out.size());
  detail::put(w, msg);
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
  T msg{};
  detail::Reader r(in, little_endian, sink);
  try {
    if (!detail::get(r, msg, detail::Path{nullptr, type_name<T>()})) return std::unexpected(std::move(r.error));
  } catch (const std::bad_alloc&) {
    return std::unexpected(std::string(type_name<T>()) + ": out of memory decoding " + std::to_string(in.size()) + " bytes");
  } catch (const std::length_error& e) {
    return std::unexpected(std::string(type_name<T>()) + ": " + e.what());
  }
  if (r.remaining() > 3)
    return std::unexpected(std::string(type_name<T>()) + ": " + std::to_string(r.remaining()) +
                           " bytes left over after the sample (another type or version on this topic, or a corrupt sample)");
  return msg;
}

}  // namespace horus::cdr
