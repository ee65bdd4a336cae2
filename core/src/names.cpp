#include "horus/names.hpp"

#include <fmt/format.h>

#include <string>

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

}  // namespace horus
