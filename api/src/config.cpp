// The configuration file (horus/config.hpp): strict parsing with yaml-cpp, topic patterns, and
// the choice of a topic's settings by precedence. The only place that reads YAML.
#include "horus/config.hpp"

#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <charconv>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <set>
#include <span>
#include <sstream>
#include <type_traits>
#include <utility>

#include "horus/names.hpp"
#include "horus/ros2/names.hpp"
#include "horus/settings.hpp"
#include "horus/shm/ring_layout.hpp"
#include "horus/transport_registry.hpp"

namespace horus {

std::string_view to_string(Source s) noexcept {
  switch (s) {
    case Source::Code: return "code";
    case Source::Environment: return "environment";
    case Source::File: return "file";
    case Source::Default: return "default";
  }
  return "?";
}

namespace {

constexpr std::array<std::string_view, 5> kTopLevelKeys{"network", "fleet", "security", "ros2", "topics"};
constexpr std::array<std::string_view, 1> kRos2Keys{"node"};
constexpr std::array<std::string_view, 3> kSecurityKeys{"mode", "keystore", "identity"};
constexpr std::array<std::string_view, 6> kFleetKeys{"announce", "heartbeat_ms", "announce_ms", "misses", "max_hosts",
                                                      "forget_after"};
constexpr std::array<std::string_view, 6> kNetworkKeys{"backend", "domain_id",     "localhost_only",
                                                       "lcm_url", "peers", "max_bandwidth"};
// A rule's keys: its own and the settings' (horus/topic_options.hpp), as README's table lists them.
const std::vector<std::string_view>& rule_key_names() {
  static const std::vector<std::string_view> names = [] {
    std::vector<std::string_view> out;
    for (const RuleKey& k : rule_keys()) out.push_back(k.key);
    return out;
  }();
  return names;
}

// Parses a YAML document's nodes into a Config, with errors that name the file, line and key.
class Parser {
 public:
  explicit Parser(std::string file) : file_(std::move(file)) {}

  std::string at(const YAML::Node& n, std::string_view key) const {
    return fmt::format("{}, line {}, key '{}'", file_, n.Mark().line + 1, key);
  }
  std::unexpected<Error> bad(const YAML::Node& n, std::string_view key, std::string_view what) const {
    return std::unexpected(Error(Errc::Config, fmt::format("{}: {}", at(n, key), what)));
  }

  // A scalar's text, or an error naming the key and the type expected.
  // A quantity at `key` (a bandwidth, a duration): `parse` gives its value or why it is not one.
  template <class Parse>
  auto quantity(const YAML::Node& n, const std::string& key, std::string_view expected, Parse parse) const
      -> Result<std::remove_cvref_t<decltype(std::get<0>(parse(std::string_view{})))>> {
    auto s = scalar(n, key, expected);
    if (!s) return std::unexpected(s.error());
    auto q = parse(*s);
    if (const auto* why = std::get_if<std::string>(&q)) return bad(n, key, *why);
    return std::get<0>(q);
  }

  Result<std::string> scalar(const YAML::Node& n, std::string_view key, std::string_view expected) const {
    if (!n.IsScalar()) return bad(n, key, fmt::format("expected {}, found {}", expected, kind(n)));
    return n.Scalar();
  }

  Result<void> known_keys(const YAML::Node& map, std::string_view where, std::span<const std::string_view> keys) const {
    std::set<std::string> seen;
    for (const auto& kv : map) {
      if (!kv.first.IsScalar()) return bad(kv.first, where, "a key must be a plain name");
      const std::string k = kv.first.Scalar();
      const std::string path = where.empty() ? k : std::string(where) + "." + k;
      if (std::find(keys.begin(), keys.end(), k) == keys.end())
        return bad(kv.first, path, fmt::format("unknown key; expected {}", setting::listed(keys)));
      if (!seen.insert(k).second) return bad(kv.first, path, "given twice");
    }
    return {};
  }

