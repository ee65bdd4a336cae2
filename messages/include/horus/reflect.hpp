// Compile-time reflection for horus messages.
//
// A message declares its fields once:
//
//     namespace horus::msg {
//     struct Pose2D { double x{}; double y{}; double theta{}; std::uint64_t timestamp_ns{}; };
//     HORUS_REFLECT(Pose2D, x, y, theta, timestamp_ns)
//     }
//
// or, for a plain data message, in one go:
//
//     HORUS_MESSAGE(MotorFeedback, (std::uint32_t, motor_id), (float, velocity))
//
// From that list come: a field visitor (name, type, offset) for codecs, the
// qualified type name ("horus::msg::Pose2D"), a stable 64-bit layout hash, and
// (in format.hpp / json.hpp) fmt and JSON rendering. HORUS_REFLECT must be
// written in the namespace of the struct (it defines functions found by ADL).
// Members must be public. A field type that contains a comma
// (std::array<double, 3>) needs parentheses-free spelling in HORUS_MESSAGE: use
// a `using` alias there; HORUS_REFLECT takes only names and has no such limit.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <tuple>
#include <type_traits>
#include <utility>
#include <vector>

// ---------------------------------------------------------------------------
// Preprocessor iteration (C++20 __VA_OPT__): HORUS_PP_FOR_EACH(m, d, a, b, c)
// expands to m(d, a) m(d, b) m(d, c); the _COMMA form separates with commas.
// The rescans below allow up to 342 arguments.
#define HORUS_PP_PARENS ()
#define HORUS_PP_EXPAND(...) HORUS_PP_EXPAND3(HORUS_PP_EXPAND3(HORUS_PP_EXPAND3(HORUS_PP_EXPAND3(__VA_ARGS__))))
#define HORUS_PP_EXPAND3(...) HORUS_PP_EXPAND2(HORUS_PP_EXPAND2(HORUS_PP_EXPAND2(HORUS_PP_EXPAND2(__VA_ARGS__))))
#define HORUS_PP_EXPAND2(...) HORUS_PP_EXPAND1(HORUS_PP_EXPAND1(HORUS_PP_EXPAND1(HORUS_PP_EXPAND1(__VA_ARGS__))))
#define HORUS_PP_EXPAND1(...) __VA_ARGS__

#define HORUS_PP_FOR_EACH(m, d, ...) __VA_OPT__(HORUS_PP_EXPAND(HORUS_PP_FE_STEP(m, d, __VA_ARGS__)))
#define HORUS_PP_FE_STEP(m, d, a, ...) m(d, a) __VA_OPT__(HORUS_PP_FE_AGAIN HORUS_PP_PARENS(m, d, __VA_ARGS__))
#define HORUS_PP_FE_AGAIN() HORUS_PP_FE_STEP

#define HORUS_PP_FOR_EACH_COMMA(m, d, ...) __VA_OPT__(HORUS_PP_EXPAND(HORUS_PP_FEC_STEP(m, d, __VA_ARGS__)))
#define HORUS_PP_FEC_STEP(m, d, a, ...) m(d, a) __VA_OPT__(, HORUS_PP_FEC_AGAIN HORUS_PP_PARENS(m, d, __VA_ARGS__))
#define HORUS_PP_FEC_AGAIN() HORUS_PP_FEC_STEP

#include "horus/export.hpp"

HORUS_API_BEGIN

namespace horus::reflect {

/// Empty tag that carries a type to ADL-found reflection functions.
template <class T>
struct tag {};

/// Describes one data member: its name, member pointer and byte offset.
template <class C, class M>
struct Field {
  using class_type = C;
  using type = M;
  std::string_view name;
  M C::*ptr;
  std::size_t offset;

