// The configuration file (HORUS_CONFIG) and how a topic's settings are chosen.
//
//   network:                        # defaults for fleet topics
//     backend: cyclonedds           # a registered transport: cyclonedds | fastdds | lcm
//     domain_id: 0                  # DDS domain, 0..232
//     localhost_only: false         # DDS: loopback only
//     lcm_url: "udpm://239.255.76.67:7667?ttl=1"
//   fleet:                          # the fleet layer (horus/fleet.hpp)
//     announce: true                # false: this host's processes do not announce it
//     heartbeat_ms: 100             # heartbeat period (HORUS_FLEET_HEARTBEAT_MS overrides), 10..60000
//     announce_ms: 2000             # full announcements: this often, and at once on change or request
//     misses: 3                     # heartbeats missed before a host is lost (+ one period of tolerance)
//     max_hosts: 1024               # hosts a process keeps; the lost one lost longest ago makes room
//     forget_after: 1h              # a host lost this long is forgotten (a duration: s, min, h)
//   security:                       # DDS-Security on fleet topics (security/README.md)
//     mode: enforce                 # enforce | permissive | off (HORUS_SECURITY)
//     keystore: /etc/horus/keystore # made by `horus security keystore init` (HORUS_SECURITY_KEYSTORE);
//                                   # a relative path is relative to this file's directory
//     identity: robot1              # this host's identity in it (HORUS_SECURITY_IDENTITY)
//   topics:                         # the first rule whose pattern matches wins
//     - match: "fleet.**"           # '*' = one dot-separated segment, '**' = any number (also none)
//       scope: fleet                # process | host | fleet
//       reliability: reliable       # ... every key of horus/topic_options.hpp's table
//                                   # (HORUS_TOPIC_SETTINGS; `horus config settings`), and
//       protection: sign            # under security: encrypt (the default) | sign
//
// Precedence, per setting: code (TopicOptions) > environment (HORUS_BACKEND, HORUS_DOMAIN_ID,
// HORUS_DDS_LOCALHOST, HORUS_LCM_URL, HORUS_LOG_TOPICS) > file > the message type's defaults. Parsing is strict:
// an unknown key or value, a value of the wrong type, a bad pattern, a rule without `match`, a
// backend this build lacks is an error naming the file, the line, the key and what is valid.
// Nothing here includes yaml-cpp.
#pragma once

#include <chrono>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "horus/backend.hpp"
#include "horus/topic_options.hpp"
#include "horus/error.hpp"
#include "horus/names.hpp"  // check_topic_pattern, topic_pattern_matches
#include "horus/network.hpp"

#include "horus/export.hpp"

HORUS_API_BEGIN

