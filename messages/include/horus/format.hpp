// fmt formatting of every reflected message, and log_summary().
//
//   fmt::format("{}", pose)  ->  Pose2D { x: 1, y: 2, theta: 0.5, timestamp_ns: 0 }
//
// Char arrays print as quoted text, other arrays and sequences as [a, b, c],
// enums through an ADL to_string(E) when one exists (else their number), and
// nested messages recursively. horus::log_summary(msg) calls the message's own
// summary: a free function log_summary(const T&) found by argument-dependent lookup
// (beside the type, in its namespace), else a member msg.log_summary() (large
// messages have one: "LaserScan(360 ranges, ...)"), else the full format.
#pragma once

#include <fmt/format.h>

#include <string>
#include <string_view>
#include <type_traits>

#include "horus/fixed_string.hpp"
#include "horus/reflect.hpp"

#include "horus/export.hpp"

HORUS_API_BEGIN

namespace horus::reflect::detail {

template <class E>
concept HasEnumToString = std::is_enum_v<E> && requires(E e) {
  { to_string(e) } -> std::convertible_to<std::string_view>;
};

inline std::string_view short_type_name(std::string_view qualified) {
  const auto pos = qualified.rfind("::");
  return pos == std::string_view::npos ? qualified : qualified.substr(pos + 2);
}

template <class Out, class V>
Out format_value(Out out, const V& v) {
  if constexpr (std::is_same_v<V, bool>) {
    return fmt::format_to(out, "{}", v);
  } else if constexpr (std::is_same_v<V, char>) {
    return fmt::format_to(out, "{}", static_cast<int>(v));
  } else if constexpr (std::is_integral_v<V> && sizeof(V) == 1) {
    return fmt::format_to(out, "{}", static_cast<int>(v));
  } else if constexpr (std::is_arithmetic_v<V>) {
    return fmt::format_to(out, "{}", v);
  } else if constexpr (ReflectedEnum<V>) {
    const std::string_view name = enum_name(v);
    if (name.empty()) return format_value(out, static_cast<std::underlying_type_t<V>>(v));
    return fmt::format_to(out, "{}", name);
  } else if constexpr (HasEnumToString<V>) {
    return fmt::format_to(out, "{}", std::string_view(to_string(v)));
  } else if constexpr (std::is_enum_v<V>) {
    return format_value(out, static_cast<std::underlying_type_t<V>>(v));
  } else if constexpr (std::is_same_v<V, std::string>) {
    return fmt::format_to(out, "\"{}\"", v);
  } else if constexpr (is_char_array<V>::value) {
    return fmt::format_to(out, "\"{}\"", fixed_str_view(v));
  } else if constexpr (is_std_array<V>::value || is_std_vector<V>::value) {
    *out++ = '[';
    bool first = true;
    for (const auto& e : v) {
      if (!first) out = fmt::format_to(out, ", ");
      first = false;
      out = format_value(out, e);
    }
    *out++ = ']';
    return out;
  } else {
    static_assert(Reflected<V>, "format_value: not a reflected type");
    out = fmt::format_to(out, "{} {{ ", short_type_name(type_name<V>()));
    bool first = true;
    for_each_field(v, [&](std::string_view name, const auto& field) {
      if (!first) out = fmt::format_to(out, ", ");
      first = false;
      out = fmt::format_to(out, "{}: ", name);
      out = format_value(out, field);
    });
    return fmt::format_to(out, " }}");
  }
}

template <class T>
concept HasLogSummary = requires(const T& t) {
  { t.log_summary() } -> std::convertible_to<std::string>;
};

// A free log_summary(const T&) beside T: this deleted one stops ordinary lookup here, so that
// only argument-dependent lookup finds one (horus::log_summary is an object, never found so).
void log_summary() = delete;
template <class T>
concept HasFreeLogSummary = requires(const T& t) {
  { log_summary(t) } -> std::convertible_to<std::string>;
};
template <class T>
std::string free_log_summary(const T& t) {
  return std::string(log_summary(t));
}

}  // namespace horus::reflect::detail

template <horus::Reflected T>
struct fmt::formatter<T> {
  constexpr auto parse(format_parse_context& ctx) {
    auto it = ctx.begin();
    if (it != ctx.end() && *it != '}') throw format_error("horus messages take no format spec: use \"{}\"");
    return it;
  }
  template <class FormatContext>
  auto format(const T& msg, FormatContext& ctx) const {
    return horus::reflect::detail::format_value(ctx.out(), msg);
  }
};

namespace horus {

/// The full text of a message, e.g. "Pose2D { x: 1, y: 2, theta: 0.5, timestamp_ns: 0 }".
template <Reflected T>
std::string to_string(const T& msg) {
  std::string out;
  reflect::detail::format_value(std::back_inserter(out), msg);
  return out;
}

namespace reflect::detail {
struct LogSummaryFn {
  template <class T>
  std::string operator()(const T& msg) const {
    if constexpr (HasFreeLogSummary<T>) {
      return free_log_summary(msg);
    } else if constexpr (HasLogSummary<T>) {
      return std::string(msg.log_summary());
    } else if constexpr (Reflected<T>) {
      return horus::to_string(msg);
    } else {
      return fmt::format("{}", msg);
    }
  }
};
}  // namespace reflect::detail

/// A short, human-readable line for logs (a verbose topic's traffic: TopicOptions::verbose): the
/// message's own summary, a free `std::string log_summary(const T&)` in T's namespace or a member
/// `log_summary() const`, else to_string(). An object, so that calls never find it by
/// argument-dependent lookup in place of a message's own overload.
inline constexpr reflect::detail::LogSummaryFn log_summary{};

}  // namespace horus

HORUS_API_END