  constexpr const M& get(const C& obj) const noexcept { return obj.*ptr; }
  constexpr M& get(C& obj) const noexcept { return obj.*ptr; }
};

template <class C, class M>
constexpr Field<C, M> make_field(std::string_view name, M C::*ptr, std::size_t offset) noexcept {
  return Field<C, M>{name, ptr, offset};
}

/// The Field descriptors of a type, in declaration order: a flat aggregate (std::tuple's
/// constructors cost about 15 ms of compile time per message, a second for the catalogue).
template <std::size_t I, class F>
struct FieldLeaf {
  F field;
};
template <class Seq, class... F>
struct FieldListImpl;
template <std::size_t... I, class... F>
struct FieldListImpl<std::index_sequence<I...>, F...> : FieldLeaf<I, F>... {
  static constexpr std::size_t size = sizeof...(F);
  /// Calls fn(field) for every descriptor, in order.
  template <class Fn>
  constexpr void for_each(Fn&& fn) const {
    (fn(static_cast<const FieldLeaf<I, F>&>(*this).field), ...);
  }
};
template <class... F>
using FieldList = FieldListImpl<std::index_sequence_for<F...>, F...>;

template <class... F>
constexpr FieldList<F...> make_fields(F... f) noexcept {
  return FieldList<F...>{{f}...};
}

namespace detail {
template <std::size_t I, class F>
constexpr const F& leaf(const FieldLeaf<I, F>& l) noexcept {
  return l.field;
}
}  // namespace detail

/// The I-th descriptor of a FieldList: get<0>(fields<Pose2D>()).name == "x".
template <std::size_t I, class L>
constexpr const auto& get(const L& list) noexcept {
  return detail::leaf<I>(list);
}

/// One enumerator of a reflected enum: its name and value.
template <class E>
struct EnumValue {
  std::string_view name;
  E value;
};

/// True for enums declared with HORUS_REFLECT_ENUM.
template <class E>
concept ReflectedEnum = std::is_enum_v<E> && requires { horus_enum_values(tag<std::remove_cv_t<E>>{}); };

/// The enumerators of E, in declaration order.
template <ReflectedEnum E>
constexpr auto enum_values() noexcept {
  return horus_enum_values(tag<std::remove_cv_t<E>>{});
}

/// The enumerator name of e ("Rgb8"), or an empty view when e has no declared name.
template <ReflectedEnum E>
constexpr std::string_view enum_name(E e) noexcept {
  for (const auto& v : enum_values<E>())
    if (v.value == e) return v.name;
  return {};
}

/// The enumerator called `name`, if any.
template <ReflectedEnum E>
constexpr bool enum_from_name(std::string_view name, E& out) noexcept {
  for (const auto& v : enum_values<E>())
    if (v.name == name) {
      out = v.value;
      return true;
    }
  return false;
}

/// True for horus's own standard messages (HORUS_STANDARD_MESSAGES in their headers): a
/// Topic<T> of one takes T's network codecs compiled in the library instead of instantiating them.
template <class T>
concept StandardMessage = requires { horus_standard_message(tag<std::remove_cv_t<T>>{}); };

/// True for types declared with HORUS_REFLECT / HORUS_MESSAGE.
template <class T>
concept Reflected = requires { horus_fields(tag<std::remove_cv_t<T>>{}); };

/// The Field descriptors of T (a FieldList), in declaration order.
template <Reflected T>
constexpr auto fields() noexcept {
  return horus_fields(tag<std::remove_cv_t<T>>{});
}

template <Reflected T>
inline constexpr std::size_t field_count = decltype(fields<T>())::size;

/// Calls f(field_descriptor) for every field of T, in order.
template <Reflected T, class F>
constexpr void for_each_field_desc(F&& f) {
  fields<T>().for_each(f);
}

/// Calls f(name, value) for every field of obj, in order (value is a reference).
template <class T, class F>
  requires Reflected<std::remove_cvref_t<T>>
constexpr void for_each_field(T&& obj, F&& f) {
  for_each_field_desc<std::remove_cvref_t<T>>([&](const auto& fd) { f(fd.name, obj.*(fd.ptr)); });
}

namespace detail {
template <class T>
constexpr auto raw_type_name() noexcept {
  return std::string_view{__PRETTY_FUNCTION__};
}

// Extracts "X" from "... [with T = X]" (GCC) or "... [T = X]" (Clang).
constexpr std::string_view parse_type_name(std::string_view pretty) noexcept {
  const auto key = pretty.find("T = ");
  if (key == std::string_view::npos) return pretty;
  auto start = key + 4;
  auto end = pretty.find_first_of(";]", start);
  if (end == std::string_view::npos) end = pretty.size();
  return pretty.substr(start, end - start);
}

template <class T>
concept HasCustomName = requires { { horus_type_name(tag<T>{}) } -> std::convertible_to<std::string_view>; };

// Parsed once, at compile time: a call of type_name<T>() at run time (a decoder names its type
// in a Path per message) would otherwise search the pretty name again each time.
template <class T>
inline constexpr std::string_view parsed_type_name = parse_type_name(raw_type_name<T>());
}  // namespace detail

/// The fully qualified name of T ("horus::msg::Pose2D"); HORUS_REFLECT_NAMED overrides it.
template <class T>
constexpr std::string_view type_name() noexcept {
  if constexpr (detail::HasCustomName<T>) {
    return horus_type_name(tag<T>{});
  } else {
    return detail::parsed_type_name<T>;
  }
}

// ---------------------------------------------------------------------------
// Layout signature and hash.
//
// The signature is a canonical text of the layout, e.g.
//   horus::msg::Pose2D{f64 x;f64 y;f64 theta;u64 timestamp_ns;}
// Scalars use fixed names (bool char i8 u8 i16 u16 i32 u32 i64 u64 f32 f64),
// fixed arrays are "[E;N]", std::string is "string", std::vector<E> is
// "seq<E>", enums are "enum Name:U", nested messages are expanded in place.
// The hash is 64-bit FNV-1a of that text: identical on every build and
// machine, and different when a field's name, type, order or array size changes.

namespace detail {
template <class T>
struct is_std_array : std::false_type {};
template <class E, std::size_t N>
struct is_std_array<std::array<E, N>> : std::true_type {};
// std::array<char, N>: a fixed text field (see fixed_string.hpp).
template <class T>
struct is_char_array : std::false_type {};
template <std::size_t N>
struct is_char_array<std::array<char, N>> : std::true_type {};
template <class T>
struct is_std_vector : std::false_type {};
template <class E, class A>
struct is_std_vector<std::vector<E, A>> : std::true_type {};

struct Fnv1a {
  std::uint64_t h = 0xcbf29ce484222325ULL;
  constexpr void put(std::string_view s) noexcept {
    for (char c : s) {
      h ^= static_cast<unsigned char>(c);
      h *= 0x100000001b3ULL;
    }
  }
};

struct StringSink {
  std::string s;
  void put(std::string_view p);  // messages/src/reflect.cpp: a call per part, not an inlined append
};

template <class Sink>
constexpr void put_number(Sink& sink, std::size_t n) {
  char buf[24]{};
  std::size_t i = sizeof(buf);
  do {
    buf[--i] = static_cast<char>('0' + n % 10);
    n /= 10;
  } while (n != 0);
  sink.put(std::string_view(buf + i, sizeof(buf) - i));
}

template <class T>
constexpr std::string_view scalar_name() noexcept {
  if constexpr (std::is_same_v<T, bool>) return "bool";
  else if constexpr (std::is_same_v<T, char>) return "char";
  else if constexpr (std::is_floating_point_v<T> && sizeof(T) == 4) return "f32";
  else if constexpr (std::is_floating_point_v<T> && sizeof(T) == 8) return "f64";
  else if constexpr (std::is_integral_v<T> && std::is_signed_v<T>) {
    if constexpr (sizeof(T) == 1) return "i8";
    else if constexpr (sizeof(T) == 2) return "i16";
    else if constexpr (sizeof(T) == 4) return "i32";
    else return "i64";
  } else if constexpr (std::is_integral_v<T>) {
    if constexpr (sizeof(T) == 1) return "u8";
    else if constexpr (sizeof(T) == 2) return "u16";
    else if constexpr (sizeof(T) == 4) return "u32";
    else return "u64";
  } else {
    return {};
  }
}

template <class T>
inline constexpr bool is_scalar_field = std::is_arithmetic_v<T> && !std::is_same_v<T, long double>;
}  // namespace detail

/// True when T is a type a reflected field may have.
template <class T>
constexpr bool is_supported_field_type() {
  if constexpr (detail::is_scalar_field<T> || std::is_enum_v<T> || Reflected<T> ||
                std::is_same_v<T, std::string>) {
    return true;
  } else if constexpr (std::is_same_v<T, std::vector<bool>>) {
    return false;  // not a container of bools (no data()); use std::vector<std::uint8_t>
  } else if constexpr (detail::is_std_array<T>::value || detail::is_std_vector<T>::value) {
    return is_supported_field_type<typename T::value_type>();
  } else {
    return false;
  }
}

/// Writes the canonical signature of type T into sink (which has put(string_view)).
template <class T, class Sink>
constexpr void describe_type(Sink& sink) {
  static_assert(is_supported_field_type<T>(),
                "horus reflection: unsupported field type; use bool, char, fixed-width integers, float, double, "
                "enums, std::array, std::vector, std::string or another reflected message");
  if constexpr (detail::is_scalar_field<T>) {
    sink.put(detail::scalar_name<T>());
  } else if constexpr (std::is_enum_v<T>) {
    sink.put("enum ");
    sink.put(type_name<T>());
    sink.put(":");
    sink.put(detail::scalar_name<std::underlying_type_t<T>>());
    if constexpr (ReflectedEnum<T>) {
      // Enumerators are part of the contract (IDL and LCM constants come from them).
      sink.put("{");
      for (const auto& v : enum_values<T>()) {
        sink.put(v.name);
        sink.put("=");
        const auto raw = static_cast<std::underlying_type_t<T>>(v.value);
        const auto mag = static_cast<std::uint64_t>(raw);
        if (raw < 0) sink.put("-");
        detail::put_number(sink, static_cast<std::size_t>(raw < 0 ? 0 - mag : mag));
        sink.put(";");
      }
      sink.put("}");
    }
  } else if constexpr (std::is_same_v<T, std::string>) {
    sink.put("string");
  } else if constexpr (detail::is_std_array<T>::value) {
    sink.put("[");
    describe_type<typename T::value_type>(sink);
    sink.put(";");
    detail::put_number(sink, std::tuple_size_v<T>);
    sink.put("]");
  } else if constexpr (detail::is_std_vector<T>::value) {
    sink.put("seq<");
    describe_type<typename T::value_type>(sink);
    sink.put(">");
  } else {
    sink.put(type_name<T>());
    sink.put("{");
    for_each_field_desc<T>([&](const auto& fd) {
      describe_type<typename std::remove_cvref_t<decltype(fd)>::type>(sink);
      sink.put(" ");
      sink.put(fd.name);
      sink.put(";");
    });
    sink.put("}");
  }
}

/// A short, human-readable type label for catalogues and tools: "f64", "[f32; 360]",
/// "char[32]" (text), "seq<i8>", "string", and the unqualified name of enums and messages.
template <class T>
std::string type_label() {
  if constexpr (detail::is_scalar_field<T>) {
    return std::string(detail::scalar_name<T>());
  } else if constexpr (detail::is_char_array<T>::value) {
    return "char[" + std::to_string(std::tuple_size_v<T>) + "]";
  } else if constexpr (detail::is_std_array<T>::value) {
    return "[" + type_label<typename T::value_type>() + "; " + std::to_string(std::tuple_size_v<T>) + "]";
  } else if constexpr (detail::is_std_vector<T>::value) {
    return "seq<" + type_label<typename T::value_type>() + ">";
  } else if constexpr (std::is_same_v<T, std::string>) {
    return "string";
  } else {
    static_assert(std::is_enum_v<T> || Reflected<T>, "type_label: unsupported field type");
    const std::string_view q = type_name<T>();
    const auto pos = q.rfind("::");
    return std::string(pos == std::string_view::npos ? q : q.substr(pos + 2));
  }
}

/// The canonical layout text of T (see above).
template <Reflected T>
std::string type_signature() {
  detail::StringSink sink;
  describe_type<T>(sink);
  return std::move(sink.s);
}

/// Stable 64-bit layout hash of T, computed at compile time.
template <Reflected T>
inline constexpr std::uint64_t type_hash = [] {
  detail::Fnv1a sink;
  describe_type<T>(sink);
  return sink.h;
}();

/// True for messages that can travel by memcpy (no pointers, no heap).
template <class T>
inline constexpr bool is_fixed_size = std::is_trivially_copyable_v<T> && std::is_standard_layout_v<T>;

}  // namespace horus::reflect

