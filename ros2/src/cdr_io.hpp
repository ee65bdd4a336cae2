// What the conversions (convert_*.cpp) write and read ROS 2's CDR with: the XCDR1 rules of
// horus/wire/xcdr1.hpp (numbers aligned to their size from the body's first byte, u32 counts,
// strings with their NUL, no padding before the elements of an empty sequence), ROS 2's
// builtin types (Time, Header) and horus's fixed-size text fields. Internal to ros2/src.
//
// A conversion is a struct with the horus type, the ROS 2 type and two functions:
//   template <class S> static void put(Out<S>& o, const Horus& m, const Context& ctx);
//   static bool get(In& in, Horus& m);      // false: in.refusal says why
// make_conversion<C>() makes its table entry (sizing with a wire::Counter, writing with a
// wire::Writer: one put for both, so they cannot disagree).
#pragma once

#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <span>
#include <string>
#include <string_view>
#include <type_traits>

#include "horus/fixed_string.hpp"
#include "horus/reflect.hpp"
#include "horus/ros2/convert.hpp"
#include "horus/wire/reader.hpp"
#include "horus/wire/walk.hpp"

namespace horus::ros2::detail {

inline constexpr std::uint64_t kNsPerSecond = 1'000'000'000;

/// A CDR writer over a wire::Counter (sizing) or a wire::Writer.
template <class S>
struct Out {
  S& s;

  template <class N>
  void num(N v) {
    static_assert(std::is_arithmetic_v<N>);
    s.align(sizeof(N));
    s.bytes(&v, sizeof(N));
  }
  void boolean(bool b) { num<std::uint8_t>(b ? 1 : 0); }
  void count(std::size_t n) { num(static_cast<std::uint32_t>(n)); }
  void string(std::string_view v) {
    count(v.size() + 1);
    s.bytes(v.data(), v.size());
    const char nul = 0;
    s.bytes(&nul, 1);
  }
  template <std::size_t N>
  void string(const std::array<char, N>& v) {
    string(fixed_str_view(v));
  }
  /// Elements of a fixed array or of a sequence after its count (none: no padding).
  template <class N>
  void run(std::span<const N> v) {
    if (v.empty()) return;
    s.align(sizeof(N));
    s.bytes(v.data(), v.size_bytes());
  }
  template <class N>
  void sequence(std::span<const N> v) {
    count(v.size());
    run(v);
  }
  /// builtin_interfaces/msg/Time from ns since the epoch (seconds saturate at 2^31 - 1).
  void time(std::uint64_t ns) {
    const std::uint64_t sec = ns / kNsPerSecond;
    num<std::int32_t>(sec > static_cast<std::uint64_t>(std::numeric_limits<std::int32_t>::max())
                          ? std::numeric_limits<std::int32_t>::max()
                          : static_cast<std::int32_t>(sec));
    num<std::uint32_t>(static_cast<std::uint32_t>(ns % kNsPerSecond));
  }
  /// std_msgs/msg/Header: the stamp and the frame id.
  void header(std::uint64_t ns, std::string_view frame_id) {
    time(ns);
    string(frame_id);
  }
  void vector3(double x, double y, double z) {
    num(x);
    num(y);
    num(z);
  }
};

/// A bounded CDR reader: each get says whether the value was there; on false, `refusal` says
/// why (the field, and what was wrong or over which limit).
struct In {
  In(std::span<const std::byte> body, bool little_endian, const ByteSink* sink, std::string_view ros_type)
      : r(body, sink, !little_endian), type(ros_type) {}

  wire::Reader r;
  std::string_view type;
  Refusal refusal;

  // -- failing ----------------------------------------------------------------------------------
  /// A sample that is not the ROS 2 type: "<type>.<field>: <what>".
  [[gnu::cold]] bool malformed(std::string_view field, std::string_view what) {
    refusal = {true, std::string(type) + "." + std::string(field) + ": " + std::string(what)};
    return false;
  }
  /// A valid sample the horus type cannot hold: "<type>.<field>: <what>".
  [[gnu::cold]] bool over(std::string_view field, std::string_view what) {
    refusal = {false, std::string(type) + "." + std::string(field) + ": " + std::string(what)};
    return false;
  }
  [[gnu::cold]] bool truncated(std::string_view field) {
    return malformed(field, "truncated (" + std::to_string(r.remaining()) + " bytes remain)");
  }

