// LCM encoding driven by the reflection: the bytes a program built by lcm-gen from
// horus-idlgen's .lcm files reads and writes, field for field (horus/wire/lcm_mapping.hpp
// has the type table).
//
//   std::uint64_t fp = horus::lcm::fingerprint<Pose2D>();          // lcm-gen's _get_hash()
//   std::size_t n = horus::lcm::encoded_size(pose);                // 8 + the members
//   horus::lcm::encode(pose, buffer);                              // buffer.size() >= n
//   auto back = horus::lcm::decode<Pose2D>(bytes);                 // std::expected<T, std::string>
//
// A message is its 8-byte fingerprint, then its members in order, big-endian, with no padding:
// nested structs carry no fingerprint, fixed arrays no count, a variable-size array's count
// is its num_<field> member, a string is an int32 length + 1, its bytes and a NUL.
// decode() checks the fingerprint (another type on the channel, or another version of this
// one), every length before reading or allocating, strings (length >= 1, NUL at the end),
// enum values, widened unsigned values (a uint16 travels as int32_t: 70000 is refused), and
// refuses bytes left over; the error names the field. A boolean byte other than 0 reads as
// true (C programs store booleans in an int8_t). This header needs no LCM library.
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
#include "horus/wire/lcm_mapping.hpp"
#include "horus/wire/mapping.hpp"
#include "horus/reflect.hpp"