namespace horus {
using reflect::Reflected;
template <class T>
constexpr std::string_view type_name() noexcept {
  return reflect::type_name<T>();
}
template <class T>
inline constexpr std::uint64_t type_hash = reflect::type_hash<T>;
}  // namespace horus

// ---------------------------------------------------------------------------
// The declaration macros.

#define HORUS_REFLECT_FIELD_(T, f) ::horus::reflect::Field<T, decltype(T::f)>{#f, &T::f, offsetof(T, f)}

#define HORUS_REFLECT_FIELDS_(T, ...)                                                     \
  [[maybe_unused]] constexpr auto horus_fields(::horus::reflect::tag<T>) noexcept {       \
    _Pragma("GCC diagnostic push") _Pragma("GCC diagnostic ignored \"-Winvalid-offsetof\"") \
    return ::horus::reflect::make_fields(HORUS_PP_FOR_EACH_COMMA(HORUS_REFLECT_FIELD_, T, __VA_ARGS__)); \
    _Pragma("GCC diagnostic pop")                                                         \
  }

/// Declares the fields of struct T (write it in T's namespace, after T).
#define HORUS_REFLECT(T, ...) HORUS_REFLECT_FIELDS_(T, __VA_ARGS__)

#define HORUS_REFLECT_AS_I_(T, name, member) ::horus::reflect::make_field(#name, &T::member, offsetof(T, member))
#define HORUS_REFLECT_AS_(T, nm) HORUS_REFLECT_AS_I_ HORUS_PP_PREPEND_T_(T, nm)
#define HORUS_PP_PREPEND_T_(T, nm) (T, HORUS_PP_UNPAREN_ nm)
#define HORUS_PP_UNPAREN_(...) __VA_ARGS__