  Result<std::uint32_t> integer(const YAML::Node& n, std::string_view key, std::uint32_t min, std::uint32_t max,
                                std::string_view what) const {
    auto s = scalar(n, key, what);
    if (!s) return std::unexpected(s.error());
    std::uint64_t v = 0;
    const char* end = s->data() + s->size();
    auto [p, ec] = std::from_chars(s->data(), end, v);
    if (s->empty() || ec != std::errc() || p != end || v < min || v > max)
      return bad(n, key, fmt::format("'{}' is not {}", *s, what));
    return static_cast<std::uint32_t>(v);
  }

  // The setting `key` of the map `n` (at `where`), of kind K, into `out` when present.
  template <class K>
  Result<void> value_at(const YAML::Node& n, const std::string& where, std::string_view key, std::string_view doc, K of,
                        std::optional<typename K::type>& out) const {
    const auto v = n[std::string(key)];
    if (!v) return {};
    const std::string path = where + "." + std::string(key);
    Result<std::string> s;
    if constexpr (std::is_same_v<K, setting::Ros2>) {
      if (v.IsMap()) {  // `ros2: {name: ..., type: ...}`: parsed as the text of its flow form
        YAML::Emitter flow;
        flow << YAML::Flow << v;
        s = std::string(flow.c_str());
      } else {
        s = scalar(v, path, setting::expected(of, doc));
      }
    } else {
      s = scalar(v, path, setting::expected(of, doc));
    }
    if (!s) return std::unexpected(s.error());
    auto value = setting::parse(of, *s, doc);
    if (const auto* why = std::get_if<std::string>(&value)) return bad(v, path, *why);
    out = std::get<0>(value);
    return {};
  }

  Result<bool> boolean(const YAML::Node& n, std::string_view key) const {
    auto s = scalar(n, key, setting::expected(setting::Boolean{}));
    if (!s) return std::unexpected(s.error());
    auto b = setting::parse(setting::Boolean{}, *s);
    if (const auto* why = std::get_if<std::string>(&b)) return bad(n, key, *why);
    return std::get<bool>(b);
  }

  // A registered transport's name (as the registry owns it).
  Result<std::string> transport(const YAML::Node& n, std::string_view key) const {
    auto s = scalar(n, key, "a network backend name");
    if (!s) return std::unexpected(s.error());
    if (const auto* t = net::find_transport(*s)) return std::string(t->name);
    const auto names = net::transport_names();
    std::string valid;
    for (std::size_t i = 0; i < names.size(); ++i) valid += (i == 0 ? "" : ", ") + names[i];
    if (*s == "cyclonedds" || *s == "fastdds" || *s == "lcm")
      return bad(n, key, fmt::format("this build of horus has no {} backend (its Debian package was missing when "
                                     "horus was built); this build has: {}",
                                     *s, valid.empty() ? "none" : valid));
    if (*s == "shm" || *s == "inproc")
      return bad(n, key, fmt::format("'{}' is not a network backend; say `scope: {}` instead; network backends: {}", *s,
                                     *s == "shm" ? "host" : "process", valid));
    return bad(n, key, fmt::format("unknown network backend '{}'; expected {}", *s, valid.empty() ? "none" : valid));
  }

