// ROS 2's topic-name rules (names.hpp), as rcl and rmw validate a fully qualified topic name.
#include "horus/ros2/names.hpp"

#include <fmt/format.h>

#include <cctype>

namespace horus::ros2 {
namespace {

bool alnum(char c) { return std::isalnum(static_cast<unsigned char>(c)) != 0; }

Error bad_name(std::string_view text, std::string_view why) {
  return Error(Errc::InvalidArgument, fmt::format("ROS 2 topic name '{}' {}", text, why));
}

}  // namespace

Result<std::string> topic_name(std::string_view text) {
  std::string name = text.starts_with('/') ? std::string(text) : "/" + std::string(text);
  if (text.empty() || name == "/") return std::unexpected(bad_name(text, "is empty; expected /token[/token...]"));
  if (name.size() > kMaxTopicNameLength)
    return std::unexpected(bad_name(text, fmt::format("has {} characters; ROS 2 allows at most {}", name.size(),
                                                      kMaxTopicNameLength)));
  for (std::size_t i = 0; i < name.size(); ++i) {
    const char c = name[i];
    if (!alnum(c) && c != '_' && c != '/')
      return std::unexpected(
          bad_name(text, fmt::format("has '{}' at {}; expected letters, digits, '_' and '/' between tokens", c, i)));
  }
  if (name.ends_with('/')) return std::unexpected(bad_name(text, "ends with '/'"));
  if (name.find("//") != std::string::npos) return std::unexpected(bad_name(text, "has an empty token ('//')"));
  if (name.find("__") != std::string::npos) return std::unexpected(bad_name(text, "has repeated underscores ('__')"));
  for (std::size_t i = 0; i + 1 < name.size(); ++i)
    if (name[i] == '/' && std::isdigit(static_cast<unsigned char>(name[i + 1])))
      return std::unexpected(bad_name(text, fmt::format("has a token that starts with a digit at {}", i + 1)));
  return name;
}

Result<NodeName> node_name(std::string_view text) {
  NodeName n;
  const auto slash = text.rfind('/');
  n.name = std::string(slash == std::string_view::npos ? text : text.substr(slash + 1));
  const auto bad = [&](std::string_view why) {
    return Error(Errc::InvalidArgument, fmt::format("ROS 2 node name '{}' {}", text, why));
  };
  if (n.name.empty()) return std::unexpected(bad("has no name; expected [/namespace/]name"));
  if (n.name.size() > 255) return std::unexpected(bad("is over 255 characters"));
  if (std::isdigit(static_cast<unsigned char>(n.name.front())) != 0) return std::unexpected(bad("starts with a digit"));
  for (char c : n.name)
    if (!alnum(c) && c != '_')
      return std::unexpected(bad(fmt::format("has '{}'; a node's name has letters, digits and '_'", c)));
  if (slash != std::string_view::npos && slash != 0) {
    auto ns = topic_name(text.substr(0, slash));
    if (!ns) return std::unexpected(bad(fmt::format("has a namespace that is not one: {}", ns.error().message())));
    n.name_space = *ns;
  }
  return n;
}

std::string topic_name_of(std::string_view horus_topic) {
  std::string out = "/";
  for (char c : horus_topic) out += c == '.' ? '/' : c;
  return out;
}

std::string ros_type_of_dds(std::string_view dds_type) {
  constexpr std::string_view kMid = "::msg::dds_::";
  const auto mid = dds_type.find(kMid);
  if (mid == std::string_view::npos || mid == 0 || !dds_type.ends_with('_')) return {};
  const auto name = dds_type.substr(mid + kMid.size(), dds_type.size() - mid - kMid.size() - 1);
  if (name.empty() || name.find(':') != std::string_view::npos) return {};
  return std::string(dds_type.substr(0, mid)) + "/msg/" + std::string(name);
}

std::string horus_topic_of(std::string_view ros_name) {
  std::string out;
  for (char c : ros_name.substr(ros_name.starts_with('/') ? 1 : 0)) out += c == '/' ? '.' : c;
  return out;
}

}  // namespace horus::ros2
