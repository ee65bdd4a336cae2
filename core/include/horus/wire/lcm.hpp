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

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <expected>
#include <limits>
#include <span>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

#include "horus/byte_buffer.hpp"
#include "horus/reflect.hpp"
#include "horus/wire/lcm_mapping.hpp"
#include "horus/wire/mapping.hpp"
#include "horus/wire/reader.hpp"
#include "horus/wire/walk.hpp"

#include "horus/export.hpp"

HORUS_API_BEGIN

namespace horus::lcm {

namespace detail {
using reflect::detail::is_std_array;
using reflect::detail::is_std_vector;
using wire::is_number;
using wire::Path;
using wire::Reader;
namespace map = idlgen::lcm;

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
// The wire: the shared walk (horus/wire/walk.hpp) with big-endian numbers, no padding.

template <class W>
W to_big(W v) noexcept {
  return ::horus::wire::byteswap_number(v);
}

/// "0x" and 16 hex digits.
std::string hex64(std::uint64_t v);  // core/src/wire/lcm.cpp
/// "<type>: fingerprint <got>, expected <want> (...)": a message of another LCM type.
std::string fingerprint_error(std::string_view type, std::uint64_t got, std::uint64_t want);

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

template <class S>
void put_length(S& s, std::size_t n, const char* what) {
  if (n > map::kMaxLength)
    throw std::length_error(std::string("horus::lcm::encode: a ") + what + " of " + std::to_string(n) +
                            " elements; LCM lengths are int32 (at most 2^31 - 1)");
  const auto v = static_cast<std::int32_t>(n);
  s.swapped(&v, 1);
}

// A length member: an int32 from 0 to what the remaining bytes can hold.
inline bool get_length(Reader& r, std::size_t& n, std::size_t min_bytes, const Path& path) {
  std::int32_t raw = 0;
  if (!r.number(raw, true)) return r.truncated(path, 4, "message");
  if (raw < 0) return r.fail(path, ": length ", raw, " is negative (corrupt message)");
  if (!r.fits(static_cast<std::uint64_t>(raw), min_bytes))
    return r.too_many(path, "length", static_cast<std::uint64_t>(raw), min_bytes, "message");
  n = static_cast<std::size_t>(raw);
  return true;
}

/// LCM's primitives for the shared walk: big-endian numbers of the widths in lcm_mapping.hpp
/// (unsigned types widened), int32 lengths, strings with their NUL, no padding.
struct Format {
  static constexpr std::string_view kNoun = "message";
  static constexpr std::size_t kMinString = 5;
  static constexpr std::size_t kPadding = 0;
  static constexpr std::string_view kOutOfMemory = ": out of memory decoding ";
  static constexpr std::string_view kLeftOver =
      " bytes left over after the message (another version of the type, or a corrupt message)";
  template <class V>
  static constexpr bool block = false;
  // Runs of numbers that travel as themselves (bytes, or numbers LCM does not widen).
  template <class E>
  static constexpr bool run = is_number<E> && (sizeof(E) == 1 || std::is_same_v<wire_t<E>, E>);
  template <class V>
  static constexpr std::size_t scalar_size = sizeof(wire_t<V>);

  template <class S, class V>
  static void put_scalar(S& s, const V& v) {
    if constexpr (std::is_same_v<V, bool>) {
      const auto b = static_cast<std::uint8_t>(v ? 1 : 0);
      s.bytes(&b, 1);
    } else {
      const auto w = static_cast<wire_t<V>>(v);
      s.swapped(&w, 1);
    }
  }
  template <class S>
  static void put_count(S& s, std::size_t n) {
    put_length(s, n, "variable-size array");
  }
  template <class S>
  static void put_string(S& s, const std::string& v) {
    if (std::memchr(v.data(), '\0', v.size()) != nullptr)
      throw std::invalid_argument("horus::lcm::encode: a string with a NUL byte inside; LCM strings end at the "
                                  "first NUL, so it cannot be sent whole");
    put_length(s, v.size() + 1, "string");
    s.bytes(v.data(), v.size());
    const std::uint8_t nul = 0;
    s.bytes(&nul, 1);
  }
  template <class S, class E>
  static void put_run(S& s, const E* p, std::size_t n) {
    if constexpr (sizeof(E) == 1) s.bytes(p, n);
    else s.swapped(p, n);
  }