  Result<void> network(const YAML::Node& n, NetworkSection& out) const {
    if (!n.IsDefined() || n.IsNull()) return {};
    if (!n.IsMap()) return bad(n, "network", fmt::format("expected a map of {}, found {}", setting::listed(kNetworkKeys), kind(n)));
    if (auto ok = known_keys(n, "network", kNetworkKeys); !ok) return ok;
    if (const auto v = n["backend"]) {
      auto t = transport(v, "network.backend");
      if (!t) return std::unexpected(t.error());
      out.backend = *t;
    }
    if (const auto v = n["domain_id"]) {
      auto id = integer(v, "network.domain_id", 0, net::kMaxDomainId,
                        fmt::format("a DDS domain id; expected an integer from 0 to {}", net::kMaxDomainId));
      if (!id) return std::unexpected(id.error());
      out.domain_id = *id;
    }
    if (const auto v = n["localhost_only"]) {
      auto b = boolean(v, "network.localhost_only");
      if (!b) return std::unexpected(b.error());
      out.localhost_only = *b;
    }
    if (const auto v = n["lcm_url"]) {
      auto s = scalar(v, "network.lcm_url", "an LCM URL such as \"udpm://239.255.76.67:7667?ttl=1\"");
      if (!s) return std::unexpected(s.error());
      if (s->empty()) return bad(v, "network.lcm_url", "empty; expected an LCM URL such as \"udpm://239.255.76.67:7667?ttl=1\"");
      out.lcm_url = *s;
      out.lcm_url_line = v.Mark().line + 1;
    }
    if (const auto v = n["peers"]) {
      constexpr std::string_view kExpected = "a list of host names or IPv4 addresses, such as [10.0.0.2, robot-3]";
      if (!v.IsSequence()) return bad(v, "network.peers", fmt::format("expected {}, found {}", kExpected, kind(v)));
      std::vector<std::string> peers;
      for (std::size_t i = 0; i < v.size(); ++i) {
        const std::string key = fmt::format("network.peers[{}]", i);
        auto s = scalar(v[i], key, "a host name or an IPv4 address");
        if (!s) return std::unexpected(s.error());
        if (const std::string why = net::check_peer(*s); !why.empty())
          return bad(v[i], key, fmt::format("'{}' {}; expected {}", *s, why, kExpected));
        peers.push_back(*s);
      }
      out.peers = std::move(peers);
      out.peers_line = v.Mark().line + 1;
    }
    if (const auto v = n["max_bandwidth"]) {
      auto b = quantity(v, "network.max_bandwidth", "the host's link budget, a bandwidth such as \"2 MB/s\"",
                        parse_bandwidth);
      if (!b) return std::unexpected(b.error());
      out.max_bandwidth = *b;
    }
    return {};
  }

  Result<void> ros2(const YAML::Node& n, Ros2Section& out) const {
    if (!n.IsDefined() || n.IsNull()) return {};
    if (!n.IsMap()) return bad(n, "ros2", fmt::format("expected a map of {}, found {}", setting::listed(kRos2Keys), kind(n)));
    if (auto ok = known_keys(n, "ros2", kRos2Keys); !ok) return ok;
    out.line = n.Mark().line + 1;
    if (const auto v = n["node"]) {
      auto s = scalar(v, "ros2.node", "this process's ROS 2 node, [/namespace/]name");
      if (!s) return std::unexpected(s.error());
      if (auto ok = ros2::node_name(*s); !ok) return bad(v, "ros2.node", ok.error().message());
      out.node = *s;
    }
    return {};
  }

  Result<void> security(const YAML::Node& n, SecuritySection& out) const {
    if (!n.IsDefined() || n.IsNull()) return {};
    if (!n.IsMap()) return bad(n, "security", fmt::format("expected a map of {}, found {}", setting::listed(kSecurityKeys), kind(n)));
    if (auto ok = known_keys(n, "security", kSecurityKeys); !ok) return ok;
    out.line = n.Mark().line + 1;
    if (const auto v = n["mode"]) {
      auto s = scalar(v, "security.mode", "enforce, permissive or off");
      if (!s) return std::unexpected(s.error());
      if (*s == "enforce") out.mode = net::SecurityMode::Enforce;
      else if (*s == "permissive") out.mode = net::SecurityMode::Permissive;
      else if (*s == "off") out.mode = net::SecurityMode::Off;
      else return bad(v, "security.mode", fmt::format("unknown mode '{}'; expected enforce, permissive or off", *s));
    }
    if (const auto v = n["keystore"]) {
      auto s = scalar(v, "security.keystore", "a directory made by `horus security keystore init`");
      if (!s) return std::unexpected(s.error());
      if (s->empty()) return bad(v, "security.keystore", "empty; expected a directory made by `horus security keystore init`");
      // A relative keystore is relative to the configuration file's directory.
      std::filesystem::path dir(*s);
      if (dir.is_relative() && file_.find('<') == std::string::npos) dir = std::filesystem::path(file_).parent_path() / dir;
      out.keystore = dir.lexically_normal().string();
    }
    if (const auto v = n["identity"]) {
      auto s = scalar(v, "security.identity", "this host's name in the keystore");
      if (!s) return std::unexpected(s.error());
      if (auto ok = net::validate_identity_name(*s); !ok) return bad(v, "security.identity", ok.error().message());
      out.identity = *s;
    }
    return {};
  }

