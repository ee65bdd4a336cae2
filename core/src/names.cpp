#include "horus/names.hpp"

#include <fmt/format.h>

#include <string>
#include <vector>

namespace horus {

namespace {
bool is_name_char(char c) {
  return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' || c == '.' ||
         c == '-';
}

std::string printable(char c) {
  if (c >= 0x20 && c < 0x7f) return fmt::format("'{}'", c);
  return fmt::format("byte 0x{:02x}", static_cast<unsigned char>(c));
}

// The segments of a dot-separated name.
std::vector<std::string_view> segments(std::string_view s) {
  std::vector<std::string_view> out;
  std::size_t start = 0;
  for (;;) {
    const std::size_t dot = s.find('.', start);
    out.push_back(s.substr(start, dot == std::string_view::npos ? std::string_view::npos : dot - start));
    if (dot == std::string_view::npos) return out;
    start = dot + 1;
  }
}

bool match_from(const std::vector<std::string_view>& pat, std::size_t pi, const std::vector<std::string_view>& name,
                std::size_t ni) {
  for (; pi < pat.size(); ++pi, ++ni) {
    if (pat[pi] == "**") {
      for (std::size_t skip = ni; skip <= name.size(); ++skip)
        if (match_from(pat, pi + 1, name, skip)) return true;
      return false;
    }
    if (ni >= name.size() || (pat[pi] != "*" && pat[pi] != name[ni])) return false;
  }
  return ni == name.size();
}

}  // namespace

Result<void> validate_topic_name(std::string_view name) {
  constexpr std::string_view rule =
      "expected 1 to 128 characters from letters, digits, '_', '.', '-', in dot-separated segments "
      "(e.g. 'sensors.imu', 'robot_1.cmd_vel')";
  if (name.empty()) return fail(Errc::InvalidName, fmt::format("invalid topic name '': the name is empty; {}", rule));
  if (name.size() > kMaxTopicNameLength)
    return fail(Errc::InvalidName, fmt::format("invalid topic name '{}...': {} characters is too long; {}",
                                               name.substr(0, 32), name.size(), rule));
  for (std::size_t i = 0; i < name.size(); ++i) {
    const char c = name[i];
    if (!is_name_char(c)) {
      const std::string hint = c == '/' ? " ('/' is not allowed: use '.' as the separator)" : "";
      return fail(Errc::InvalidName, fmt::format("invalid topic name '{}': {} at position {} is not allowed{}; {}",
                                                 name, printable(c), i, hint, rule));
    }
  }
  if (name.front() == '.' || name.back() == '.')
    return fail(Errc::InvalidName,
                fmt::format("invalid topic name '{}': it starts or ends with '.'; {}", name, rule));
  if (name.find("..") != std::string_view::npos)
    return fail(Errc::InvalidName, fmt::format("invalid topic name '{}': it has an empty segment ('..'); {}", name, rule));
  if (name.front() == '-')
    return fail(Errc::InvalidName, fmt::format("invalid topic name '{}': it starts with '-'; {}", name, rule));
  return {};
}

Result<void> check_topic_pattern(std::string_view pattern) {
  const auto rule = "expected dot-separated segments of letters, digits, '_' and '-', or '*' (one segment) or '**' "
                    "(any number of segments), e.g. \"fleet.**\" or \"*.camera\"";
  if (pattern.empty()) return fail(Errc::Config, fmt::format("empty pattern; {}", rule));
  for (std::string_view seg : segments(pattern)) {
    if (seg.empty()) return fail(Errc::Config, fmt::format("pattern '{}' has an empty segment; {}", pattern, rule));
    if (seg == "*" || seg == "**") continue;
    for (char c : seg) {
      if (c == '*')
        return fail(Errc::Config,
                    fmt::format("pattern '{}': '*' must be a whole segment (segment '{}'); {}", pattern, seg, rule));
      const bool ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' || c == '-';
      if (!ok) return fail(Errc::Config, fmt::format("pattern '{}': character '{}' is not allowed; {}", pattern, c, rule));
    }
  }
  return {};
}

bool topic_pattern_matches(std::string_view pattern, std::string_view topic) noexcept {
  try {
    return match_from(segments(pattern), 0, segments(topic), 0);
  } catch (...) {
    return false;
  }
}

}  // namespace horus
