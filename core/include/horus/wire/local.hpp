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

#include <algorithm>
#include <array>
#include <bit>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <expected>
#include <limits>
#include <new>
#include <stdexcept>
#include <span>
#include <string>
#include <type_traits>
#include <vector>

#include "horus/reflect.hpp"

namespace horus::codec {

static_assert(std::endian::native == std::endian::little, "the local wire format assumes a little-endian host");

namespace detail {
using reflect::detail::is_std_array;
using reflect::detail::is_std_vector;

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

/// Fewest bytes an encoded V can take (bounds a corrupt element count before allocating).
template <class V>
constexpr std::size_t min_size() {
  if constexpr (std::is_same_v<V, bool>) {
    return 1;
  } else if constexpr (is_raw_decodable<V>) {
    return sizeof(V);
  } else if constexpr (is_sequence<V>) {
    return 4;
  } else if constexpr (is_std_array<V>::value) {
    return std::tuple_size_v<V> * min_size<typename V::value_type>();
  } else {
    static_assert(Reflected<V>, "horus::codec: not a reflected message or supported field type");
    std::size_t n = 0;
    reflect::for_each_field_desc<V>([&](const auto& fd) { n += min_size<typename std::remove_cvref_t<decltype(fd)>::type>(); });
    return n;
  }
}

inline constexpr std::size_t kTooLarge = std::numeric_limits<std::size_t>::max();
inline constexpr std::size_t kMaxCount = std::numeric_limits<std::uint32_t>::max();

constexpr std::size_t sat_add(std::size_t a, std::size_t b) noexcept { return b > kTooLarge - a ? kTooLarge : a + b; }

// kTooLarge when a sequence has more elements than a u32 count can say.
template <class V>
std::size_t size_of(const V& v) {
  if constexpr (std::is_same_v<V, bool>) {
    return 1;
  } else if constexpr (is_raw_decodable<V>) {
    return sizeof(V);
  } else if constexpr (is_sequence<V>) {
    using E = typename V::value_type;
    if (v.size() > kMaxCount) return kTooLarge;
    if constexpr (is_raw_decodable<E>) {
      return 4 + v.size() * sizeof(E);
    } else {
      std::size_t n = 4;
      for (const auto& e : v) n = sat_add(n, size_of(e));
      return n;
    }
  } else if constexpr (is_std_array<V>::value) {
    std::size_t n = 0;
    for (const auto& e : v) n = sat_add(n, size_of(e));
    return n;
  } else {
    std::size_t n = 0;
    reflect::for_each_field(v, [&](std::string_view, const auto& f) { n = sat_add(n, size_of(f)); });
    return n;
  }
}

class Writer {
 public:
  Writer(std::byte* out, std::size_t size) noexcept : p_(out), end_(out + size) {}
  void raw(const void* src, std::size_t n) {
    if (n > static_cast<std::size_t>(end_ - p_))
      throw std::length_error("horus::codec::encode: the output buffer is smaller than encoded_size(msg)");
    if (n != 0) std::memcpy(p_, src, n);
    p_ += n;
  }
  std::byte* position() const noexcept { return p_; }

 private:
  std::byte* p_;
  std::byte* end_;
};

template <class V>
void put(Writer& w, const V& v) {
  if constexpr (std::is_same_v<V, bool>) {
    const std::uint8_t b = v ? 1 : 0;
    w.raw(&b, 1);
  } else if constexpr (is_raw_decodable<V>) {
    w.raw(&v, sizeof(V));
  } else if constexpr (is_sequence<V>) {
    using E = typename V::value_type;
    if (v.size() > kMaxCount)
      throw std::length_error("horus::codec::encode: a sequence of " + std::to_string(v.size()) +
                              " elements; at most 4294967295");
    const auto count = static_cast<std::uint32_t>(v.size());
    w.raw(&count, 4);
    if constexpr (is_raw_decodable<E>) {
      w.raw(v.data(), v.size() * sizeof(E));
    } else {
      for (const auto& e : v) put(w, e);
    }
  } else if constexpr (is_std_array<V>::value) {
    for (const auto& e : v) put(w, e);
  } else {
    reflect::for_each_field(v, [&](std::string_view, const auto& f) { put(w, f); });
  }
}

class Reader {
 public:
  explicit Reader(std::span<const std::byte> in) noexcept : p_(in.data()), end_(in.data() + in.size()) {}
  std::size_t remaining() const noexcept { return static_cast<std::size_t>(end_ - p_); }
  const std::byte* position() const noexcept { return p_; }
  bool raw(void* dst, std::size_t n) noexcept {
    if (n > remaining()) return false;
    if (n != 0) std::memcpy(dst, p_, n);
    p_ += n;
    return true;
  }
  void skip(std::size_t n) noexcept { p_ += n; }
  // Set on the first failure; later reads are skipped.
  std::string error;

