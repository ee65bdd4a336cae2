// The functions of horus/msg/control.hpp that produce text with fmt, compiled once here so that
// including the header does not pull in fmt.
#include "horus/msg/control.hpp"

#include <fmt/format.h>

#include <cstddef>
#include <string>

#include "summary_list.hpp"

namespace horus::msg {

std::string JointCommand::log_summary() const {
  std::string out = fmt::format("JointCommand({} joints", count());
  detail::append_summary_list(out, count(), [&](std::size_t i) {
    switch (modes[i]) {
      case MODE_POSITION: return fmt::format("{} pos {:.4g} rad|m", name_at(i), positions[i]);
      case MODE_VELOCITY: return fmt::format("{} vel {:.4g} rad/s|m/s", name_at(i), velocities[i]);
      case MODE_EFFORT: return fmt::format("{} effort {:.4g} Nm|N", name_at(i), efforts[i]);
      default: return fmt::format("{} mode {}", name_at(i), static_cast<int>(modes[i]));
    }
  });
  return out;
}

}  // namespace horus::msg
