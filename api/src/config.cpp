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
#include <list>
#include <mutex>
#include <set>
#include <span>
#include <sstream>
#include <type_traits>
#include <utility>

#include "horus/environment.hpp"
#include "horus/names.hpp"
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

constexpr std::array<std::string_view, 4> kTopLevelKeys{"network", "fleet", "security", "topics"};
constexpr std::array<std::string_view, 3> kSecurityKeys{"mode", "keystore", "identity"};
constexpr std::array<std::string_view, 6> kFleetKeys{"announce", "heartbeat_ms", "announce_ms", "misses", "max_hosts",
                                                      "forget_after"};
constexpr std::array<std::string_view, 6> kNetworkKeys{"backend", "domain_id",     "localhost_only",
                                                       "lcm_url", "peers", "max_bandwidth"};
constexpr std::array<std::string_view, 15> kRuleKeys{
    "match",    "scope",    "backend",    "reliability", "durability", "capacity",  "max_rate_hz", "max_bandwidth",
    "priority", "deadline", "lifespan",   "protection",  "log",        "log_level", "log_rate_hz"};

template <std::size_t N>
std::string one_of(const std::array<std::string_view, N>& names) {
  std::string out;
  for (std::size_t i = 0; i < N; ++i) out += (i == 0 ? "" : (i + 1 == N ? " or " : ", ")) + std::string(names[i]);
  return out;
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

  template <std::size_t N>
  Result<void> known_keys(const YAML::Node& map, std::string_view where, const std::array<std::string_view, N>& keys) const {
    std::set<std::string> seen;
    for (const auto& kv : map) {
      if (!kv.first.IsScalar()) return bad(kv.first, where, "a key must be a plain name");
      const std::string k = kv.first.Scalar();
      const std::string path = where.empty() ? k : std::string(where) + "." + k;
      if (std::find(keys.begin(), keys.end(), k) == keys.end())
        return bad(kv.first, path, fmt::format("unknown key; expected {}", one_of(keys)));
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

  // A rate in Hz up to 1e9: above 0, or also 0 when `zero_ok`.
  Result<double> rate(const YAML::Node& n, std::string_view key, bool zero_ok, std::string_view expected) const {
    auto s = scalar(n, key, expected);
    if (!s) return std::unexpected(s.error());
    double hz = 0;
    const auto [end, ec] = std::from_chars(s->data(), s->data() + s->size(), hz);
    if (ec != std::errc{} || end != s->data() + s->size() || !(hz > 0 || (zero_ok && hz == 0)) || hz > 1e9)
      return bad(n, key, fmt::format("'{}' is not a rate; expected {}", *s, expected));
    return hz;
  }

  Result<bool> boolean(const YAML::Node& n, std::string_view key) const {
    auto s = scalar(n, key, "true or false");
    if (!s) return std::unexpected(s.error());
    if (*s == "true") return true;
    if (*s == "false") return false;
    return bad(n, key, fmt::format("'{}' is not a boolean; expected true or false", *s));
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
    if (!n.IsMap()) return bad(n, "network", fmt::format("expected a map of {}, found {}", one_of(kNetworkKeys), kind(n)));
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

  Result<void> security(const YAML::Node& n, SecuritySection& out) const {
    if (!n.IsDefined() || n.IsNull()) return {};
    if (!n.IsMap()) return bad(n, "security", fmt::format("expected a map of {}, found {}", one_of(kSecurityKeys), kind(n)));
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
    if (!n.IsMap()) return bad(n, "fleet", fmt::format("expected a map of {}, found {}", one_of(kFleetKeys), kind(n)));
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
    if (auto ok = known_keys(n, where, kRuleKeys); !ok) return std::unexpected(ok.error());
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
    if (const auto v = n["reliability"]) {
      auto s = scalar(v, where + ".reliability", "best_effort or reliable");
      if (!s) return std::unexpected(s.error());
      if (*s == "reliable") r.reliability = net::Reliability::Reliable;
      else if (*s == "best_effort") r.reliability = net::Reliability::BestEffort;
      else return bad(v, where + ".reliability", fmt::format("unknown reliability '{}'; expected best_effort or reliable", *s));
    }
    if (const auto v = n["durability"]) {
      auto s = scalar(v, where + ".durability", "volatile or transient_local");
      if (!s) return std::unexpected(s.error());
      if (*s == "volatile") r.durability = net::Durability::Volatile;
      else if (*s == "transient_local") r.durability = net::Durability::TransientLocal;
      else return bad(v, where + ".durability", fmt::format("unknown durability '{}'; expected volatile or transient_local", *s));
    }
    if (const auto v = n["capacity"]) {
      auto c = integer(v, where + ".capacity", 1, shm::kMaxCapacity,
                       fmt::format("a capacity; expected a power of two from 1 to {} (slots per publisher)", shm::kMaxCapacity));
      if (!c) return std::unexpected(c.error());
      if ((*c & (*c - 1)) != 0)
        return bad(v, where + ".capacity",
                   fmt::format("{} is not a power of two; expected a power of two from 1 to {} (slots per publisher)", *c,
                               shm::kMaxCapacity));
      r.capacity = *c;
    }
    if (const auto v = n["max_rate_hz"]) {
      auto hz = rate(v, where + ".max_rate_hz", false,
                     "messages per second the host's bridge sends at most, a number above 0 (such as 5 or 0.5)");
      if (!hz) return std::unexpected(hz.error());
      r.max_rate_hz = *hz;
    }
    if (const auto v = n["max_bandwidth"]) {
      auto b = quantity(v, where + ".max_bandwidth", "a bandwidth such as \"2 MB/s\"", parse_bandwidth);
      if (!b) return std::unexpected(b.error());
      r.max_bandwidth = *b;
    }
    if (const auto v = n["priority"]) {
      auto s = scalar(v, where + ".priority", "high, normal or low");
      if (!s) return std::unexpected(s.error());
      if (*s == "high") r.priority = Priority::High;
      else if (*s == "normal") r.priority = Priority::Normal;
      else if (*s == "low") r.priority = Priority::Low;
      else return bad(v, where + ".priority", fmt::format("unknown priority '{}'; expected high, normal or low", *s));
    }
    for (const char* key : {"deadline", "lifespan"}) {
      const auto v = n[key];
      if (!v) continue;
      auto d = quantity(v, where + "." + key, "a duration such as \"100ms\"", parse_duration);
      if (!d) return std::unexpected(d.error());
      (std::string_view(key) == "deadline" ? r.deadline : r.lifespan) = *d;
    }
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
    if (const auto v = n["log"]) {
      auto b = boolean(v, where + ".log");
      if (!b) return std::unexpected(b.error());
      r.log = *b;
    }
    if (const auto v = n["log_level"]) {
      constexpr std::string_view kLevels = "trace, debug, info, warn or error";
      auto s = scalar(v, where + ".log_level", kLevels);
      if (!s) return std::unexpected(s.error());
      const auto level = log_level_from(*s);
      if (!level) return bad(v, where + ".log_level", fmt::format("unknown level '{}'; expected {}", *s, kLevels));
      r.log_level = *level;
    }
    if (const auto v = n["log_rate_hz"]) {
      auto hz = rate(v, where + ".log_rate_hz", true,
                     "lines per second the topic logs at most, a number such as 5 or 0.5 (0: every message)");
      if (!hz) return std::unexpected(hz.error());
      r.log_rate_hz = *hz;
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
                                            root.Mark().line + 1, one_of(kTopLevelKeys), Parser::kind(root)));
    if (auto ok = p.known_keys(root, "", kTopLevelKeys); !ok) return std::unexpected(ok.error());
    if (auto ok = p.network(root["network"], c.network_); !ok) return std::unexpected(ok.error());
    if (auto ok = p.fleet(root["fleet"], c.fleet_); !ok) return std::unexpected(ok.error());
    if (auto ok = p.security(root["security"], c.security_); !ok) return std::unexpected(ok.error());
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
// The file HORUS_CONFIG names, read once per value of the variable (a program sets it before its
// first topic; a test may change it). Configurations stay alive: choices made earlier keep
// pointing at theirs.
Result<const Config*> file_from(const Environment& env) {
  static std::mutex mutex;
  static std::optional<std::string> cached_path;
  static std::optional<Result<const Config*>> cached;
  static std::list<Config> loaded;
  const std::string& path = env.config;
  std::lock_guard lock(mutex);
  if (cached_path == path && cached) return *cached;
  cached_path = path;
  if (path.empty()) return *(cached = Result<const Config*>(nullptr));
  auto c = Config::load(path);
  if (!c)
    return *(cached = Result<const Config*>(
                 std::unexpected(Error(Errc::Config, "HORUS_CONFIG=" + path + ": " + c.error().message()))));
  return *(cached = Result<const Config*>(&loaded.emplace_back(std::move(*c))));
}

net::FileDefaults file_defaults(const Config* config) {
  if (config == nullptr) return {};
  const auto& n = config->network();
  const auto& s = config->security();
  net::FileDefaults d;
  d.domain_id = n.domain_id;
  d.localhost_only = n.localhost_only;
  d.lcm_url = n.lcm_url;
  d.peers = n.peers;
  d.link_bandwidth = n.max_bandwidth;
  d.security_mode = s.mode;
  d.security_keystore = s.keystore;
  d.security_identity = s.identity;
  d.security_line = s.line;
  d.origin = "configuration file '" + config->file() + "'";
  d.lcm_url_line = n.lcm_url_line;
  d.peers_line = n.peers_line;
  return d;
}
}  // namespace

Result<const Config*> config_from_environment() { return file_from(Environment::read()); }

Result<net::Config> net::config_of(const horus::Config& file) { return net::config_from(Environment{}, file_defaults(&file)); }

namespace net {
Result<Config> config_from_environment() {
  const Environment env = Environment::read();
  auto config = file_from(env);
  if (!config) return std::unexpected(config.error());
  return config_from(env, file_defaults(*config));
}
Result<Config> config_from_environment(const horus::Config* file) {
  return config_from(Environment::read(), file_defaults(file));
}
}  // namespace net

Result<TopicChoice> choose(std::string_view topic, const TopicOptions& code, const Config* config) {
  TopicChoice c;
  c.config = config;
  c.rule = config != nullptr ? config->match(topic) : nullptr;
  const TopicRule* r = c.rule;
  const Environment env = Environment::read();
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
  pick(code.capacity, rule.capacity, c.capacity, c.capacity_from);
  pick(code.reliability, rule.reliability, c.reliability, c.reliability_from);
  pick(code.durability, rule.durability, c.durability, c.durability_from);
  pick(code.max_rate_hz, rule.max_rate_hz, c.max_rate_hz, c.max_rate_hz_from);
  pick(code.max_bandwidth, rule.max_bandwidth, c.max_bandwidth, c.max_bandwidth_from);
  pick(code.priority, rule.priority, c.priority, c.priority_from);
  pick(code.deadline, rule.deadline, c.deadline, c.deadline_from);
  pick(code.lifespan, rule.lifespan, c.lifespan, c.lifespan_from);
  pick(code.log_level, rule.log_level, c.log_level, c.log_level_from);
  pick(code.log_rate_hz, rule.log_rate_hz, c.log_rate_hz, c.log_rate_hz_from);
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
  return c;
}

Result<TopicChoice> choose(std::string_view topic, const TopicOptions& code) {
  auto config = config_from_environment();
  if (!config) return std::unexpected(config.error());
  return choose(topic, code, *config);
}

TopicOptions options_of(const TopicChoice& c, const TopicOptions& code) {
  TopicOptions out = code;
  out.backend = c.backend;
  out.capacity = c.capacity;
  out.reliability = c.reliability;
  out.durability = c.durability;
  out.max_rate_hz = c.max_rate_hz;
  out.max_bandwidth = c.max_bandwidth;
  out.priority = c.priority;
  out.deadline = c.deadline;
  out.lifespan = c.lifespan;
  out.verbose = c.verbose;
  out.log_level = c.log_level;
  out.log_rate_hz = c.log_rate_hz;
  return out;
}

Result<TopicOptions> resolve_topic_options(std::string_view topic, const TopicOptions& code) {
  auto c = choose(topic, code);
  if (!c) return std::unexpected(c.error());
  return options_of(*c, code);
}

Result<FleetSettings> fleet_settings() {
  const Environment env = Environment::read();
  auto config = file_from(env);
  if (!config) return std::unexpected(config.error());
  FleetSettings out;
  if (*config != nullptr) {
    const FleetSection& f = (*config)->fleet();
    if (f.announce) out.announce = *f.announce;
    if (f.heartbeat_ms) out.heartbeat = std::chrono::milliseconds(*f.heartbeat_ms);
    if (f.announce_ms) out.announce_period = std::chrono::milliseconds(*f.announce_ms);
    if (f.misses) out.misses = *f.misses;
    if (f.max_hosts) out.max_hosts = *f.max_hosts;
    if (f.forget_after) out.forget_after = *f.forget_after;
    if (const auto& b = (*config)->network().backend) out.transport = *b;
  }
  if (!env.fleet_heartbeat_ms.empty()) {
    const std::string_view text(env.fleet_heartbeat_ms);
    std::uint64_t v = 0;
    auto [p, ec] = std::from_chars(text.data(), text.data() + text.size(), v);
    if (ec != std::errc() || p != text.data() + text.size() || v < kMinHeartbeatMs || v > kMaxHeartbeatMs)
      return fail(Errc::Config, fmt::format("HORUS_FLEET_HEARTBEAT_MS='{}' is not a heartbeat period; expected "
                                            "milliseconds from {} to {}",
                                            text, kMinHeartbeatMs, kMaxHeartbeatMs));
    out.heartbeat = std::chrono::milliseconds(v);
  }
  if (!env.backend.empty()) {
    auto b = backend_from(env.backend);
    if (!b) return std::unexpected(b.error());
    if (b->scope() == Scope::Fleet) out.transport = std::string(b->transport());
  }
  return out;
}

}  // namespace horus