namespace horus {

/// Where a topic's setting came from (`horus config explain`).
enum class Source : std::uint8_t { Code, Environment, File, Default };
/// "code", "environment", "file", "default".
std::string_view to_string(Source s) noexcept;

/// One rule of the file's `topics:` list: its own keys, and one member per setting of
/// HORUS_TOPIC_SETTINGS that follows the plain precedence (code > file > default).
struct TopicRule {
  std::string match;  // the pattern
  int line = 0;       // the rule's line in the file (1-based)
  std::optional<Scope> scope;
  std::optional<std::string> backend;         // a registered transport's name (fleet topics)
  std::optional<net::Protection> protection;  // under DDS-Security (the governance document)
  std::optional<bool> log;                    // traffic logging (TopicOptions::verbose)
#define HORUS_RULE_FIELD(member, Kind, Rule, key, example, dflt, unset, doc) \
  HORUS_SETTING_IF_PLAIN_##Rule(std::optional<setting::Kind::type> member;)
  HORUS_TOPIC_SETTINGS(HORUS_RULE_FIELD)
#undef HORUS_RULE_FIELD
};

/// A key of a rule of the file's `topics:` list, as README's table of settings shows it: the
/// rule's own keys (match, scope, protection) and those of HORUS_TOPIC_SETTINGS, with their
/// TopicOptions member ("" when code has none), an example value and a line of meaning.
struct RuleKey {
  std::string_view key;
  std::string_view member;
  std::string_view example;
  std::string_view doc;
};
/// Every key a rule may have, in README's order (the parser knows these and no other).
std::span<const RuleKey> rule_keys() noexcept;
/// The table of per-topic settings as README shows it (`horus config settings`): Markdown, one
/// row per setting of HORUS_TOPIC_SETTINGS and per rule key of its own.
std::string settings_table();

namespace setting {
// The values of each kind of setting in the file's form (what a rule's key holds), which
// `horus config explain` and Python's strings use too. parse gives the value or why `text` is
// not one ("unknown reliability 'x'; expected best_effort or reliable"); `doc` is the setting's
// line of the table (a rate's expectation). expected says in words what a value must be;
// format writes a value ("reliable", "100 ms", "2000000 B/s").
#define HORUS_SETTING_CODEC(Kind)                                                                         \
  std::variant<Kind::type, std::string> parse(Kind, std::string_view text, std::string_view doc = {});   \
  std::string expected(Kind, std::string_view doc = {});                                                  \
  std::string format(Kind, const Kind::type& value);
HORUS_SETTING_CODEC(PowerOfTwo)
HORUS_SETTING_CODEC(ReliabilityName)
HORUS_SETTING_CODEC(DurabilityName)
HORUS_SETTING_CODEC(PositiveRate)
HORUS_SETTING_CODEC(RateOrZero)
HORUS_SETTING_CODEC(Bandwidth)
HORUS_SETTING_CODEC(PriorityName)
HORUS_SETTING_CODEC(Duration)
HORUS_SETTING_CODEC(Boolean)
HORUS_SETTING_CODEC(LevelName)
HORUS_SETTING_CODEC(Ros2)
#undef HORUS_SETTING_CODEC
/// Names as an error message lists what it expected: "a, b or c".
std::string listed(std::span<const std::string_view> names);
}  // namespace setting

/// Parses a bandwidth: a number of bytes per second, or a number with a unit (B/s, kB/s, MB/s,
/// GB/s, KiB/s, MiB/s, GiB/s, kbit/s, Mbit/s, Gbit/s; "2 MB/s", "20Mbit/s"); an error message
/// saying what is wrong, or the bytes per second.
std::variant<std::uint64_t, std::string> parse_bandwidth(std::string_view text);
/// Parses a duration above 0: a number with a unit, ns, us, ms, s, min or h ("100ms", "1.5 s");
/// an error message saying what is wrong, or the duration.
std::variant<std::chrono::nanoseconds, std::string> parse_duration(std::string_view text);

/// The file's `network:` section: defaults of fleet topics and of the transports.
/// The `fleet:` section: the fleet layer's discovery (horus/fleet.hpp).
struct FleetSection {
  std::optional<bool> announce;             // false: this host's processes never announce it
  std::optional<std::uint32_t> heartbeat_ms;
  std::optional<std::uint32_t> announce_ms;
  std::optional<std::uint32_t> misses;
  std::optional<std::uint32_t> max_hosts;
  std::optional<std::chrono::nanoseconds> forget_after;
};
inline constexpr std::uint32_t kMinHeartbeatMs = 10;
inline constexpr std::uint32_t kMaxHeartbeatMs = 60000;

/// The `security:` section (net::Security).
struct SecuritySection {
  std::optional<net::SecurityMode> mode;
  std::optional<std::string> keystore;  // made absolute against the file's directory when relative
  std::optional<std::string> identity;
  int line = 0;  // the section's line
};

struct NetworkSection {
  std::optional<std::string> backend;
  std::optional<std::uint32_t> domain_id;
  std::optional<bool> localhost_only;
  std::optional<std::string> lcm_url;
  std::optional<std::vector<std::string>> peers;  // unicast discovery to these hosts, multicast off
  std::optional<std::uint64_t> max_bandwidth;     // the host's link budget for fleet topics, bytes/s
  int lcm_url_line = 0;                           // the lines they were given on (errors name them)
  int peers_line = 0;
};

/// The `ros2:` section: this process's node on the ROS 2 graph (docs/ROS2.md).
struct Ros2Section {
  std::optional<std::string> node;  // "[/namespace/]name", checked by ROS 2's rules
  int line = 0;
};

/// A parsed configuration file.
class Config {
 public:
  /// Parses YAML text; `file` names it in errors.
  static Result<Config> parse(std::string_view text, std::string file = "<text>");
  /// Reads and parses a file.
  static Result<Config> load(const std::string& path);

  const std::string& file() const noexcept { return file_; }
  const NetworkSection& network() const noexcept { return network_; }
  const FleetSection& fleet() const noexcept { return fleet_; }
  const SecuritySection& security() const noexcept { return security_; }
  const Ros2Section& ros2() const noexcept { return ros2_; }
  const std::vector<TopicRule>& rules() const noexcept { return rules_; }
  /// The first rule whose pattern matches `topic`, or nullptr.
  const TopicRule* match(std::string_view topic) const noexcept;