namespace horus::lcm {

namespace detail {
using reflect::detail::is_std_array;
using reflect::detail::is_std_vector;
namespace map = idlgen::lcm;

template <class V>
inline constexpr bool is_number = std::is_arithmetic_v<V> && !std::is_same_v<V, bool>;

// The wire integer or float of a primitive field (see lcm_mapping.hpp).
template <class V>
struct wire {
  using type = V;
};
template <>
struct wire<bool> {
  using type = std::uint8_t;
};
template <>
struct wire<char> {
  using type = std::uint8_t;
};
template <>
struct wire<std::uint16_t> {
  using type = std::int32_t;
};
template <>
struct wire<std::uint32_t> {
  using type = std::int64_t;
};
template <>
struct wire<std::uint64_t> {
  using type = std::int64_t;
};
template <class V>
  requires std::is_enum_v<V>
struct wire<V> {
  using type = std::conditional_t<idlgen::is_idl_enum<V>(), std::int32_t,
                                  typename wire<std::underlying_type_t<V>>::type>;
};
template <class V>
using wire_t = typename wire<V>::type;

// The LCM primitive type name of a field's element (hashed into the fingerprint).
template <class V>
constexpr std::string_view primitive_name() {
  if constexpr (std::is_same_v<V, bool>) return map::kBoolean;
  else if constexpr (std::is_same_v<V, char>) return map::kByte;
  else if constexpr (std::is_same_v<V, float>) return map::kFloat;
  else if constexpr (std::is_same_v<V, double>) return map::kDouble;
  else if constexpr (std::is_same_v<V, std::string>) return map::kString;
  else if constexpr (std::is_enum_v<V>) {
    if constexpr (idlgen::is_idl_enum<V>()) return map::kInt32;
    else return primitive_name<std::underlying_type_t<V>>();
  } else {
    static_assert(std::is_integral_v<V>, "horus::lcm: unsupported field type");
    return map::integer_type(sizeof(V), std::is_signed_v<V>);
  }
}

// The element type under fixed arrays (std::array<std::array<float, 3>, 2> -> float).
template <class V>
struct strip_arrays {
  using type = V;
  static constexpr int dims = 0;
};
template <class E, std::size_t N>
struct strip_arrays<std::array<E, N>> {
  using type = typename strip_arrays<E>::type;
  static constexpr int dims = 1 + strip_arrays<E>::dims;
};

template <class V>
constexpr bool expressible();

// What may sit inside an array: anything but another variable-size array, and no zero size.
template <class V>
constexpr bool expressible_element() {
  if constexpr (is_std_vector<V>::value) return false;
  else if constexpr (is_std_array<V>::value)
    return std::tuple_size_v<V> != 0 && expressible_element<typename V::value_type>();
  else if constexpr (Reflected<V>) return expressible<V>();
  else return true;
}

template <class V>
constexpr bool expressible_field() {
  if constexpr (is_std_vector<V>::value) return expressible_element<typename V::value_type>();
  else return expressible_element<V>();
}

template <class V>
constexpr bool expressible() {
  bool ok = true;
  reflect::for_each_field_desc<V>(
      [&](const auto& fd) { ok = ok && expressible_field<typename std::remove_cvref_t<decltype(fd)>::type>(); });
  return ok;
}

template <class T>
constexpr std::uint64_t fingerprint_of();

// The fixed dimensions of V: mode 0 and the decimal size, outermost first.
template <class V>
constexpr std::int64_t hash_fixed_dims(std::int64_t v) {
  if constexpr (is_std_array<V>::value) {
    v = map::hash_update(v, 0);
    v = map::hash_string(v, map::decimal(std::tuple_size_v<V>).view());
    return hash_fixed_dims<typename V::value_type>(v);
  } else {
    return v;
  }
}

// lcm-gen's base hash of one member (and of the num_<field> member a vector brings).
template <class F>
constexpr std::int64_t hash_member(std::int64_t v, std::string_view field) {
  const auto name = map::member_name(field);
  if constexpr (is_std_vector<F>::value) {
    v = map::hash_string(v, map::kLengthPrefix, field);
    v = map::hash_string(v, map::kInt32);
    v = map::hash_update(v, 0);
    using E = typename F::value_type;
    using B = typename strip_arrays<E>::type;
    v = map::hash_string(v, name.field, name.suffix());
    if constexpr (!Reflected<B>) v = map::hash_string(v, primitive_name<B>());
    v = map::hash_update(v, static_cast<char>(1 + strip_arrays<E>::dims));
    v = map::hash_update(v, 1);
    v = map::hash_string(v, map::kLengthPrefix, field);
    return hash_fixed_dims<E>(v);
  } else {
    using B = typename strip_arrays<F>::type;
    v = map::hash_string(v, name.field, name.suffix());
    if constexpr (!Reflected<B>) v = map::hash_string(v, primitive_name<B>());
    v = map::hash_update(v, static_cast<char>(strip_arrays<F>::dims));
    return hash_fixed_dims<F>(v);
  }
}

// A struct-typed member adds its type's fingerprint once, whatever its dimensions.
// The element of a variable-size array, or the field itself.
template <class F>
struct unvector {
  using type = F;
};
template <class F>
  requires is_std_vector<F>::value
struct unvector<F> {
  using type = typename F::value_type;
};

template <class F>
constexpr std::uint64_t nested_term() {
  using B = typename strip_arrays<typename unvector<F>::type>::type;
  if constexpr (Reflected<B>) return fingerprint_of<B>();
  else return 0;
}

template <class T>
constexpr std::uint64_t fingerprint_of() {
  std::int64_t base = map::kHashSeed;
  std::uint64_t nested = 0;
  reflect::for_each_field_desc<T>([&](const auto& fd) {
    using F = typename std::remove_cvref_t<decltype(fd)>::type;
    base = hash_member<F>(base, fd.name);
    nested += nested_term<F>();
  });
  return map::hash_finish(base, nested);
}

// ---------------------------------------------------------------------------------------------
// Encoding.

struct Counter {
  std::size_t pos = 0;
  void bytes(const void*, std::size_t n) noexcept { pos += n; }
  template <class W>
  void number(W) noexcept {
    pos += sizeof(W);
  }
  template <class W>
  void numbers(const W*, std::size_t n) noexcept {
    pos += n * sizeof(W);
  }
};

template <class W>
W to_big(W v) noexcept {
  if constexpr (sizeof(W) == 1) {
    return v;
  } else {
    using U = std::conditional_t<sizeof(W) == 2, std::uint16_t, std::conditional_t<sizeof(W) == 4, std::uint32_t, std::uint64_t>>;
    return std::bit_cast<W>(std::byteswap(std::bit_cast<U>(v)));
  }
}

class Writer {
 public:
  Writer(std::byte* out, std::size_t size) noexcept : base_(out), size_(size) {}
  void bytes(const void* src, std::size_t n) {
    check(n);
    if (n != 0) std::memcpy(base_ + pos, src, n);
    pos += n;
  }
  template <class W>
  void number(W v) {
    check(sizeof(W));
    v = to_big(v);
    std::memcpy(base_ + pos, &v, sizeof(W));
    pos += sizeof(W);
  }
  template <class W>
  void numbers(const W* src, std::size_t n) {
    check(n * sizeof(W));
    for (std::size_t i = 0; i < n; ++i) {
      const W v = to_big(src[i]);
      std::memcpy(base_ + pos + i * sizeof(W), &v, sizeof(W));
    }
    pos += n * sizeof(W);
  }
  std::size_t pos = 0;

