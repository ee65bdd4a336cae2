// Time messages: Clock (simulation / replay time broadcast) and TimeReference
// (offset to an external time source such as GPS, NTP or PTP).
//
// Layout and helpers follow HORUS clock.rs (the spec only names the types).
// Times are nanoseconds; clock_ns and time_ref_ns are on the clock they name,
// realtime_ns and timestamp_ns are wall-clock nanoseconds since the epoch.
#pragma once

#include <array>
#include <chrono>
#include <cstdint>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>

#include "horus/fixed_string.hpp"
#include "horus/reflect.hpp"

#include "horus/export.hpp"

HORUS_API_BEGIN

namespace horus::msg {

// ---------------------------------------------------------------------------
/// The time all nodes should use, published on a well-known topic (e.g.
/// "clock") by a simulator or a log player, or from the wall clock.
struct Clock {
  static constexpr std::uint8_t SOURCE_WALL = 0;    ///< wall-clock time
  static constexpr std::uint8_t SOURCE_SIM = 1;     ///< simulation time
  static constexpr std::uint8_t SOURCE_REPLAY = 2;  ///< log playback time

  std::uint64_t clock_ns{};      ///< ns, the current time on the clock `source` names
  std::uint64_t realtime_ns{};   ///< ns since the epoch (wall clock) when clock_ns was read
  double sim_speed{};            ///< playback rate: 1 = real time, 2 = twice as fast, 0.5 = half
  std::uint8_t paused{};         ///< 1 = paused, 0 = running
  std::uint8_t source{};         ///< SOURCE_WALL, SOURCE_SIM or SOURCE_REPLAY
  std::uint64_t timestamp_ns{};  ///< ns since the epoch when published

  /// Wall-clock time now_ns (ns since the epoch) in all three time fields, speed 1, running.
  static constexpr Clock wall_clock(std::uint64_t now_ns) noexcept {
    return Clock{now_ns, now_ns, 1.0, 0, SOURCE_WALL, now_ns};
  }
  /// The same, reading std::chrono::system_clock now.
  static Clock wall_clock() noexcept {
    const auto since_epoch = std::chrono::system_clock::now().time_since_epoch();
    const auto ns = std::chrono::duration_cast<std::chrono::nanoseconds>(since_epoch).count();
    return wall_clock(ns > 0 ? static_cast<std::uint64_t>(ns) : 0);
  }
  /// Simulation time sim_ns at playback rate speed, running. realtime_ns and
  /// timestamp_ns are set to wall_ns (HORUS stamps them with the wall clock;
  /// here the caller passes it, or leaves 0 to stamp later).
  static constexpr Clock sim_time(std::uint64_t sim_ns, double speed, std::uint64_t wall_ns = 0) noexcept {
    return Clock{sim_ns, wall_ns, speed, 0, SOURCE_SIM, wall_ns};
  }
  /// Log playback time replay_ns at playback rate speed, running; wall_ns as sim_time().
  static constexpr Clock replay_time(std::uint64_t replay_ns, double speed, std::uint64_t wall_ns = 0) noexcept {
    return Clock{replay_ns, wall_ns, speed, 0, SOURCE_REPLAY, wall_ns};
  }

  /// Nanoseconds of clock time from earlier to this one; 0 when earlier is
  /// later (clock time went back, e.g. a replay was rewound).
  constexpr std::uint64_t elapsed_since(const Clock& earlier) const noexcept {
    return clock_ns >= earlier.clock_ns ? clock_ns - earlier.clock_ns : 0;
  }

  /// True when paused is non-zero.
  constexpr bool is_paused() const noexcept { return paused != 0; }
  /// Sets paused to 1 or 0.
  constexpr void set_paused(bool pause) noexcept { paused = static_cast<std::uint8_t>(pause ? 1 : 0); }
  /// A copy with paused set to 1 or 0 (HORUS's builder form of set_paused).
  [[nodiscard]] constexpr Clock with_paused(bool pause) const noexcept {
    Clock c = *this;
    c.set_paused(pause);
    return c;
  }

  friend constexpr bool operator==(const Clock&, const Clock&) = default;
};
HORUS_REFLECT(Clock, clock_ns, realtime_ns, sim_speed, paused, source, timestamp_ns)

// ---------------------------------------------------------------------------
/// The offset between this machine's clock and an external reference:
/// offset_ns = local time - reference time, measured when the reference read
/// time_ref_ns. Subscribers correct local stamps with correct_timestamp().
struct TimeReference {
  std::uint64_t time_ref_ns{};    ///< ns, the reference's time
  std::array<char, 32> source{};  ///< reference name ("gps", "ntp", "ptp"), NUL-terminated, at most 31 characters
  std::int64_t offset_ns{};       ///< local time - reference time, ns
  std::uint64_t timestamp_ns{};   ///< ns since the epoch when published

  /// A reference reading from source_name, or nullopt when the name does not
  /// fit (at most 31 characters, no NUL; HORUS Rust cuts it instead). The
  /// timestamp is left 0.
  static constexpr std::optional<TimeReference> create(std::uint64_t ref_ns, std::string_view source_name,
                                                       std::int64_t offset) noexcept {
    TimeReference t{};
    if (!t.set_source(source_name)) return std::nullopt;
    t.time_ref_ns = ref_ns;
    t.offset_ns = offset;
    return t;
  }
  /// The spec's TimeReference::new(): throwing form of create(),
  /// std::invalid_argument when the name does not fit.
  static TimeReference make(std::uint64_t ref_ns, std::string_view source_name, std::int64_t offset) {
    if (auto t = create(ref_ns, source_name, offset)) return *t;
    throw std::invalid_argument("TimeReference source '" + std::string(source_name) + "' has " +
                                std::to_string(source_name.size()) + " characters; at most 31 fit");
  }

  /// Sets the source name; returns false, changing nothing, when it does not fit.
  constexpr bool set_source(std::string_view name) noexcept { return set_fixed_str(source, name); }
  constexpr std::string_view source_str() const noexcept { return fixed_str_view(source); }
  /// HORUS's name for source_str().
  constexpr std::string_view source_name() const noexcept { return source_str(); }

  /// A local timestamp (ns) moved onto the reference's clock: local_ns -
  /// offset_ns, saturating at 0 and at the largest u64 instead of wrapping
  /// (every offset works, including the most negative i64).
  constexpr std::uint64_t correct_timestamp(std::uint64_t local_ns) const noexcept {
    constexpr std::uint64_t kMax = std::numeric_limits<std::uint64_t>::max();
    if (offset_ns >= 0) {
      const auto ahead = static_cast<std::uint64_t>(offset_ns);
      return local_ns >= ahead ? local_ns - ahead : 0;
    }
    // |offset_ns| without overflowing for INT64_MIN.
    const std::uint64_t behind = static_cast<std::uint64_t>(-(offset_ns + 1)) + 1;
    return local_ns <= kMax - behind ? local_ns + behind : kMax;
  }

  friend constexpr bool operator==(const TimeReference&, const TimeReference&) = default;
};
HORUS_REFLECT(TimeReference, time_ref_ns, source, offset_ns, timestamp_ns)

static_assert(horus::reflect::is_fixed_size<Clock>, "Clock must be trivially copyable and standard layout");
static_assert(horus::reflect::is_fixed_size<TimeReference>,
              "TimeReference must be trivially copyable and standard layout");

// The standard messages of this header (Topic<T> takes their network codecs from the library).
HORUS_STANDARD_MESSAGES(Clock, TimeReference)

}  // namespace horus::msg

HORUS_API_END