  Result<void> fleet(const YAML::Node& n, FleetSection& out) const {
    if (!n.IsDefined() || n.IsNull()) return {};
    if (!n.IsMap()) return bad(n, "fleet", fmt::format("expected a map of {}, found {}", setting::listed(kFleetKeys), kind(n)));
    if (auto ok = known_keys(n, "fleet", kFleetKeys); !ok) return ok;
    if (const auto v = n["announce"]) {
      auto b = boolean(v, "fleet.announce");
      if (!b) return std::unexpected(b.error());
      out.announce = *b;
    }
    if (const auto v = n["heartbeat_ms"]) {
      auto ms = integer(v, "fleet.heartbeat_ms", kMinHeartbeatMs, kMaxHeartbeatMs,
                        fmt::format("a heartbeat period; expected milliseconds from {} to {}", kMinHeartbeatMs, kMaxHeartbeatMs));
      if (!ms) return std::unexpected(ms.error());
      out.heartbeat_ms = *ms;
    }
    if (const auto v = n["announce_ms"]) {
      auto ms = integer(v, "fleet.announce_ms", 100, 600000, "an announcement period; expected milliseconds from 100 to 600000");
      if (!ms) return std::unexpected(ms.error());
      out.announce_ms = *ms;
    }
    if (const auto v = n["misses"]) {
      auto m = integer(v, "fleet.misses", 1, 100, "a number of missed heartbeats; expected an integer from 1 to 100");
      if (!m) return std::unexpected(m.error());
      out.misses = *m;
    }
    if (const auto v = n["max_hosts"]) {
      auto m = integer(v, "fleet.max_hosts", 8, 65536, "a number of hosts; expected an integer from 8 to 65536");
      if (!m) return std::unexpected(m.error());
      out.max_hosts = *m;
    }
    if (const auto v = n["forget_after"]) {
      auto d = quantity(v, "fleet.forget_after", "a duration such as \"1h\" or \"10min\"", parse_duration);
      if (!d) return std::unexpected(d.error());
      out.forget_after = *d;
    }
    return {};
  }