  // -- values ---------------------------------------------------------------------------------
  template <class N>
  bool num(N& v, std::string_view field) {
    static_assert(std::is_arithmetic_v<N>);
    if (!r.align(sizeof(N)) || !r.number(v, r.swap)) return truncated(field);
    return true;
  }
  template <class N>
  N skip_num(std::string_view field, bool& ok) {
    N v{};
    ok = ok && num(v, field);
    return v;
  }
  bool boolean(bool& v, std::string_view field) {
    std::uint8_t b = 0;
    if (!num(b, field)) return false;
    if (b > 1) return malformed(field, "bool byte " + std::to_string(b) + ", expected 0 or 1");
    v = b == 1;
    return true;
  }
  bool count(std::size_t& n, std::size_t min_bytes, std::string_view field) {
    std::uint32_t c = 0;
    if (!num(c, field)) return false;
    if (!r.fits(c, min_bytes))
      return malformed(field, "count " + std::to_string(c) + " needs at least " + std::to_string(std::size_t{c} * min_bytes) +
                                  " bytes, " + std::to_string(r.remaining()) + " remain");
    n = c;
    return true;
  }
  /// A string's bytes (without the NUL), valid while the body is.
  bool string_view(std::string_view& v, std::string_view field) {
    std::size_t n = 0;
    if (!count(n, 1, field)) return false;
    if (n == 0) {  // some writers send an empty string as length 0
      v = {};
      return true;
    }
    const auto* p = reinterpret_cast<const char*>(r.here());
    if (p[n - 1] != '\0') return malformed(field, "a string of " + std::to_string(n) + " bytes without its NUL");
    v = std::string_view(p, n - 1);
    r.skip(n);
    return true;
  }
  bool string(std::string& v, std::string_view field) {
    std::string_view s;
    if (!string_view(s, field)) return false;
    v.assign(s);
    return true;
  }
  /// A string into a horus fixed text field: over its N - 1 characters is refused.
  template <std::size_t N>
  bool string(std::array<char, N>& v, std::string_view field, std::string_view horus_field) {
    std::string_view s;
    if (!string_view(s, field)) return false;
    return text(v, s, field, horus_field);
  }
  template <std::size_t N>
  bool text(std::array<char, N>& v, std::string_view s, std::string_view field, std::string_view horus_field) {
    if (s.size() > N - 1 || s.find('\0') != std::string_view::npos)
      return over(field, std::to_string(s.size()) + " characters ('" + std::string(s.substr(0, 40)) +
                             (s.size() > 40 ? "...'" : "'") + "); " + std::string(horus_field) + " holds " +
                             std::to_string(N - 1));
    v.fill('\0');
    set_fixed_str(v, s);
    return true;
  }
  bool skip_string(std::string_view field) {
    std::string_view s;
    return string_view(s, field);
  }
  /// n numbers into out.
  template <class N>
  bool run(N* out, std::size_t n, std::string_view field) {
    if (n == 0) return true;
    if (!r.align(sizeof(N)) || !r.numbers(out, n, r.swap)) return truncated(field);
    return true;
  }
  /// A sequence of numbers into a horus array of `limit` elements: its length in n; more than
  /// the limit is refused (`what` names the elements: "beams", "joints").
  template <class N>
  bool sequence(N* out, std::size_t limit, std::size_t& n, std::string_view field, std::string_view horus_field,
                std::string_view what) {
    if (!count(n, sizeof(N), field)) return false;
    if (n > limit)
      return over(field, std::to_string(n) + " " + std::string(what) + "; " + std::string(horus_field) + " holds " +
                             std::to_string(limit));
    return run(out, n, field);
  }
  /// builtin_interfaces/msg/Time as ns since the epoch: a time before the epoch is refused.
  bool time(std::uint64_t& ns, std::string_view field) {
    std::int32_t sec = 0;
    std::uint32_t nsec = 0;
    if (!num(sec, field) || !num(nsec, field)) return false;
    if (nsec >= kNsPerSecond)
      return malformed(field, "nanosec " + std::to_string(nsec) + ", expected below 1000000000");
    if (sec < 0) return over(field, "sec " + std::to_string(sec) + "; horus stamps are ns since the epoch, not before");
    ns = static_cast<std::uint64_t>(sec) * kNsPerSecond + nsec;
    return true;
  }
  /// std_msgs/msg/Header: the stamp, and the frame id's text (valid while the body is).
  bool header(std::uint64_t& ns, std::string_view& frame_id) {
    return time(ns, "header.stamp") && string_view(frame_id, "header.frame_id");
  }
  bool vector3(double& x, double& y, double& z, std::string_view field) {
    return num(x, field) && num(y, field) && num(z, field);
  }
  /// After the last field: at most 3 bytes of padding may remain.
  bool end() {
    if (r.remaining() > 3)
      return malformed("(end)", std::to_string(r.remaining()) + " bytes left over after the sample (another type on the topic?)");
    return true;
  }
};

/// The time now, as ns since the epoch: the horus stamp of a ROS 2 type that has none.
inline std::uint64_t now_ns() noexcept {
  return static_cast<std::uint64_t>(
      std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::system_clock::now().time_since_epoch()).count());
}

/// A frame id: the horus field's when it has text, else the rule's.
inline std::string_view frame_or(std::string_view field, std::string_view rule) { return field.empty() ? rule : field; }

/// The table entry of conversion C.
template <class C>
constexpr Conversion make_conversion() {
  using H = typename C::Horus;
  return Conversion{
      horus::type_name<H>(), horus::type_hash<H>, C::kRos, C::kPreferred, C::kLoses,
      [](const void* msg, const Context& ctx) -> std::size_t {
        wire::Counter c;
        Out<wire::Counter> o{c};
        C::put(o, *static_cast<const H*>(msg), ctx);
        return c.pos;
      },
      [](const void* msg, const Context& ctx, std::span<std::byte> body) noexcept {
        try {
          wire::Writer w(body.data(), body.size(), "horus::ros2: the body is smaller than encoded_size");
          Out<wire::Writer> o{w};
          C::put(o, *static_cast<const H*>(msg), ctx);
        } catch (...) {
          std::memset(body.data(), 0, body.size());
        }
      },
      [](std::span<const std::byte> body, bool little_endian, void* out,
         const ByteSink* sink) -> std::expected<void, Refusal> {
        In in(body, little_endian, sink, C::kRos);
        try {
          if (!C::get(in, *static_cast<H*>(out)) || !in.end()) return std::unexpected(std::move(in.refusal));
        } catch (const std::bad_alloc&) {
          return std::unexpected(Refusal{true, std::string(C::kRos) + ": out of memory"});
        }
        return {};
      }};
}

// The conversions of each file, by domain.
std::span<const Conversion> geometry_conversions() noexcept;  // convert_geometry.cpp
std::span<const Conversion> sensor_conversions() noexcept;    // convert_sensor.cpp
std::span<const Conversion> vision_conversions() noexcept;    // convert_vision.cpp
std::span<const Conversion> navigation_conversions() noexcept;  // convert_navigation.cpp

}  // namespace horus::ros2::detail
