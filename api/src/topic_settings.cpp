// The per-topic settings' table (horus/topic_options.hpp, HORUS_TOPIC_SETTINGS) made into what
// the configuration file, `horus config explain`, Python and README read: each kind's values in
// the file's form (setting::parse, expected, format), a rule's keys and README's table.
#include <fmt/format.h>

#include <array>
#include <charconv>
#include <string>
#include <vector>

#include <yaml-cpp/yaml.h>

#include "horus/config.hpp"
#include "horus/ros2/interface.hpp"
#include "horus/ros2/names.hpp"
#include "horus/shm/ring_layout.hpp"

namespace horus {

namespace setting {

std::string listed(std::span<const std::string_view> names) {
  std::string out;
  for (std::size_t i = 0; i < names.size(); ++i)
    out += (i == 0 ? "" : (i + 1 == names.size() ? " or " : ", ")) + std::string(names[i]);
  return out;
}

namespace {

// A kind of value named by words: "unknown <noun> 'x'; expected a, b or c".
template <class T, std::size_t N>
struct Names {
  std::string_view noun;
  std::array<std::pair<T, std::string_view>, N> names;

  std::string expected() const {
    std::array<std::string_view, N> words;
    for (std::size_t i = 0; i < N; ++i) words[i] = names[i].second;
    return listed(words);
  }
  std::variant<T, std::string> parse(std::string_view text) const {
    for (const auto& [value, name] : names)
      if (name == text) return value;
    return fmt::format("unknown {} '{}'; expected {}", noun, text, expected());
  }
  std::string format(T value) const {
    for (const auto& [v, name] : names)
      if (v == value) return std::string(name);
    return "?";
  }
};

constexpr Names<net::Reliability, 2> kReliability{
    "reliability", {{{net::Reliability::BestEffort, "best_effort"}, {net::Reliability::Reliable, "reliable"}}}};
constexpr Names<net::Durability, 2> kDurability{
    "durability", {{{net::Durability::Volatile, "volatile"}, {net::Durability::TransientLocal, "transient_local"}}}};
constexpr Names<Priority, 3> kPriority{
    "priority", {{{Priority::High, "high"}, {Priority::Normal, "normal"}, {Priority::Low, "low"}}}};
constexpr Names<LogLevel, 5> kLevel{"level",
                                    {{{LogLevel::Trace, "trace"},
                                      {LogLevel::Debug, "debug"},
                                      {LogLevel::Info, "info"},
                                      {LogLevel::Warn, "warn"},
                                      {LogLevel::Error, "error"}}}};
constexpr Names<bool, 2> kBoolean{"boolean", {{{true, "true"}, {false, "false"}}}};

// A rate in Hz up to 1e9: above 0, or also 0 when `zero_ok`.
std::variant<double, std::string> rate(std::string_view text, bool zero_ok, std::string_view doc) {
  double hz = 0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), hz);
  if (text.empty() || ec != std::errc{} || end != text.data() + text.size() || !(hz > 0 || (zero_ok && hz == 0)) ||
      hz > 1e9)
    return fmt::format("'{}' is not a rate; expected {}", text, doc);
  return hz;
}

std::string capacity_expected() {
  return fmt::format("a capacity; expected a power of two from 1 to {} (slots per publisher)", shm::kMaxCapacity);
}

}  // namespace

std::variant<std::uint32_t, std::string> parse(PowerOfTwo, std::string_view text, std::string_view) {
  std::uint64_t v = 0;
  const char* end = text.data() + text.size();
  auto [p, ec] = std::from_chars(text.data(), end, v);
  if (text.empty() || ec != std::errc() || p != end || v < 1 || v > shm::kMaxCapacity)
    return fmt::format("'{}' is not {}", text, capacity_expected());
  if ((v & (v - 1)) != 0)
    return fmt::format("{} is not a power of two; expected a power of two from 1 to {} (slots per publisher)", v,
                       shm::kMaxCapacity);
  return static_cast<std::uint32_t>(v);
}
std::string expected(PowerOfTwo, std::string_view) { return capacity_expected(); }
std::string format(PowerOfTwo, const std::uint32_t& v) { return std::to_string(v); }