 private:
  void check(std::size_t n) const {
    if (n > size_ - pos) throw std::length_error("horus::lcm::encode: the output buffer is smaller than encoded_size(msg)");
  }
  std::byte* base_;
  std::size_t size_;
};

template <class S>
void put_length(S& s, std::size_t n, const char* what) {
  if (n > map::kMaxLength)
    throw std::length_error(std::string("horus::lcm::encode: a ") + what + " of " + std::to_string(n) +
                            " elements; LCM lengths are int32 (at most 2^31 - 1)");
  s.number(static_cast<std::int32_t>(n));
}

template <class S, class V>
void put(S& s, const V& v) {
  if constexpr (std::is_same_v<V, bool>) {
    s.number(static_cast<std::uint8_t>(v ? 1 : 0));
  } else if constexpr (is_number<V> || std::is_enum_v<V>) {
    s.number(static_cast<wire_t<V>>(v));
  } else if constexpr (std::is_same_v<V, std::string>) {
    if (std::memchr(v.data(), '\0', v.size()) != nullptr)
      throw std::invalid_argument("horus::lcm::encode: a string with a NUL byte inside; LCM strings end at the "
                                  "first NUL, so it cannot be sent whole");
    put_length(s, v.size() + 1, "string");
    s.bytes(v.data(), v.size());
    s.number(std::uint8_t{0});
  } else if constexpr (is_std_vector<V>::value) {
    using E = typename V::value_type;
    put_length(s, v.size(), "variable-size array");
    if constexpr (is_number<E> && sizeof(E) == 1) {
      s.bytes(v.data(), v.size());
    } else if constexpr (is_number<E> && std::is_same_v<wire_t<E>, E>) {
      s.numbers(v.data(), v.size());
    } else {
      for (const auto& e : v) put(s, e);
    }
  } else if constexpr (is_std_array<V>::value) {
    using E = typename V::value_type;
    if constexpr (is_number<E> && sizeof(E) == 1) {
      s.bytes(v.data(), v.size());
    } else if constexpr (is_number<E> && std::is_same_v<wire_t<E>, E>) {
      s.numbers(v.data(), v.size());
    } else {
      for (const auto& e : v) put(s, e);
    }
  } else {
    static_assert(Reflected<V>, "horus::lcm: not a reflected message or supported field type");
    reflect::for_each_field(v, [&](std::string_view, const auto& f) { put(s, f); });
  }
}

// ---------------------------------------------------------------------------------------------
// Decoding.

// Fewest bytes an encoded V can take: bounds a corrupt count before allocating.
template <class V>
constexpr std::size_t min_size() {
  if constexpr (std::is_same_v<V, bool> || is_number<V> || std::is_enum_v<V>) {
    return sizeof(wire_t<V>);
  } else if constexpr (std::is_same_v<V, std::string>) {
    return 5;
  } else if constexpr (is_std_vector<V>::value) {
    return 4;
  } else if constexpr (is_std_array<V>::value) {
    return std::tuple_size_v<V> * min_size<typename V::value_type>();
  } else {
    std::size_t n = 0;
    reflect::for_each_field_desc<V>([&](const auto& fd) { n += min_size<typename std::remove_cvref_t<decltype(fd)>::type>(); });
    return n;
  }
}

using Path = codec::detail::Path;

inline std::string hex64(std::uint64_t v) {
  static constexpr char kDigits[] = "0123456789abcdef";
  std::string out = "0x";
  for (int shift = 60; shift >= 0; shift -= 4) out += kDigits[(v >> shift) & 0xf];
  return out;
}

inline std::string fingerprint_error(std::string_view type, std::uint64_t got, std::uint64_t want) {
  return std::string(type) + ": fingerprint " + hex64(got) + ", expected " + hex64(want) +
         " (a message of another LCM type on this channel, another version of the type, or not an LCM message)";
}

class Reader {
 public:
  Reader(std::span<const std::byte> in, const ByteSink* byte_sink) noexcept
      : sink(byte_sink), base_(in.data()), size_(in.size()) {}
  std::size_t remaining() const noexcept { return size_ - pos_; }
  const std::byte* here() const noexcept { return base_ + pos_; }
  void skip(std::size_t n) noexcept { pos_ += n; }
  template <class W>
  bool number(W& v, const Path& path) {
    if (sizeof(W) > remaining()) {
      error = path.text() + ": needs " + std::to_string(sizeof(W)) + " bytes, " + std::to_string(remaining()) +
              " remain (truncated message)";
      return false;
    }
    std::memcpy(&v, base_ + pos_, sizeof(W));
    v = to_big(v);
    pos_ += sizeof(W);
    return true;
  }
  std::string error;
  const ByteSink* sink;