  Result<TopicRule> rule(const YAML::Node& n, std::size_t index, const NetworkSection& net_section) const {
    const std::string where = fmt::format("topics[{}]", index);
    if (!n.IsMap())
      return bad(n, where, fmt::format("expected a rule (a map with match and any of scope, backend, reliability, "
                                       "durability, capacity), found {}",
                                       kind(n)));
    if (auto ok = known_keys(n, where, rule_key_names()); !ok) return std::unexpected(ok.error());
    TopicRule r;
    r.line = n.Mark().line + 1;
    const auto m = n["match"];
    if (!m) return bad(n, where, "the rule has no 'match' (the topic-name pattern it applies to)");
    auto pattern = scalar(m, where + ".match", "a topic-name pattern such as \"fleet.**\"");
    if (!pattern) return std::unexpected(pattern.error());
    if (auto ok = check_topic_pattern(*pattern); !ok) return bad(m, where + ".match", ok.error().message());
    r.match = *pattern;
    if (const auto v = n["scope"]) {
      auto s = scalar(v, where + ".scope", "process, host or fleet");
      if (!s) return std::unexpected(s.error());
      if (*s == "process") r.scope = Scope::Process;
      else if (*s == "host") r.scope = Scope::Host;
      else if (*s == "fleet") r.scope = Scope::Fleet;
      else return bad(v, where + ".scope", fmt::format("unknown scope '{}'; expected process, host or fleet", *s));
    }
    if (const auto v = n["backend"]) {
      auto t = transport(v, where + ".backend");
      if (!t) return std::unexpected(t.error());
      if (r.scope && *r.scope != Scope::Fleet)
        return bad(v, where + ".backend",
                   fmt::format("a network backend applies to fleet topics only; this rule's scope is {}",
                               to_string(*r.scope)));
      r.scope = Scope::Fleet;
      r.backend = *t;
    }
    if (r.scope == Scope::Fleet && !r.backend && !net_section.backend)
      return bad(n, where, "scope fleet needs a network backend: set this rule's 'backend' or 'network.backend'");
    // The settings of the table with the plain precedence, each by its kind.
#define HORUS_PARSE_SETTING(member, Kind, Rule, key, example, dflt, unset, doc) \
  HORUS_SETTING_IF_PLAIN_##Rule(if (auto ok = value_at(n, where, key, doc, setting::Kind{}, r.member); !ok) return std::unexpected(ok.error());)
    HORUS_TOPIC_SETTINGS(HORUS_PARSE_SETTING)
#undef HORUS_PARSE_SETTING
    if (auto ok = value_at(n, where, "log", "", setting::Boolean{}, r.log); !ok) return std::unexpected(ok.error());
    if (const auto v = n["protection"]) {
      auto s = scalar(v, where + ".protection", "encrypt or sign");
      if (!s) return std::unexpected(s.error());
      if (*s == "encrypt") r.protection = net::Protection::Encrypt;
      else if (*s == "sign") r.protection = net::Protection::Sign;
      else
        return bad(v, where + ".protection",
                   fmt::format("unknown protection '{}'; expected encrypt (the default under security) or sign "
                               "(authenticated, not secret)",
                               *s));
      if (r.scope && *r.scope != Scope::Fleet)
        return bad(v, where + ".protection",
                   fmt::format("protection applies to fleet topics (DDS-Security); this rule's scope is {}", to_string(*r.scope)));
    }
    if (r.ros2 && r.ros2->enabled) {
      const auto v = n["ros2"];
      if (r.scope && *r.scope != Scope::Fleet)
        return bad(v, where + ".ros2",
                   fmt::format("a ROS 2 mapping puts the topic on the network (a fleet topic on cyclonedds or "
                               "fastdds); this rule's scope is {}",
                               to_string(*r.scope)));
      if (const std::string b = r.backend ? *r.backend : net_section.backend.value_or(""); b == "lcm")
        return bad(v, where + ".ros2",
                   "ROS 2 nodes speak DDS: a ROS 2 mapping needs backend cyclonedds or fastdds, and this rule's "
                   "backend is lcm");
    }
    if ((r.max_rate_hz || r.max_bandwidth || r.priority) && r.scope && *r.scope != Scope::Fleet)
      return bad(n, where, fmt::format("max_rate_hz, max_bandwidth and priority are budgets of the network (fleet topics); "
                                       "this rule's scope is {}",
                                       to_string(*r.scope)));
    return r;
  }

  static std::string_view kind(const YAML::Node& n) {
    switch (n.Type()) {
      case YAML::NodeType::Null: return "nothing";
      case YAML::NodeType::Scalar: return "a scalar";
      case YAML::NodeType::Sequence: return "a list";
      case YAML::NodeType::Map: return "a map";
      default: return "an undefined node";
    }
  }