 private:
  std::string file_;
  NetworkSection network_;
  FleetSection fleet_;
  SecuritySection security_;
  Ros2Section ros2_;
  std::vector<TopicRule> rules_;
};


/// The process's configuration: the file HORUS_CONFIG names, read once per value of the
/// variable (later calls return the same result); nullptr when HORUS_CONFIG is unset or empty.
/// Its network section is the transports' default (net::config_from_environment()).
Result<const Config*> config_from_environment();

namespace net {
/// The process's network settings, which the fleet layer passes to TransportInfo::open: the
/// environment (HORUS_DOMAIN_ID, HORUS_DDS_LOCALHOST, HORUS_LCM_URL, LCM_DEFAULT_URL) over the
/// configuration file's `network:` section (net::config_from). An error names the variable or
/// the file.
Result<Config> config_from_environment();
/// The network settings `file` alone gives (no environment): what `horus config check` checks.
Result<Config> config_of(const horus::Config& file);
/// The environment over `file` (nullptr: the environment alone): what a process would get if
/// HORUS_CONFIG named that file (`horus config explain --file`).
Result<Config> config_from_environment(const horus::Config* file);
}  // namespace net
/// Same as net::config_from_environment() (the name horus has always had).
inline Result<net::Config> network_config_from_environment() { return net::config_from_environment(); }

/// What a topic gets, setting by setting, and from where: one value and source per setting of
/// HORUS_TOPIC_SETTINGS (nullopt: its default_value, else the type's default or none).
struct TopicChoice {
  Backend backend;  // the scope, and the transport of a fleet topic
  Source backend_from = Source::Default;
  bool verbose = false;  // the topic's traffic is logged
  Source verbose_from = Source::Default;
  std::string verbose_entry;  // Source::Environment: the HORUS_LOG_TOPICS entry that decided
#define HORUS_CHOICE_FIELD(member, Kind, Rule, key, example, dflt, unset, doc) \
  HORUS_SETTING_IF_PLAIN_##Rule(std::optional<setting::Kind::type> member; Source member##_from = Source::Default;)
  HORUS_TOPIC_SETTINGS(HORUS_CHOICE_FIELD)
#undef HORUS_CHOICE_FIELD
  const TopicRule* rule = nullptr;  // the file's rule that matched
  const Config* config = nullptr;   // the file, when there is one
};

/// Chooses a topic's settings: code > environment > `config` > defaults. `config` may be null.
Result<TopicChoice> choose(std::string_view topic, const TopicOptions& code, const Config* config);
/// The same with the process's configuration (config_from_environment()).
Result<TopicChoice> choose(std::string_view topic, const TopicOptions& code);

/// `code` with what the environment and the file choose filled in (what Topic<T>::open uses).
Result<TopicOptions> resolve_topic_options(std::string_view topic, const TopicOptions& code);
/// The same from a choice already made for `code`.
TopicOptions options_of(const TopicChoice& choice, const TopicOptions& code);

/// What HORUS_LOG_TOPICS (`value`) says of `topic`: the first entry that matches it (a pattern
/// turns logging on, `!pattern` off) and that entry; nothing when no entry matches. An error
/// names the variable, the entry and what is expected.
struct LogTopicsEntry {
  bool on = true;
  std::string entry;
};
Result<std::optional<LogTopicsEntry>> log_topics_match(std::string_view value, std::string_view topic);
/// Why a topic logs its traffic or not, in words ("environment (HORUS_LOG_TOPICS entry 'cmd_*')",
/// "file F, line L: rule 'R'", "code (TopicOptions::verbose)", "default"): `horus config explain`
/// and the line a verbose handle logs when it opens.
std::string verbose_origin(const TopicChoice& choice);

/// The fleet layer's settings (horus/fleet.hpp): HORUS_FLEET_HEARTBEAT_MS > the file's
/// `fleet:` section > defaults; the transport: HORUS_BACKEND when it names a network backend,
/// else the file's `network.backend`, else none (empty).
struct FleetSettings {
  bool announce = true;
  std::chrono::milliseconds heartbeat{100};
  std::chrono::milliseconds announce_period{2000};
  std::uint32_t misses = 3;  // a host is lost after this many heartbeats missed (+ one period of tolerance)
  // What a process keeps of the fleet, whatever its peers send: at most max_hosts hosts (a new
  // one takes the place of the host lost longest ago, or is refused while all are alive), and
  // a lost host only for forget_after.
  std::uint32_t max_hosts = 1024;
  std::chrono::nanoseconds forget_after = std::chrono::hours(1);
  std::string transport;
};
Result<FleetSettings> fleet_settings();
/// The fleet transport when none is named: HORUS_BACKEND when it names a network backend, else
/// the file's `network.backend`, else none (empty). What `scope: fleet` without a backend, the
/// fleet layer and Python's scope='fleet' use.
Result<std::string> fleet_transport();

}  // namespace horus

HORUS_API_END