  template <class V>
  static bool get_scalar(Reader& r, V& v, const Path& path) {
    wire_t<V> raw{};
    if (!r.number(raw, true)) return r.truncated(path, sizeof(raw), kNoun);
    if constexpr (std::is_same_v<V, bool>) {
      v = raw != 0;  // C programs store booleans in an int8_t
    } else if constexpr (std::is_enum_v<V> && idlgen::is_idl_enum<V>()) {
      if (raw < 0 || static_cast<std::size_t>(raw) >= idlgen::idl_enum_count<V>())
        return r.fail(path, ": enum value ", raw, ", expected 0..", idlgen::idl_enum_count<V>() - 1,
                      " (corrupt message or another version of the type)");
      v = static_cast<V>(raw);
    } else {
      using I = typename unenum<V>::type;
      if constexpr (std::is_integral_v<I> && !std::is_same_v<wire_t<V>, I> && sizeof(wire_t<V>) > sizeof(I)) {
        // A widened unsigned integer: the value must fit.
        if (raw < 0 || static_cast<std::uint64_t>(raw) > std::numeric_limits<I>::max())
          return r.fail(path, ": value ", raw, " is out of range for a ", sizeof(I) * 8,
                        "-bit unsigned field (expected 0..", std::numeric_limits<I>::max(), ")");
      }
      v = static_cast<V>(static_cast<I>(raw));
    }
    return true;
  }
  static bool get_count(Reader& r, std::size_t& n, std::size_t min_bytes, const Path& path) {
    return get_length(r, n, min_bytes, path);
  }
  static bool get_string(Reader& r, std::string& v, const Path& path) {
    std::size_t n = 0;
    if (!get_length(r, n, 1, path)) return false;
    if (n == 0)
      return r.fail(path, ": string length 0; LCM strings count their NUL, so the least is 1 (corrupt message)");
    const auto* p = reinterpret_cast<const char*>(r.here());
    if (p[n - 1] != '\0')
      return r.fail(path, ": a string of ", n, " bytes without its NUL terminator (corrupt message)");
    if (std::memchr(p, '\0', n - 1) != nullptr)  // lcm-gen's C and C++ would read it shorter
      return r.fail(path, ": a string with a NUL byte inside (LCM strings end at the first NUL; corrupt message)");
    v.assign(p, n - 1);
    r.skip(n);
    return true;
  }
  template <class E>
  static bool get_run(Reader& r, E* out, std::size_t n, const Path& path) {
    if (!r.numbers(out, n, true)) return r.truncated(path, n * sizeof(E), kNoun);
    return true;
  }
};

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
  wire::Counter c;
  c.pos = 8;
  wire::put<detail::Format>(c, msg);
  return c.pos;
}

/// Writes msg into out (at least encoded_size(msg) bytes); returns the bytes written.
template <Reflected T>
  requires expressible<T>
std::size_t encode(const T& msg, std::span<std::byte> out) {
  static constexpr std::uint64_t kFingerprint = fingerprint<T>();
  wire::Writer w(out.data(), out.size(), "horus::lcm::encode: the output buffer is smaller than encoded_size(msg)");
  w.swapped(&kFingerprint, 1);
  wire::put<detail::Format>(w, msg);
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
  if (in.size() < 8)
    return std::unexpected(std::string(type_name<T>()) + ": " + std::to_string(in.size()) +
                           " bytes, shorter than the 8-byte fingerprint (not an LCM message)");
  detail::Reader r(in, sink);
  std::uint64_t fp = 0;
  r.number(fp, true);
  if (fp != kFingerprint) return std::unexpected(detail::fingerprint_error(type_name<T>(), fp, kFingerprint));
  return wire::decode_message<detail::Format, T>(r, in.size());
}

}  // namespace horus::lcm

HORUS_API_END