 private:
  std::string file_;
};

}  // namespace

Result<Config> Config::parse(std::string_view text, std::string file) {
  Parser p(file);
  YAML::Node root;
  try {
    root = YAML::Load(std::string(text));
  } catch (const YAML::Exception& e) {
    return fail(Errc::Config, fmt::format("{}, line {}, column {}: not valid YAML: {}", file, e.mark.line + 1,
                                          e.mark.column + 1, e.msg));
  }
  Config c;
  c.file_ = std::move(file);
  try {
    if (root.IsNull()) return c;
    if (!root.IsMap())
      return fail(Errc::Config, fmt::format("{}, line {}: expected a map with {}, found {}", c.file_,
                                            root.Mark().line + 1, setting::listed(kTopLevelKeys), Parser::kind(root)));
    if (auto ok = p.known_keys(root, "", kTopLevelKeys); !ok) return std::unexpected(ok.error());
    if (auto ok = p.network(root["network"], c.network_); !ok) return std::unexpected(ok.error());
    if (auto ok = p.fleet(root["fleet"], c.fleet_); !ok) return std::unexpected(ok.error());
    if (auto ok = p.security(root["security"], c.security_); !ok) return std::unexpected(ok.error());
    if (auto ok = p.ros2(root["ros2"], c.ros2_); !ok) return std::unexpected(ok.error());
    if (const auto topics = root["topics"]; topics && !topics.IsNull()) {
      if (!topics.IsSequence())
        return p.bad(topics, "topics", fmt::format("expected a list of rules (- match: ...), found {}", Parser::kind(topics)));
      for (std::size_t i = 0; i < topics.size(); ++i) {
        auto r = p.rule(topics[i], i, c.network_);
        if (!r) return std::unexpected(r.error());
        c.rules_.push_back(std::move(*r));
      }
    }
  } catch (const YAML::Exception& e) {
    return fail(Errc::Config, fmt::format("{}, line {}: {}", c.file_, e.mark.line + 1, e.msg));
  }
  return c;
}

Result<Config> Config::load(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return fail(Errc::Config, fmt::format("configuration file '{}' cannot be read: {}", path, std::strerror(errno)));
  std::ostringstream text;
  text << in.rdbuf();
  if (in.bad()) return fail(Errc::Config, fmt::format("configuration file '{}': read error", path));
  return parse(text.str(), path);
}

const TopicRule* Config::match(std::string_view topic) const noexcept {
  for (const auto& r : rules_)
    if (topic_pattern_matches(r.match, topic)) return &r;
  return nullptr;
}

namespace {

// A ROS 2 mapping makes the topic a fleet topic on DDS: without a scope chosen, on the file's
// network.backend when it is a DDS one, else on Cyclone DDS (else Fast DDS); a scope of process
// or host chosen, or LCM, is an error naming where it came from.
Result<void> ros2_backend(std::string_view topic, TopicChoice& c) {
  if (!c.ros2 || !c.ros2->enabled) return {};
  const auto mapped_by = [&] { return c.ros2_from == Source::Code ? std::string("code (TopicOptions::ros2)") : std::string("the file's ros2"); };
  if (!is_network(c.backend)) {
    if (c.backend_from != Source::Default)
      return fail(Errc::Config, fmt::format("topic '{}': {} maps it onto ROS 2, a fleet topic on cyclonedds or fastdds, "
                                            "but its scope is {} ({}); drop one of the two",
                                            topic, mapped_by(), to_string(c.backend.scope()), to_string(c.backend_from)));
    std::string name;
    if (c.config != nullptr && c.config->network().backend && *c.config->network().backend != "lcm")
      name = *c.config->network().backend;
    for (const char* dds : {"cyclonedds", "fastdds"})
      if (name.empty() && net::find_transport(dds) != nullptr) name = dds;
    const auto* t = name.empty() ? nullptr : net::find_transport(name);
    if (t == nullptr)
      return fail(Errc::Config, fmt::format("topic '{}': {} maps it onto ROS 2, and this program has no DDS backend "
                                            "(cyclonedds or fastdds)",
                                            topic, mapped_by()));
    c.backend = Backend::network(t->name);
    c.backend_from = c.ros2_from;
  }
  if (c.backend.transport() == "lcm")
    return fail(Errc::Config, fmt::format("topic '{}': {} maps it onto ROS 2, and ROS 2 nodes speak DDS; its backend is "
                                          "lcm ({}): use cyclonedds or fastdds for it",
                                          topic, mapped_by(), to_string(c.backend_from)));
  return {};
}

}  // namespace

Result<TopicChoice> choose(std::string_view topic, const TopicOptions& code, const Settings& settings) {
  const Config* config = settings.file;
  const Environment& env = settings.env();
  TopicChoice c;
  c.config = config;
  c.rule = config != nullptr ? config->match(topic) : nullptr;
  const TopicRule* r = c.rule;
  // Scope and backend: code, HORUS_BACKEND, the rule (its backend, else network.backend).
  if (code.backend) {
    c.backend = *code.backend;
    c.backend_from = Source::Code;
  } else if (!env.backend.empty()) {
    auto b = backend_from(env.backend);
    if (!b) return std::unexpected(b.error());
    c.backend = *b;
    c.backend_from = Source::Environment;
  } else if (r != nullptr && r->scope) {
    c.backend_from = Source::File;
    switch (*r->scope) {
      case Scope::Process: c.backend = Backend::InProcess; break;
      case Scope::Host: c.backend = Backend::SharedMemory; break;
      case Scope::Fleet: {
        const std::string& name = r->backend ? *r->backend : *config->network().backend;  // checked by parse
        const auto* t = net::find_transport(name);
        if (t == nullptr)
          return fail(Errc::Config, fmt::format("{}, line {}: topic '{}': this program has no {} backend", config->file(),
                                                r->line, topic, name));
        c.backend = Backend::network(t->name);
        break;
      }
    }
  }
  // Per setting: the code's value, else the rule's, with where it came from.
  auto pick = [&](const auto& from_code, const auto& from_rule, auto& out, Source& source) {
    if (from_code) {
      out = from_code;
      source = Source::Code;
    } else if (from_rule) {
      out = from_rule;
      source = Source::File;
    }
  };
  static const TopicRule kNoRule{};
  const TopicRule& rule = r != nullptr ? *r : kNoRule;
#define HORUS_PICK_SETTING(member, Kind, Rule, key, example, dflt, unset, doc) \
  HORUS_SETTING_IF_PLAIN_##Rule(pick(code.member, rule.member, c.member, c.member##_from);)
  HORUS_TOPIC_SETTINGS(HORUS_PICK_SETTING)
#undef HORUS_PICK_SETTING
  // Traffic logging: the code's verbose, else the first HORUS_LOG_TOPICS entry that matches,
  // else the rule's log.
  if (code.verbose) {
    c.verbose = *code.verbose;
    c.verbose_from = Source::Code;
  } else if (!env.log_topics.empty()) {
    auto m = log_topics_match(env.log_topics, topic);
    if (!m) return std::unexpected(m.error());
    if (*m) {
      c.verbose = (*m)->on;
      c.verbose_from = Source::Environment;
      c.verbose_entry = (*m)->entry;
    }
  }
  if (c.verbose_from == Source::Default && rule.log) {
    c.verbose = *rule.log;
    c.verbose_from = Source::File;
  }
  if (auto ok = ros2_backend(topic, c); !ok) return std::unexpected(ok.error());
  return c;
}

TopicOptions options_of(const TopicChoice& c, const TopicOptions& code) {
  TopicOptions out = code;
  out.backend = c.backend;
  out.verbose = c.verbose;
#define HORUS_CHOSEN_SETTING(member, Kind, Rule, key, example, dflt, unset, doc) \
  HORUS_SETTING_IF_PLAIN_##Rule(out.member = c.member;)
  HORUS_TOPIC_SETTINGS(HORUS_CHOSEN_SETTING)
#undef HORUS_CHOSEN_SETTING
  return out;
}

Result<TopicOptions> resolve_topic_options(std::string_view topic, const TopicOptions& code) {
  auto c = choose(topic, code);
  if (!c) return std::unexpected(c.error());
  return options_of(*c, code);
}

}  // namespace horus