/// For classes with private members: fields under a public name, as (name, member) pairs.
///   class Image { ... std::uint32_t width_; HORUS_REFLECT_FRIEND(Image) };
///   HORUS_REFLECT_AS(Image, (width, width_), (data, data_))
#define HORUS_REFLECT_AS(T, ...)                                                               \
  [[maybe_unused]] constexpr auto horus_fields(::horus::reflect::tag<T>) noexcept {            \
    _Pragma("GCC diagnostic push") _Pragma("GCC diagnostic ignored \"-Winvalid-offsetof\"")   \
    return ::horus::reflect::make_fields(HORUS_PP_FOR_EACH_COMMA(HORUS_REFLECT_AS_, T, __VA_ARGS__));  \
    _Pragma("GCC diagnostic pop")                                                              \
  }

/// Inside a class with private reflected members: lets HORUS_REFLECT / HORUS_REFLECT_AS see them.
#define HORUS_REFLECT_FRIEND(T) friend constexpr auto horus_fields(::horus::reflect::tag<T>) noexcept;

/// Same, with an explicit type name (for renamed or versioned types).
#define HORUS_REFLECT_NAMED(T, NAME, ...)                                                          \
  [[maybe_unused]] constexpr std::string_view horus_type_name(::horus::reflect::tag<T>) noexcept { \
    return NAME;                                                                                    \
  }                                                                                                 \
  HORUS_REFLECT_FIELDS_(T, __VA_ARGS__)

