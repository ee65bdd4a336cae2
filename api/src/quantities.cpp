// Quantities of the configuration file (horus/config.hpp): bandwidths ("2 MB/s") and durations
// ("100ms"), parsed with errors that say what is wrong and what is expected.
#include <fmt/format.h>

#include <charconv>
#include <span>

#include "horus/config.hpp"

namespace horus {

namespace {
// A number above 0 and a unit from `units` (a quantity of the file: "2 MB/s", "100ms"),
// scaled to the unit's factor and checked against [lo, hi]; an error message naming what was
// wrong and `expected`, or the value. `what` names the kind ("a bandwidth", "a duration").
struct Unit {
  std::string_view name;
  double factor;
};
std::variant<double, std::string> parse_quantity(std::string_view text, std::span<const Unit> units, double lo,
                                                 double hi, std::string_view what, std::string_view range,
                                                 std::string_view expected) {
  std::string_view t = text;
  while (!t.empty() && t.front() == ' ') t.remove_prefix(1);
  while (!t.empty() && t.back() == ' ') t.remove_suffix(1);
  double value = 0;
  const auto [end, ec] = std::from_chars(t.data(), t.data() + t.size(), value);
  if (ec != std::errc{} || !(value > 0)) return fmt::format("'{}' is not {}; {}", text, what, expected);
  std::string_view unit(end, static_cast<std::size_t>(t.data() + t.size() - end));
  while (!unit.empty() && unit.front() == ' ') unit.remove_prefix(1);
  for (const Unit& u : units) {
    if (unit != u.name) continue;
    const double scaled = value * u.factor;
    if (scaled < lo || scaled > hi) return fmt::format("'{}' is out of range ({}); {}", text, range, expected);
    return scaled;
  }
  if (unit.empty()) return fmt::format("'{}' has no unit; {}", text, expected);
  return fmt::format("'{}' has an unknown unit '{}'; {}", text, unit, expected);
}
}  // namespace

std::variant<std::uint64_t, std::string> parse_bandwidth(std::string_view text) {
  static constexpr Unit kUnits[] = {{"", 1},          {"B/s", 1},           {"kB/s", 1e3},      {"MB/s", 1e6},
                                    {"GB/s", 1e9},    {"KiB/s", 1024.0},    {"MiB/s", 1048576.0}, {"GiB/s", 1073741824.0},
                                    {"kbit/s", 125},  {"Mbit/s", 125000},   {"Gbit/s", 125000000}};
  auto q = parse_quantity(text, kUnits, 1, 1e12, "a bandwidth", "1 B/s to 1000 GB/s",
                          "expected bytes per second, or a number with a unit: B/s, kB/s, MB/s, GB/s, KiB/s, MiB/s, "
                          "GiB/s, kbit/s, Mbit/s, Gbit/s (such as \"2 MB/s\" or \"20 Mbit/s\")");
  if (auto* why = std::get_if<std::string>(&q)) return std::move(*why);
  return static_cast<std::uint64_t>(std::get<double>(q));
}

std::variant<std::chrono::nanoseconds, std::string> parse_duration(std::string_view text) {
  static constexpr Unit kUnits[] = {{"ns", 1}, {"us", 1e3}, {"ms", 1e6}, {"s", 1e9}, {"min", 60e9}, {"h", 3600e9}};
  auto q = parse_quantity(text, kUnits, 1, 1e15, "a duration", "1 ns to 11 days",
                          "expected a duration above 0 with a unit: ns, us, ms, s, min or h (such as \"100ms\" or "
                          "\"1.5 s\")");
  if (auto* why = std::get_if<std::string>(&q)) return std::move(*why);
  return std::chrono::nanoseconds(static_cast<std::int64_t>(std::get<double>(q)));
}

}  // namespace horus