std::variant<net::Reliability, std::string> parse(ReliabilityName, std::string_view text, std::string_view) {
  return kReliability.parse(text);
}
std::string expected(ReliabilityName, std::string_view) { return kReliability.expected(); }
std::string format(ReliabilityName, const net::Reliability& v) { return kReliability.format(v); }

std::variant<net::Durability, std::string> parse(DurabilityName, std::string_view text, std::string_view) {
  return kDurability.parse(text);
}
std::string expected(DurabilityName, std::string_view) { return kDurability.expected(); }
std::string format(DurabilityName, const net::Durability& v) { return kDurability.format(v); }

std::variant<Priority, std::string> parse(PriorityName, std::string_view text, std::string_view) {
  return kPriority.parse(text);
}
std::string expected(PriorityName, std::string_view) { return kPriority.expected(); }
std::string format(PriorityName, const Priority& v) { return kPriority.format(v); }

std::variant<LogLevel, std::string> parse(LevelName, std::string_view text, std::string_view) {
  return kLevel.parse(text);
}
std::string expected(LevelName, std::string_view) { return kLevel.expected(); }
std::string format(LevelName, const LogLevel& v) { return kLevel.format(v); }

std::variant<bool, std::string> parse(Boolean, std::string_view text, std::string_view) {
  auto b = kBoolean.parse(text);
  if (std::holds_alternative<std::string>(b)) return fmt::format("'{}' is not a boolean; expected true or false", text);
  return b;
}
std::string expected(Boolean, std::string_view) { return kBoolean.expected(); }
std::string format(Boolean, const bool& v) { return kBoolean.format(v); }

std::variant<double, std::string> parse(PositiveRate, std::string_view text, std::string_view doc) {
  return rate(text, false, doc);
}
std::string expected(PositiveRate, std::string_view doc) { return std::string(doc); }
std::string format(PositiveRate, const double& v) { return fmt::format("{:g}", v); }

std::variant<double, std::string> parse(RateOrZero, std::string_view text, std::string_view doc) {
  return rate(text, true, doc);
}
std::string expected(RateOrZero, std::string_view doc) { return std::string(doc); }
std::string format(RateOrZero, const double& v) { return v > 0 ? fmt::format("{:g}", v) : "0 (no limit)"; }

std::variant<std::uint64_t, std::string> parse(Bandwidth, std::string_view text, std::string_view) {
  return parse_bandwidth(text);
}
std::string expected(Bandwidth, std::string_view) { return "a bandwidth such as \"2 MB/s\""; }
std::string format(Bandwidth, const std::uint64_t& v) { return fmt::format("{} B/s", v); }

std::variant<std::chrono::nanoseconds, std::string> parse(Duration, std::string_view text, std::string_view) {
  return parse_duration(text);
}
std::string expected(Duration, std::string_view) { return "a duration such as \"100ms\""; }
std::string format(Duration, const std::chrono::nanoseconds& v) {
  return fmt::format("{} ms", static_cast<double>(v.count()) / 1e6);
}

namespace {

constexpr std::string_view kRos2Expected =
    "true, false or a map of name (a ROS 2 topic name), type (pkg/msg/Name), frame_id, child_frame_id and qos "
    "(default or sensor_data)";
constexpr Names<Ros2Mapping::Qos, 3> kRos2Qos{"ROS 2 QoS profile",
                                              {{{Ros2Mapping::Qos::Default, "default"},
                                                {Ros2Mapping::Qos::SensorData, "sensor_data"},
                                                {Ros2Mapping::Qos::Topic, "topic"}}}};

// One key of a `ros2:` map into m; an error text, or empty.
std::string ros2_key(Ros2Mapping& m, const std::string& key, const std::string& value) {
  if (key == "name") {
    auto n = ros2::topic_name(value);
    if (!n) return n.error().message();
    m.name = *n;
  } else if (key == "type") {
    auto t = ros2::parse_type_name(value);
    if (!t) return t.error().message();
    m.type = t->full();
  } else if (key == "frame_id" || key == "child_frame_id") {
    if (value.size() > 255 || value.find('\0') != std::string::npos)
      return fmt::format("{} '{}' is not a frame id; expected at most 255 characters", key, value.substr(0, 40));
    (key == "frame_id" ? m.frame_id : m.child_frame_id) = value;
  } else if (key == "qos") {
    auto q = kRos2Qos.parse(value);
    if (const auto* why = std::get_if<std::string>(&q)) return *why;
    m.qos = std::get<0>(q);
  } else {
    return fmt::format("unknown key '{}' in ros2; expected name, type, frame_id, child_frame_id or qos", key);
  }
  return {};
}

}  // namespace

