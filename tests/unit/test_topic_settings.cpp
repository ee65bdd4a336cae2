// The per-topic settings' table (horus/topic_options.hpp, HORUS_TOPIC_SETTINGS): README shows the
// table `horus config settings` prints; every key README documents parses with its example, and
// every key the parser knows is documented (the parser's own list, from its error, not the
// table's); every setting of the plain kind goes from the file and from code through choose()
// and options_of with its source.
#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "horus/config.hpp"
#include "horus/transport_registry.hpp"
#include "process_support.hpp"

namespace {

std::string read_all(const char* path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

constexpr std::string_view kBegin = "<!-- the table `horus config settings` prints (a test compares) -->\n";
constexpr std::string_view kEnd = "<!-- end of the table -->";

// README's table of settings (between its markers), or "" when the markers are missing.
std::string readme_table() {
  const std::string readme = read_all(HORUS_README);
  const auto a = readme.find(kBegin);
  const auto b = readme.find(kEnd);
  if (a == std::string::npos || b == std::string::npos || b < a) return {};
  return readme.substr(a + kBegin.size(), b - a - kBegin.size());
}

struct Row {
  std::string key, example;
};

// The rows of a Markdown table whose first column is a file key (`key`, or - for code only).
std::vector<Row> rows_of(const std::string& table) {
  std::vector<Row> rows;
  std::istringstream in(table);
  std::string line;
  auto cell = [](std::string c) {
    while (!c.empty() && c.front() == ' ') c.erase(0, 1);
    while (!c.empty() && c.back() == ' ') c.pop_back();
    if (c.size() >= 2 && c.front() == '`' && c.back() == '`') c = c.substr(1, c.size() - 2);
    return c;
  };
  while (std::getline(in, line)) {
    if (!line.starts_with("| ")) continue;
    std::vector<std::string> cells;
    std::size_t at = 1;
    for (std::size_t bar; (bar = line.find(" |", at)) != std::string::npos; at = bar + 2)
      cells.push_back(cell(line.substr(at, bar - at)));
    if (cells.size() < 3 || cells[0] == "file key") continue;
    rows.push_back({cells[0], cells[2]});
  }
  return rows;
}

}  // namespace

TEST(TopicSettings, ReadmeShowsTheTableThatHorusConfigSettingsPrints) {
  const std::string table = readme_table();
  ASSERT_FALSE(table.empty()) << "README.md has no table of settings between '" << kBegin << "' and '" << kEnd << "'";
  EXPECT_EQ(table, horus::settings_table()) << "README.md's table differs from `horus config settings`; paste its output";
  std::string out;
  ASSERT_EQ(horus_test::run_command(std::string(HORUS_CLI) + " config settings", out), 0) << out;
  EXPECT_EQ(out, horus::settings_table());
}

TEST(TopicSettings, EveryKeyReadmeDocumentsParsesWithItsExample) {
  const auto rows = rows_of(readme_table());
  ASSERT_GE(rows.size(), 10u);
  const auto transports = horus::net::transport_names();
  for (const Row& r : rows) {
    if (r.key == "-" || r.key == "match") continue;
    // A fleet rule needs a transport; a build without any documents the same keys.
    if ((r.key == "backend" || r.key == "scope" || r.key == "protection") && transports.empty()) continue;
    std::string example = r.example;
    if (r.key == "backend") example = transports.front();
    const std::string network = transports.empty() ? "" : "network:\n  backend: " + transports.front() + "\n";
    const std::string yaml = network + "topics:\n  - match: \"a.*\"\n    " + r.key + ": " + example + "\n";
    auto c = horus::Config::parse(yaml, "readme.yaml");
    ASSERT_TRUE(c) << "README documents '" << r.key << ": " << r.example << "', which does not parse: "
                   << c.error().message();
    ASSERT_EQ(c->rules().size(), 1u);
  }
}

TEST(TopicSettings, EveryKeyTheParserKnowsIsDocumentedInReadme) {
  auto c = horus::Config::parse("topics:\n  - match: a\n    no_such_key: 1\n", "keys.yaml");
  ASSERT_FALSE(c);
  const std::string msg = c.error().message();
  const std::string lead = "unknown key; expected ";
  const auto at = msg.find(lead);
  ASSERT_NE(at, std::string::npos) << msg;
  // "a, b, c or d": the parser's own list of a rule's keys.
  std::string list = msg.substr(at + lead.size());
  std::vector<std::string> keys;
  for (std::size_t pos = 0; pos < list.size();) {
    std::size_t end = std::min(list.find(", ", pos), list.find(" or ", pos));
    if (end == std::string::npos) end = list.size();
    keys.push_back(list.substr(pos, end - pos));
    pos = end == list.size() ? end : end + (list.compare(end, 4, " or ") == 0 ? 4 : 2);
  }
  ASSERT_GE(keys.size(), 10u) << msg;
  std::set<std::string> documented;
  for (const auto& r : rows_of(readme_table())) documented.insert(r.key);
  for (const auto& k : keys) EXPECT_TRUE(documented.contains(k)) << "the parser knows '" << k << "'; README does not document it";
  for (const auto& k : documented) {
    if (k == "-") continue;
    EXPECT_NE(std::find(keys.begin(), keys.end(), k), keys.end()) << "README documents '" << k << "'; the parser refuses it";
  }
}

// Each setting of the plain kind: the file's example reaches TopicChoice (source file) and
// options_of; the same value in code wins (source code).
TEST(TopicSettings, EveryPlainSettingGoesFromTheFileAndFromCodeWithItsSource) {
  int checked = 0;
#define HORUS_CHECK_SETTING(member, Kind, Rule, key, example, dflt, unset, doc)                                       \
  HORUS_SETTING_IF_PLAIN_##Rule({                                                                                      \
    SCOPED_TRACE(key);                                                                                                 \
    auto file = horus::Config::parse(std::string("topics:\n  - match: t\n    ") + key + ": " + example + "\n", "s.yaml"); \
    ASSERT_TRUE(file) << file.error().message();                                                                       \
    auto from_file = horus::choose("t", horus::TopicOptions{}, &*file);                                                \
    ASSERT_TRUE(from_file) << from_file.error().message();                                                             \
    ASSERT_TRUE(from_file->member.has_value());                                                                        \
    EXPECT_EQ(from_file->member##_from, horus::Source::File);                                                          \
    EXPECT_EQ(horus::options_of(*from_file, {}).member, from_file->member);                                            \
    horus::TopicOptions code;                                                                                          \
    code.member = *from_file->member;                                                                                  \
    auto from_code = horus::choose("t", code, &*file);                                                                 \
    ASSERT_TRUE(from_code);                                                                                            \
    EXPECT_EQ(from_code->member##_from, horus::Source::Code);                                                          \
    auto none = horus::choose("t", horus::TopicOptions{}, nullptr);                                                    \
    ASSERT_TRUE(none);                                                                                                 \
    EXPECT_FALSE(none->member.has_value());                                                                            \
    EXPECT_EQ(none->member##_from, horus::Source::Default);                                                            \
    ++checked;                                                                                                         \
  })
  HORUS_TOPIC_SETTINGS(HORUS_CHECK_SETTING)
#undef HORUS_CHECK_SETTING
  EXPECT_GE(checked, 9);
}

// The `ros2:` key (docs/ROS2.md): true, false or a map; each value checked as ROS 2 checks it.
TEST(TopicSettings, Ros2IsTrueFalseOrAMapOfCheckedValues) {
  using horus::Ros2Mapping;
  auto parse = [](const std::string& text) { return horus::setting::parse(horus::setting::Ros2{}, text); };
  auto value = [&](const std::string& text) { return std::get<Ros2Mapping>(parse(text)); };
  auto error = [&](const std::string& text) {
    auto v = parse(text);
    return std::holds_alternative<std::string>(v) ? std::get<std::string>(v) : std::string("(no error)");
  };
  EXPECT_EQ(value("true"), Ros2Mapping{});
  EXPECT_FALSE(value("false").enabled);
  const auto m = value("{name: cmd_vel, type: geometry_msgs/Twist, frame_id: base_link, qos: sensor_data}");
  EXPECT_EQ(m.name, "/cmd_vel");                  // made absolute
  EXPECT_EQ(m.type, "geometry_msgs/msg/Twist");   // the short form made full
  EXPECT_EQ(m.frame_id, "base_link");
  EXPECT_EQ(m.qos, Ros2Mapping::Qos::SensorData);
  EXPECT_EQ(horus::setting::format(horus::setting::Ros2{}, m),
            "{name: /cmd_vel, type: geometry_msgs/msg/Twist, frame_id: base_link, qos: sensor_data}");
  EXPECT_EQ(value(horus::setting::format(horus::setting::Ros2{}, m)), m);  // what explain prints parses back
  EXPECT_NE(error("{name: /robot1/2d}").find("starts with a digit"), std::string::npos);
  EXPECT_NE(error("{name: /a//b}").find("'//'"), std::string::npos);
  EXPECT_NE(error("{name: /a__b}").find("repeated underscores"), std::string::npos);
  EXPECT_NE(error("{name: /a-b}").find("'-'"), std::string::npos);
  EXPECT_NE(error("{type: Geometry/Twist}").find("package 'Geometry'"), std::string::npos);
  EXPECT_NE(error("{type: geometry_msgs/srv/Twist}").find("not a message type"), std::string::npos);
  EXPECT_NE(error("{qos: fast}").find("unknown ROS 2 QoS profile 'fast'"), std::string::npos);
  EXPECT_NE(error("{nmae: /x}").find("unknown key 'nmae' in ros2"), std::string::npos);
  EXPECT_NE(error("maybe").find("true, false or a map"), std::string::npos);
}

// A ROS 2 mapping is a fleet topic on DDS: without a scope it gets one (Cyclone DDS unless the
// file's network.backend is another DDS); a host scope or LCM is an error naming both.
TEST(TopicSettings, Ros2MakesAFleetTopicOnDdsAndRefusesAnotherScopeOrLcm) {
  if (horus::net::find_transport("cyclonedds") == nullptr) GTEST_SKIP() << "this build has no Cyclone DDS backend";
  auto file = horus::Config::parse("topics:\n  - match: cmd_vel\n    ros2: {name: /cmd_vel}\n", "r.yaml");
  ASSERT_TRUE(file) << file.error().message();
  auto c = horus::choose("cmd_vel", {}, &*file);
  ASSERT_TRUE(c) << c.error().message();
  EXPECT_EQ(c->backend, horus::Backend::CycloneDds);
  EXPECT_EQ(c->backend_from, horus::Source::File);
  auto host = horus::Config::parse("topics:\n  - match: cmd_vel\n    scope: host\n    ros2: true\n", "r.yaml");
  ASSERT_FALSE(host);
  EXPECT_NE(host.error().message().find("r.yaml, line 4, key 'topics[0].ros2'"), std::string::npos) << host.error().message();
  EXPECT_NE(host.error().message().find("scope is host"), std::string::npos) << host.error().message();
  auto lcm = horus::Config::parse("topics:\n  - match: cmd_vel\n    backend: lcm\n    ros2: true\n", "r.yaml");
  ASSERT_FALSE(lcm);
  EXPECT_NE(lcm.error().message().find("backend is lcm"), std::string::npos) << lcm.error().message();
  horus::TopicOptions code;
  code.backend = horus::Backend::SharedMemory;
  code.ros2 = horus::Ros2Mapping{};
  auto both = horus::choose("cmd_vel", code, nullptr);
  ASSERT_FALSE(both);
  EXPECT_NE(both.error().message().find("maps it onto ROS 2"), std::string::npos) << both.error().message();
  code.backend = horus::Backend::Lcm;
  auto on_lcm = horus::choose("cmd_vel", code, nullptr);
  ASSERT_FALSE(on_lcm);
  EXPECT_NE(on_lcm.error().message().find("ROS 2 nodes speak DDS"), std::string::npos) << on_lcm.error().message();
  code.backend.reset();
  code.ros2->enabled = false;  // off: nothing changes
  auto off = horus::choose("cmd_vel", code, nullptr);
  ASSERT_TRUE(off);
  EXPECT_FALSE(horus::is_network(off->backend));
}

// The file's `ros2:` section names the process's node on the ROS 2 graph, by ROS 2's rules.
TEST(TopicSettings, TheFilesRos2NodeIsCheckedByRos2sRules) {
  auto ok = horus::Config::parse("ros2:\n  node: /robot1/planner\n", "n.yaml");
  ASSERT_TRUE(ok) << ok.error().message();
  EXPECT_EQ(ok->ros2().node, "/robot1/planner");
  auto digit = horus::Config::parse("ros2:\n  node: 9lives\n", "n.yaml");
  ASSERT_FALSE(digit);
  EXPECT_NE(digit.error().message().find("n.yaml, line 2, key 'ros2.node': ROS 2 node name '9lives' starts with a digit"),
            std::string::npos)
      << digit.error().message();
  auto dash = horus::Config::parse("ros2:\n  node: my-node\n", "n.yaml");
  ASSERT_FALSE(dash);
  EXPECT_NE(dash.error().message().find("has '-'"), std::string::npos) << dash.error().message();
  auto key = horus::Config::parse("ros2:\n  name: x\n", "n.yaml");
  ASSERT_FALSE(key);
  EXPECT_NE(key.error().message().find("unknown key; expected node"), std::string::npos) << key.error().message();
}