 private:
  const std::byte* p_;
  const std::byte* end_;
};

// Where a value sits in the message ("horus::msg::OccupancyGrid.data[3]"): a chain of frames
// on the stack, turned into text only when decoding fails (so success builds no strings).
struct Path {
  const Path* parent = nullptr;
  std::string_view name;           // a field name, or the type name at the root
  std::size_t index = ~std::size_t{0};  // an element index instead of a name

  std::string text() const {
    std::string head = parent ? parent->text() : std::string();
    if (index != ~std::size_t{0}) return head + "[" + std::to_string(index) + "]";
    return parent ? head + "." + std::string(name) : std::string(name);
  }
};

template <class V>
bool get(Reader& r, V& v, const Path& path) {
  if constexpr (std::is_same_v<V, bool>) {
    std::uint8_t b = 0;
    if (!r.raw(&b, 1)) {
      r.error = path.text() + ": needs 1 byte, 0 remain (truncated message)";
      return false;
    }
    if (b > 1) {
      r.error = path.text() + ": bool byte " + std::to_string(b) + ", expected 0 or 1 (corrupt message)";
      return false;
    }
    v = b == 1;
    return true;
  } else if constexpr (is_raw_decodable<V>) {
    if (!r.raw(&v, sizeof(V))) {
      r.error = path.text() + ": needs " + std::to_string(sizeof(V)) + " bytes, " + std::to_string(r.remaining()) +
                " remain (truncated message)";
      return false;
    }
    return true;
  } else if constexpr (is_sequence<V>) {
    using E = typename V::value_type;
    std::uint32_t count = 0;
    if (!r.raw(&count, 4)) {
      r.error = path.text() + ": the element count is cut off (truncated message)";
      return false;
    }
    constexpr std::size_t kMin = std::max<std::size_t>(min_size<E>(), 1);
    if (count > r.remaining() / kMin) {
      r.error = path.text() + ": count " + std::to_string(count) + " needs at least " +
                std::to_string(static_cast<std::uint64_t>(count) * kMin) + " bytes, " +
                std::to_string(r.remaining()) + " remain (corrupt or truncated message)";
      return false;
    }
    if constexpr (is_raw_decodable<E> && sizeof(E) == 1) {
      // Bytes (images, grids, text): one copy, no zero-fill first.
      const auto* p = reinterpret_cast<const unsigned char*>(r.position());
      v.assign(reinterpret_cast<const E*>(p), reinterpret_cast<const E*>(p) + count);
      r.skip(count);
      return true;
    } else if constexpr (is_raw_decodable<E>) {
      v.resize(count);
      return r.raw(v.data(), static_cast<std::size_t>(count) * sizeof(E));  // checked above
    } else {
      // Grow as elements decode: a corrupt count costs at most what the bytes can hold,
      // however much larger sizeof(E) is than its encoding (a std::string is 32 bytes, 4 encoded).
      v.clear();
      v.reserve(std::min<std::size_t>(count, 4096));
      for (std::uint32_t i = 0; i < count; ++i) {
        v.emplace_back();
        if (!get(r, v.back(), Path{&path, {}, i})) return false;
      }
      return true;
    }
  } else if constexpr (is_std_array<V>::value) {
    for (std::size_t i = 0; i < v.size(); ++i)
      if (!get(r, v[i], Path{&path, {}, i})) return false;
    return true;
  } else {
    bool ok = true;
    reflect::for_each_field(v, [&](std::string_view name, auto& f) {
      if (ok) ok = get(r, f, Path{&path, name});
    });
    return ok;
  }
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
  detail::Writer w(out.data(), out.size());
  detail::put(w, msg);
  return static_cast<std::size_t>(w.position() - out.data());
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
  T msg{};
  detail::Reader r(in);
  try {
    if (!detail::get(r, msg, detail::Path{nullptr, type_name<T>()})) return std::unexpected(std::move(r.error));
  } catch (const std::bad_alloc&) {
    return std::unexpected(std::string(type_name<T>()) + ": out of memory while decoding " +
                           std::to_string(in.size()) + " bytes");
  } catch (const std::length_error& e) {
    return std::unexpected(std::string(type_name<T>()) + ": " + e.what());
  }
  if (r.remaining() != 0)
    return std::unexpected(std::string(type_name<T>()) + ": " + std::to_string(r.remaining()) +
                           " bytes left over after the message (corrupt message or wrong type)");
  return msg;
}

}  // namespace horus::codec