std::variant<Ros2Mapping, std::string> parse(Ros2, std::string_view text, std::string_view) {
  Ros2Mapping m;
  YAML::Node node;
  try {
    node = YAML::Load(std::string(text));
  } catch (const YAML::Exception& e) {
    return fmt::format("'{}' is not {} ({})", text, kRos2Expected, e.msg);
  }
  if (node.IsScalar()) {
    auto b = kBoolean.parse(node.Scalar());
    if (std::holds_alternative<std::string>(b)) return fmt::format("'{}' is not {}", text, kRos2Expected);
    m.enabled = std::get<bool>(b);
    return m;
  }
  if (!node.IsMap()) return fmt::format("'{}' is not {}", text, kRos2Expected);
  for (const auto& kv : node) {
    if (!kv.first.IsScalar() || !kv.second.IsScalar())
      return fmt::format("'{}' is not {}: each key and value is a plain word", text, kRos2Expected);
    if (std::string why = ros2_key(m, kv.first.Scalar(), kv.second.Scalar()); !why.empty()) return why;
  }
  return m;
}
std::string expected(Ros2, std::string_view) { return std::string(kRos2Expected); }
std::string format(Ros2, const Ros2Mapping& m) {
  if (!m.enabled) return "false";
  std::string out;
  auto add = [&](std::string_view key, std::string_view value) {
    if (!value.empty()) out += fmt::format("{}{}: {}", out.empty() ? "" : ", ", key, value);
  };
  add("name", m.name);
  add("type", m.type);
  add("frame_id", m.frame_id);
  add("child_frame_id", m.child_frame_id);
  if (m.qos != Ros2Mapping::Qos::Topic) add("qos", kRos2Qos.format(m.qos));
  return out.empty() ? "true" : "{" + out + "}";
}

}  // namespace setting

namespace {

std::vector<RuleKey> make_rule_keys() {
  std::vector<RuleKey> keys = {
      {"match", "", "\"fleet.**\"", "the topic-name pattern the rule applies to: '*' one dot-separated segment, '**' any "
                                    "number (also none); the first rule that matches wins"},
      {"scope", "backend", "fleet", "process, host or fleet (with `backend:` or network.backend)"},
  };
#define HORUS_RULE_KEY(member, Kind, Rule, key, example, dflt, unset, doc) \
  HORUS_SETTING_IF_IN_FILE_##Rule(keys.push_back({key, #member, example, doc});)
  HORUS_TOPIC_SETTINGS(HORUS_RULE_KEY)
#undef HORUS_RULE_KEY
  keys.push_back({"protection", "", "sign",
                  "fleet topics under DDS-Security: encrypt (the default) or sign (authenticated, not secret; "
                  "`horus security governance`)"});
  return keys;
}

}  // namespace

std::span<const RuleKey> rule_keys() noexcept {
  static const std::vector<RuleKey> keys = make_rule_keys();
  return keys;
}

std::string settings_table() {
  std::string out = "| file key | `TopicOptions` | example | what it chooses |\n|---|---|---|---|\n";
  auto row = [&](std::string_view key, std::string_view member, std::string_view example, std::string_view doc) {
    out += fmt::format("| {} | {} | {} | {} |\n", key.empty() ? "-" : fmt::format("`{}`", key),
                       member.empty() ? "-" : fmt::format("`{}`", member),
                       example.empty() ? "-" : fmt::format("`{}`", example), doc);
  };
  for (const RuleKey& k : rule_keys()) row(k.key, k.member, k.example, k.doc);
#define HORUS_CODE_ONLY_ROW(member, Kind, Rule, key, example, dflt, unset, doc) \
  if (std::string_view(key).empty()) row("", #member, "", doc);
  HORUS_TOPIC_SETTINGS(HORUS_CODE_ONLY_ROW)
#undef HORUS_CODE_ONLY_ROW
  return out;
}

}  // namespace horus
