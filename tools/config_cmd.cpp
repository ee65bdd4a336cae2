// horus config check / explain (config_cmd.hpp): a configuration file validated, and what a
// topic name gets from the environment and the file (horus/config.hpp's choose()), and under
// DDS-Security its protection (security_cmd.hpp's governance_spec()).
#include "config_cmd.hpp"

#include <fmt/format.h>

#include <cstdio>
#include <optional>
#include <set>
#include <string>
#include <string_view>
#include <type_traits>
#include <utility>

#include "horus/config.hpp"
#include "horus/ros2/interface.hpp"
#include "horus/ros2/names.hpp"
#include "horus/horus.hpp"
#include "horus/log.hpp"
#include "horus/transport_registry.hpp"
#include "security_cmd.hpp"

namespace horus::tools {

int cmd_config_check(const std::string& file) {
  auto c = horus::Config::load(file);
  if (!c) {
    fmt::print(stderr, "horus config check: {}\n", c.error().message());
    return 1;
  }
  // What only a transport knows (LCM's URL syntax, LCM's refusal of peers): every transport checks
  // its own settings; peers only where the file uses the transport.
  auto net = horus::net::config_of(*c);
  if (!net) {
    fmt::print(stderr, "horus config check: {}\n", net.error().message());
    return 1;
  }
  std::set<std::string> used;
  if (c->network().backend) used.insert(*c->network().backend);
  for (const auto& r : c->rules())
    if (r.backend) used.insert(*r.backend);
  for (const std::string& name : horus::net::transport_names()) {
    const auto* t = horus::net::find_transport(name);
    if (t == nullptr || t->check == nullptr) continue;
    horus::net::Config checked = *net;
    if (!used.contains(name)) checked.peers.clear();  // a transport the file does not use: its own settings only
    if (auto ok = t->check(checked); !ok) {
      fmt::print(stderr, "horus config check: {}\n", ok.error().message());
      return 1;
    }
  }
  fmt::print("{}: valid; {} rule{}\n", file, c->rules().size(), c->rules().size() == 1 ? "" : "s");
  return 0;
}

namespace {

std::string from_where(horus::Source s, const horus::TopicChoice& c) {
  if (s == horus::Source::File && c.rule != nullptr)
    return fmt::format("file {}, line {}: rule '{}'", c.config->file(), c.rule->line, c.rule->match);
  if (s == horus::Source::Environment) return "environment (HORUS_BACKEND)";
  if (s == horus::Source::Default) return "default";
  return std::string(horus::to_string(s));
}

// A fleet topic under DDS-Security: the settings in force (the environment over the file), and
// the protection the fleet's governance gives it when signed from this file's rules.
int print_security(std::string_view topic, const horus::Backend& backend, const horus::Config* config) {
  auto net = horus::net::config_from_environment(config);
  if (!net) {
    fmt::print(stderr, "horus config explain: {}\n", net.error().message());
    return 1;
  }
  const horus::net::Security& s = net->security;
  if (s.mode == horus::net::SecurityMode::Off) {
    fmt::print("  security    {:<16} {}\n", "off", "no security settings (security: or HORUS_SECURITY*), or mode off");
    return 0;
  }
  fmt::print("  security    {:<16} {}: identity '{}' in keystore {}\n", horus::net::to_string(s.mode), s.origin, s.identity,
             s.keystore);
  if (backend.transport() == "lcm") {
    fmt::print("  protection  {:<16} {}\n", "none",
               s.mode == horus::net::SecurityMode::Enforce ? "LCM has no security: the topic is refused under enforce"
                                                           : "LCM has no security: the topic is plain");
    return 0;
  }
  const security::TopicProtection p = security::protection_of(governance_spec(config), topic);
  const horus::TopicRule* rule = p.rule ? protection_rules(config).at(*p.rule) : nullptr;
  fmt::print("  protection  {:<16} {}\n", horus::net::to_string(p.protection),
             rule != nullptr ? fmt::format("file {}, line {}: rule '{}' (once `horus security governance` signs it)",
                                           config->file(), rule->line, rule->match)
                             : "default (no rule with protection: matches; the governance encrypts the rest)");
  return 0;
}

// A setting of the table: its value (or its default value, or what unset means) and its source.
template <class K, class D>
void print_setting(std::string_view key, K of, const std::optional<typename K::type>& v, const D& default_value,
                   std::string_view unset, const std::string& from) {
  std::string value(unset);
  if (v) value = horus::setting::format(of, *v);
  else if constexpr (!std::is_same_v<D, std::nullopt_t>) value = horus::setting::format(of, typename K::type(default_value));
  fmt::print("  {:<11} {:<16} {}\n", key, value, from);
}

// A topic mapped onto ROS 2: its ROS 2 name, DDS topic, type and type hash (the message type's
// preferred ROS 2 type when the mapping names none: explain does not know the message type).
void print_ros2(const std::string& topic, const horus::Ros2Mapping& m) {
  const std::string name = m.name.empty() ? horus::ros2::topic_name_of(topic) : m.name;
  fmt::print("  ROS 2 name  {}{}\n", name, m.name.empty() ? " (from the topic's name)" : "");
  fmt::print("  wire name   {} (DDS topic)\n", horus::ros2::dds_topic(name));
  if (m.type.empty()) {
    fmt::print("  ROS 2 type  the message type's own (docs/ROS2.md: its preferred ROS 2 type, else horus_msgs/msg/<Name>)\n");
    return;
  }
  const auto dds = horus::ros2::parse_type_name(m.type);
  fmt::print("  ROS 2 type  {} (DDS type {})\n", m.type, dds ? dds->dds() : "?");
  if (auto hash = horus::ros2::Interfaces::standard().type_hash(m.type))
    fmt::print("  type hash   {} (USER_DATA typehash=...;)\n", *hash);
  else
    fmt::print("  type hash   that of {} in its package (`horus idl --ros2` prints it)\n", m.type);
}

// The settings of the table (horus/topic_options.hpp), in its order. The scope and backend
// come first (above); a topic whose traffic is not logged shows no level or rate unless set.
void print_settings(const horus::TopicChoice& c) {
  const auto shown = [&](std::string_view key, bool set) { return set || c.verbose || !key.starts_with("log_"); };
#define HORUS_EXPLAIN_ROW(member, Kind, Rule, key, example, dflt, unset, doc)                             \
  if (std::string_view(#member) == "verbose")                                                              \
    fmt::print("  {:<11} {:<16} {}\n", key, c.verbose ? "on" : "off", horus::verbose_origin(c));          \
  HORUS_SETTING_IF_PLAIN_##Rule(if (shown(key, c.member.has_value())) print_setting(                      \
      key, horus::setting::Kind{}, c.member, dflt, unset, from_where(c.member##_from, c));)
  HORUS_TOPIC_SETTINGS(HORUS_EXPLAIN_ROW)
#undef HORUS_EXPLAIN_ROW
  // The CLI's logger reads the same HORUS_LOG_LEVEL as the program would.
  const horus::LogLevel level = c.log_level.value_or(horus::LogLevel::Info);
  if (const std::string hidden = horus::detail::hidden_lines(static_cast<spdlog::level::level_enum>(level));
      c.verbose && !hidden.empty())
    fmt::print("  (hidden: {})\n", hidden);
}

}  // namespace

int cmd_config_explain(const std::string& topic, const std::string& file) {
  if (auto ok = horus::validate_topic_name(topic); !ok) {
    fmt::print(stderr, "horus config explain: {}\n", ok.error().message());
    return 2;
  }
  std::optional<horus::Config> own;
  const horus::Config* config = nullptr;
  if (!file.empty()) {
    auto c = horus::Config::load(file);
    if (!c) {
      fmt::print(stderr, "horus config explain: {}\n", c.error().message());
      return 1;
    }
    own = std::move(*c);
    config = &*own;
  } else {
    auto c = horus::config_from_environment();
    if (!c) {
      fmt::print(stderr, "horus config explain: {}\n", c.error().message());
      return 1;
    }
    config = *c;
  }
  auto choice = horus::choose(topic, horus::TopicOptions{}, config);
  if (!choice) {
    fmt::print(stderr, "horus config explain: {}\n", choice.error().message());
    return 1;
  }
  const auto& c = *choice;
  fmt::print("topic '{}'{}\n", topic, config != nullptr ? fmt::format(" (configuration file {})", config->file()) : "");
  if (c.rule != nullptr) fmt::print("  rule        '{}' (line {})\n", c.rule->match, c.rule->line);
  else fmt::print("  rule        none matches\n");
  fmt::print("  scope       {:<16} {}\n", horus::to_string(c.backend.scope()), from_where(c.backend_from, c));
  if (horus::is_network(c.backend)) {
    fmt::print("  backend     {:<16} {}\n", c.backend.transport(), from_where(c.backend_from, c));
    if (c.ros2 && c.ros2->enabled) print_ros2(topic, *c.ros2);
    else if (auto wire = horus::wire_name(c.backend, topic)) fmt::print("  wire name   {}\n", *wire);
    if (const int rc = print_security(topic, c.backend, config); rc != 0) return rc;
  }
  print_settings(c);
  return 0;
}

}  // namespace horus::tools