#define HORUS_STANDARD_MESSAGE_(unused, T) \
  [[maybe_unused]] constexpr bool horus_standard_message(::horus::reflect::tag<T>) noexcept { return true; }
/// For horus's own messages only (messages/include/horus/msg/): marks them standard.
#define HORUS_STANDARD_MESSAGES(...) HORUS_PP_FOR_EACH(HORUS_STANDARD_MESSAGE_, ~, __VA_ARGS__)

#define HORUS_REFLECT_ENUMERATOR_(E, v) ::horus::reflect::EnumValue<E>{#v, E::v}

/// Declares the enumerators of enum E (write it in E's namespace, after E):
///   enum class ImageEncoding : std::uint8_t { Mono8, Rgb8 };
///   HORUS_REFLECT_ENUM(ImageEncoding, Mono8, Rgb8)
/// Gives enum_values<E>(), enum_name(e), enum_from_name(), and an ADL to_string(e)
/// ("Rgb8", or "" for a value with no enumerator). JSON and fmt print the name.
#define HORUS_REFLECT_ENUM(E, ...)                                                                    \
  [[maybe_unused]] constexpr auto horus_enum_values(::horus::reflect::tag<E>) noexcept {              \
    return std::array{HORUS_PP_FOR_EACH_COMMA(HORUS_REFLECT_ENUMERATOR_, E, __VA_ARGS__)};            \
  }                                                                                                   \
  [[maybe_unused]] constexpr std::string_view to_string(E e) noexcept { return ::horus::reflect::enum_name(e); }

#define HORUS_MESSAGE_MEMBER_I_(type, name) type name{};
#define HORUS_MESSAGE_MEMBER_(unused, tf) HORUS_MESSAGE_MEMBER_I_ tf
#define HORUS_MESSAGE_NAME_I_(type, name) name
#define HORUS_MESSAGE_NAME_(unused, tf) HORUS_MESSAGE_NAME_I_ tf

/// Declares a plain message struct and its reflection in one go:
///   HORUS_MESSAGE(MotorFeedback, (std::uint32_t, motor_id), (float, velocity))
#define HORUS_MESSAGE(Name, ...)                                   \
  struct Name {                                                    \
    HORUS_PP_FOR_EACH(HORUS_MESSAGE_MEMBER_, ~, __VA_ARGS__)       \
  };                                                               \
  HORUS_REFLECT(Name, HORUS_PP_FOR_EACH_COMMA(HORUS_MESSAGE_NAME_, ~, __VA_ARGS__))

HORUS_API_END
