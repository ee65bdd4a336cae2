// Control messages: JointCommand.
#pragma once

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

#include <fmt/format.h>

#include "horus/fixed_string.hpp"
#include "horus/format.hpp"
#include "horus/reflect.hpp"

namespace horus::msg {

// ---------------------------------------------------------------------------
/// Targets for up to 16 named joints. Entries [0, joint_count) are in use;
/// modes[i] says which of positions / velocities / efforts joint i follows (the
/// other two may carry limits). Units as JointState: rad or m, rad/s or m/s,
/// N*m or N.
struct JointCommand {
  static constexpr std::size_t kMaxJoints = 16;
  static constexpr std::uint8_t MODE_POSITION = 0;
  static constexpr std::uint8_t MODE_VELOCITY = 1;
  static constexpr std::uint8_t MODE_EFFORT = 2;

  std::array<std::array<char, 32>, kMaxJoints> joint_names{};
  std::uint8_t joint_count{};
  std::array<double, kMaxJoints> positions{};
  std::array<double, kMaxJoints> velocities{};
  std::array<double, kMaxJoints> efforts{};
  std::array<std::uint8_t, kMaxJoints> modes{};
  std::uint64_t timestamp_ns{};

  /// joint_count, clamped to kMaxJoints (a received message may hold any byte).
  constexpr std::size_t count() const noexcept { return std::min<std::size_t>(joint_count, kMaxJoints); }

  /// Position target (MODE_POSITION) for the joint called name. A joint already
  /// in the command is updated (its mode becomes MODE_POSITION); a new one is
  /// appended. Returns false, changing nothing, when a new joint does not fit:
  /// the command is full, or the name is empty or longer than 31 characters.
  bool add_position(std::string_view name, double position) noexcept {
    return set_target(name, MODE_POSITION, [&](std::size_t i) { positions[i] = position; });
  }
  /// Velocity target (MODE_VELOCITY); same rules as add_position.
  bool add_velocity(std::string_view name, double velocity) noexcept {
    return set_target(name, MODE_VELOCITY, [&](std::size_t i) { velocities[i] = velocity; });
  }
  /// Effort target (MODE_EFFORT); same rules as add_position.
  bool add_effort(std::string_view name, double effort) noexcept {
    return set_target(name, MODE_EFFORT, [&](std::size_t i) { efforts[i] = effort; });
  }

  /// The name of joint i, or "" when i >= joint_count.
  std::string_view name_at(std::size_t i) const noexcept {
    return i < count() ? fixed_str_view(joint_names[i]) : std::string_view{};
  }
  /// The index of the joint called name, if any.
  std::optional<std::size_t> index_of(std::string_view name) const noexcept {
    for (std::size_t i = 0; i < count(); ++i)
      if (fixed_str_view(joint_names[i]) == name) return i;
    return std::nullopt;
  }

  /// "JointCommand(3 joints: shoulder pos 1 rad|m, elbow vel 0.5 rad/s|m/s, wrist effort 2 Nm|N)".
  /// Lists as many joints as fit in about 170 characters, then "+N more": the
  /// line always stays under 200 characters.
  std::string log_summary() const {
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

  friend constexpr bool operator==(const JointCommand&, const JointCommand&) = default;

 private:
  template <class Set>
  bool set_target(std::string_view name, std::uint8_t mode, Set set) noexcept {
    std::size_t i = 0;
    if (const auto found = index_of(name)) {
      i = *found;
    } else {
      i = count();
      if (i >= kMaxJoints || name.empty() || !set_fixed_str(joint_names[i], name)) return false;
      joint_count = static_cast<std::uint8_t>(i + 1);
    }
    set(i);
    modes[i] = mode;
    return true;
  }
};
HORUS_REFLECT(JointCommand, joint_names, joint_count, positions, velocities, efforts, modes, timestamp_ns)

static_assert(horus::reflect::is_fixed_size<JointCommand>,
              "JointCommand must be trivially copyable and standard layout");

}  // namespace horus::msg
