// Topic-name rules, shared by every layer (the local registry, the transports' wire names).
#pragma once

#include <cstddef>
#include <string_view>

#include "horus/error.hpp"

#include "horus/export.hpp"

HORUS_API_BEGIN

namespace horus {

/// Longest topic name accepted.
inline constexpr std::size_t kMaxTopicNameLength = 128;

/// Checks a topic name: 1 to 128 characters from letters, digits, '_', '.', '-';
/// dot-separated segments ("sensors.imu", "robot_1.cmd_vel"); no empty segment,
/// no leading '-'. The error names the offending character and the rule.
Result<void> validate_topic_name(std::string_view name);

/// Checks a pattern: dot-separated segments, each a name segment (letters, digits, '_', '-'),
/// '*' or '**'. The error says what is wrong.
Result<void> check_topic_pattern(std::string_view pattern);
/// Whether `pattern` (checked) matches `topic`: '*' is one segment, '**' any number of them.
bool topic_pattern_matches(std::string_view pattern, std::string_view topic) noexcept;

}  // namespace horus

HORUS_API_END