 private:
  const std::byte* base_;
  std::size_t size_;
  std::size_t pos_ = 0;
};

// A length member: an int32 from 0 to what the remaining bytes can hold.
inline bool get_length(Reader& r, std::size_t& n, std::size_t min_bytes, const Path& path) {
  std::int32_t raw = 0;
  if (!r.number(raw, path)) return false;
  if (raw < 0) {
    r.error = path.text() + ": length " + std::to_string(raw) + " is negative (corrupt message)";
    return false;
  }
  n = static_cast<std::size_t>(raw);
  if (n > r.remaining() / std::max<std::size_t>(min_bytes, 1)) {
    r.error = path.text() + ": length " + std::to_string(raw) + " needs at least " +
              std::to_string(n * std::max<std::size_t>(min_bytes, 1)) + " bytes, " + std::to_string(r.remaining()) +
              " remain (corrupt or truncated message)";
    return false;
  }
  return true;
}

// An enum's underlying integer, or the type itself.
template <class V>
struct unenum {
  using type = V;
};
template <class V>
  requires std::is_enum_v<V>
struct unenum<V> {
  using type = std::underlying_type_t<V>;
};

template <class V>
bool get_scalar(Reader& r, V& v, const Path& path) {
  wire_t<V> raw{};
  if (!r.number(raw, path)) return false;
  if constexpr (std::is_same_v<V, bool>) {
    v = raw != 0;
  } else if constexpr (std::is_enum_v<V> && idlgen::is_idl_enum<V>()) {
    if (raw < 0 || static_cast<std::size_t>(raw) >= idlgen::idl_enum_count<V>()) {
      r.error = path.text() + ": enum value " + std::to_string(raw) + ", expected 0.." +
                std::to_string(idlgen::idl_enum_count<V>() - 1) + " (corrupt message or another version of the type)";
      return false;
    }
    v = static_cast<V>(raw);
  } else {
    using I = typename unenum<V>::type;
    if constexpr (std::is_integral_v<I> && !std::is_same_v<wire_t<V>, I> && sizeof(wire_t<V>) > sizeof(I)) {
      // A widened unsigned integer: the value must fit.
      if (raw < 0 || static_cast<std::uint64_t>(raw) > std::numeric_limits<I>::max()) {
        r.error = path.text() + ": value " + std::to_string(raw) + " is out of range for a " +
                  std::to_string(sizeof(I) * 8) + "-bit unsigned field (expected 0.." +
                  std::to_string(std::numeric_limits<I>::max()) + ")";
        return false;
      }
    }
    v = static_cast<V>(static_cast<I>(raw));
  }
  return true;
}

template <class E, class Out>
bool get_numbers(Reader& r, Out* out, std::size_t n, const Path& path) {
  if (n == 0) return true;  // out may be null (an empty vector)
  if (n > r.remaining() / sizeof(E)) {
    r.error = path.text() + ": needs " + std::to_string(n * sizeof(E)) + " bytes, " + std::to_string(r.remaining()) +
              " remain (truncated message)";
    return false;
  }
  std::memcpy(out, r.here(), n * sizeof(E));
  if constexpr (sizeof(E) > 1)
    for (std::size_t i = 0; i < n; ++i) out[i] = to_big(out[i]);
  r.skip(n * sizeof(E));
  return true;
}

template <class V>
bool get(Reader& r, V& v, const Path& path) {
  if constexpr (std::is_same_v<V, bool> || is_number<V> || std::is_enum_v<V>) {
    return get_scalar(r, v, path);
  } else if constexpr (std::is_same_v<V, std::string>) {
    std::size_t n = 0;
    if (!get_length(r, n, 1, path)) return false;
    if (n == 0) {
      r.error = path.text() + ": string length 0; LCM strings count their NUL, so the least is 1 (corrupt message)";
      return false;
    }
    const auto* p = reinterpret_cast<const char*>(r.here());
    if (p[n - 1] != '\0') {
      r.error = path.text() + ": a string of " + std::to_string(n) + " bytes without its NUL terminator (corrupt message)";
      return false;
    }
    if (std::memchr(p, '\0', n - 1) != nullptr) {  // lcm-gen's C and C++ would read it shorter
      r.error = path.text() + ": a string with a NUL byte inside (LCM strings end at the first NUL; corrupt message)";
      return false;
    }
    v.assign(p, n - 1);
    r.skip(n);
    return true;
  } else if constexpr (is_std_vector<V>::value) {
    using E = typename V::value_type;
    std::size_t n = 0;
    if (!get_length(r, n, min_size<E>(), path)) return false;
    if constexpr (is_number<E> && sizeof(E) == 1) {
      if constexpr (std::is_same_v<V, ByteBuffer>) {
        if (r.sink != nullptr && r.sink->place != nullptr && !r.sink->place(r.sink->context, n, v)) {
          r.error = path.text() + ": no buffer for " + std::to_string(n) + " bytes (every pool slot is in use)";
          return false;
        }
      }
      const auto* p = reinterpret_cast<const E*>(r.here());
      v.assign(p, p + n);  // checked by get_length
      r.skip(n);
      return true;
    } else if constexpr (is_number<E> && std::is_same_v<wire_t<E>, E>) {
      if (n == 0) {
        v.clear();
        return true;
      }
      v.resize(n);
      return get_numbers<E>(r, v.data(), n, path);
    } else {
      // Grow as elements decode: a corrupt length costs at most what the bytes can hold.
      v.clear();
      v.reserve(std::min<std::size_t>(n, 4096));
      for (std::size_t i = 0; i < n; ++i) {
        v.emplace_back();
        if (!get(r, v.back(), Path{&path, {}, i})) return false;
      }
      return true;
    }
  } else if constexpr (is_std_array<V>::value) {
    using E = typename V::value_type;
    if constexpr (is_number<E> && (sizeof(E) == 1 || std::is_same_v<wire_t<E>, E>)) {
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

/// True when LCM can express T (no variable-size array of variable-size arrays, no
/// zero-size array); Topic<T> refuses the lcm backend for other types.
template <Reflected T>
inline constexpr bool expressible = detail::expressible<T>();

/// lcm-gen's fingerprint of T's .lcm type (what its generated _get_hash() / getHash() returns).
template <Reflected T>
  requires expressible<T>
constexpr std::uint64_t fingerprint() {
  return detail::fingerprint_of<T>();
}

/// Bytes encode(msg) writes: the 8-byte fingerprint and the members. Throws std::length_error
/// when a string or array is longer than LCM's int32 lengths allow, std::invalid_argument for
/// a string with a NUL byte inside (both are std::logic_error).
template <Reflected T>
  requires expressible<T>
std::size_t encoded_size(const T& msg) {
  detail::Counter c;
  c.pos = 8;
  detail::put(c, msg);
  return c.pos;
}

/// Writes msg into out (at least encoded_size(msg) bytes); returns the bytes written.
template <Reflected T>
  requires expressible<T>
std::size_t encode(const T& msg, std::span<std::byte> out) {
  static constexpr std::uint64_t kFingerprint = fingerprint<T>();
  detail::Writer w(out.data(), out.size());
  w.number(kFingerprint);
  detail::put(w, msg);
  return w.pos;
}

/// The message as LCM bytes, in a new buffer.
template <Reflected T>
  requires expressible<T>
std::vector<std::byte> encode(const T& msg) {
  std::vector<std::byte> out(encoded_size(msg));
  encode(msg, std::span<std::byte>(out));
  return out;
}

/// Reads one LCM message (fingerprint and members). `sink`, when given, provides the buffers
/// of ByteBuffer fields.
template <Reflected T>
  requires expressible<T> && std::is_default_constructible_v<T>
std::expected<T, std::string> decode(std::span<const std::byte> in, const ByteSink* sink = nullptr) {
  static constexpr std::uint64_t kFingerprint = fingerprint<T>();
  T msg{};
  detail::Reader r(in, sink);
  const detail::Path root{nullptr, type_name<T>()};
  std::uint64_t fp = 0;
  if (in.size() < 8)
    return std::unexpected(std::string(type_name<T>()) + ": " + std::to_string(in.size()) +
                           " bytes, shorter than the 8-byte fingerprint (not an LCM message)");
  r.number(fp, root);
  if (fp != kFingerprint)
    return std::unexpected(detail::fingerprint_error(type_name<T>(), fp, kFingerprint));
  try {
    if (!detail::get(r, msg, root)) return std::unexpected(std::move(r.error));
  } catch (const std::bad_alloc&) {
    return std::unexpected(std::string(type_name<T>()) + ": out of memory decoding " + std::to_string(in.size()) + " bytes");
  } catch (const std::length_error& e) {
    return std::unexpected(std::string(type_name<T>()) + ": " + e.what());
  }
  if (r.remaining() != 0)
    return std::unexpected(std::string(type_name<T>()) + ": " + std::to_string(r.remaining()) +
                           " bytes left over after the message (another version of the type, or a corrupt message)");
  return msg;
}

}  // namespace horus::lcm
