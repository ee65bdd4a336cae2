// The functions of horus/msg/control.hpp that produce text with fmt, compiled once here so that
// including the header does not pull in fmt.
#include "horus/msg/control.hpp"

#include <fmt/format.h>

#include <cstddef>
#include <string>

namespace horus::msg {

std::string JointCommand::log_summary() const {
  std::string out = fmt::format("JointCommand({} joints", count());
  std::size_t shown = 0;
  for (; shown < count(); ++shown) {
    const std::size_t i = shown;
    std::string entry;
    switch (modes[i]) {
      case MODE_POSITION: entry = fmt::format("{} pos {:.4g} rad|m", name_at(i), positions[i]); break;
      case MODE_VELOCITY: entry = fmt::format("{} vel {:.4g} rad/s|m/s", name_at(i), velocities[i]); break;
      case MODE_EFFORT: entry = fmt::format("{} effort {:.4g} Nm|N", name_at(i), efforts[i]); break;
      default: entry = fmt::format("{} mode {}", name_at(i), static_cast<int>(modes[i])); break;
    }
    if (out.size() + entry.size() + 2 > 170) break;
    out += shown == 0 ? ": " : ", ";
    out += entry;
  }
  if (shown < count()) out += fmt::format(", +{} more", count() - shown);
  out += ')';
  return out;
}

}  // namespace horus::msg
