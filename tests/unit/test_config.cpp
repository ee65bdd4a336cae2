// The configuration file (horus/config.hpp): parsing, errors naming file/line/key, topic
// patterns, first-match rules, precedence (code > environment > file > defaults), and what a
// Topic opened under HORUS_CONFIG gets. ctest runs each test in its own process, so the
// process-wide HORUS_CONFIG cache starts empty in each.
#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <string>
#include <vector>

#include <unistd.h>

#include "horus/config.hpp"
#include "horus/environment.hpp"
#include "horus/network.hpp"
#include "horus/msg/geometry.hpp"
#include "horus/topic.hpp"
#include "process_support.hpp"
#include "test_support.hpp"

namespace {

using horus::Config;
using horus::Errc;
using horus::Scope;
using horus::Source;

using horus_test::TempFile;

// The error of parsing `text` (which must fail).
std::string parse_error(const std::string& text) {
  auto c = Config::parse(text, "robot.yaml");
  EXPECT_FALSE(c.has_value()) << "parsed:\n" << text;
  if (c) return {};
  EXPECT_EQ(c.error().code(), Errc::Config);
  return c.error().message();
}

class ConfigTest : public ::testing::Test {
 protected:
  void SetUp() override {
    ::unsetenv("HORUS_BACKEND");
    ::unsetenv("HORUS_CONFIG");
    ::unsetenv("HORUS_DOMAIN_ID");
    ::unsetenv("HORUS_DDS_LOCALHOST");
    ::unsetenv("HORUS_PEERS");
  }
};

constexpr const char* kExample = R"(network:
  backend: cyclonedds
  domain_id: 7
  localhost_only: true
  lcm_url: "udpm://239.255.76.67:7667?ttl=1"
topics:
  - match: "fleet.**"
    scope: fleet
    backend: lcm
    reliability: reliable
    durability: transient_local
    capacity: 64
  - match: "camera.*"
    scope: host
    capacity: 4
  - match: "debug.**"
    scope: process
  - match: "**"
    scope: fleet
)";

TEST_F(ConfigTest, TheIssuesExampleParsesIntoItsNetworkSectionAndRulesWithTheirLines) {
  auto c = Config::parse(kExample, "robot.yaml");
  ASSERT_TRUE(c.has_value()) << c.error().message();
  EXPECT_EQ(c->network().backend, "cyclonedds");
  EXPECT_EQ(c->network().domain_id, 7u);
  EXPECT_EQ(c->network().localhost_only, true);
  EXPECT_EQ(c->network().lcm_url, "udpm://239.255.76.67:7667?ttl=1");
  ASSERT_EQ(c->rules().size(), 4u);
  const auto& fleet = c->rules()[0];
  EXPECT_EQ(fleet.match, "fleet.**");
  EXPECT_EQ(fleet.line, 7);
  EXPECT_EQ(fleet.scope, Scope::Fleet);
  EXPECT_EQ(fleet.backend, "lcm");
  EXPECT_EQ(fleet.reliability, horus::net::Reliability::Reliable);
  EXPECT_EQ(fleet.durability, horus::net::Durability::TransientLocal);
  EXPECT_EQ(fleet.capacity, 64u);
  EXPECT_EQ(c->rules()[1].scope, Scope::Host);
  EXPECT_EQ(c->rules()[1].line, 13);
  EXPECT_EQ(c->rules()[2].scope, Scope::Process);
  EXPECT_FALSE(c->rules()[3].backend.has_value());  // network.backend applies
}

TEST_F(ConfigTest, PatternsMatchWholeSegmentsStarOneAndDoubleStarAnyNumber) {
  using horus::topic_pattern_matches;
  EXPECT_TRUE(topic_pattern_matches("fleet.**", "fleet"));
  EXPECT_TRUE(topic_pattern_matches("fleet.**", "fleet.pose"));
  EXPECT_TRUE(topic_pattern_matches("fleet.**", "fleet.robot_1.pose"));
  EXPECT_FALSE(topic_pattern_matches("fleet.**", "fleetwide.pose"));
  EXPECT_TRUE(topic_pattern_matches("camera.*", "camera.front"));
  EXPECT_FALSE(topic_pattern_matches("camera.*", "camera"));
  EXPECT_FALSE(topic_pattern_matches("camera.*", "camera.front.raw"));
  EXPECT_TRUE(topic_pattern_matches("*.cmd_vel", "robot_2.cmd_vel"));
  EXPECT_FALSE(topic_pattern_matches("*.cmd_vel", "cmd_vel"));
  EXPECT_TRUE(topic_pattern_matches("robot.**.pose", "robot.pose"));
  EXPECT_TRUE(topic_pattern_matches("robot.**.pose", "robot.a.b.pose"));
  EXPECT_FALSE(topic_pattern_matches("robot.**.pose", "robot.a.b.twist"));
  EXPECT_TRUE(topic_pattern_matches("**", "anything.at.all"));
  EXPECT_TRUE(topic_pattern_matches("imu", "imu"));
  EXPECT_FALSE(topic_pattern_matches("imu", "imu.raw"));
}

TEST_F(ConfigTest, BadPatternsAreRejectedWithTheRule) {
  for (const char* p : {"", "a..b", ".a", "a.", "cam*", "a/b", "a.b c"}) {
    auto ok = horus::check_topic_pattern(p);
    EXPECT_FALSE(ok.has_value()) << "'" << p << "' was accepted";
    if (!ok) {
      EXPECT_NE(ok.error().message().find("segment"), std::string::npos) << ok.error().message();
    }
  }
  EXPECT_TRUE(horus::check_topic_pattern("robot_1.*.pose-raw.**").has_value());
}

TEST_F(ConfigTest, TheFirstMatchingRuleWins) {
  auto c = Config::parse(kExample, "robot.yaml");
  ASSERT_TRUE(c.has_value()) << c.error().message();
  ASSERT_NE(c->match("camera.front"), nullptr);
  EXPECT_EQ(c->match("camera.front")->match, "camera.*");
  EXPECT_EQ(c->match("fleet.robot_1.pose")->match, "fleet.**");
  EXPECT_EQ(c->match("debug.trace")->match, "debug.**");
  EXPECT_EQ(c->match("camera.front.raw")->match, "**");  // camera.* wants exactly one segment
  auto none = Config::parse("topics:\n  - match: a.*\n    scope: host\n");
  ASSERT_TRUE(none.has_value());
  EXPECT_EQ(none->match("b.c"), nullptr);
}

TEST_F(ConfigTest, EveryErrorNamesTheFileTheLineTheKeyAndWhatIsValid) {
  struct Case {
    std::string text;
    std::vector<std::string> expected;  // substrings of the message
  };
  const std::vector<Case> cases{
      {"netwrok:\n  backend: lcm\n", {"robot.yaml, line 1", "'netwrok'", "unknown key", "network, fleet, security, ros2 or topics"}},
      {"fleet:\n  heartbeat_ms: 5\n", {"line 2", "fleet.heartbeat_ms", "'5'", "10 to 60000"}},
      {"fleet:\n  misses: 0\n", {"line 2", "fleet.misses", "1 to 100"}},
      {"fleet:\n  max_hosts: 4\n", {"line 2", "fleet.max_hosts", "8 to 65536"}},
      {"fleet:\n  forget_after: soon\n", {"line 2", "fleet.forget_after", "'soon'", "min or h"}},
      {"fleet:\n  announce: often\n", {"line 2", "fleet.announce", "true or false"}},
      {"fleet:\n  heartbeat: 100\n", {"line 2", "fleet.heartbeat", "unknown key", "heartbeat_ms"}},
      {"topics:\n  - match: a.**\n    scop: host\n", {"line 3", "topics[0].scop", "unknown key", "scope"}},
      {"topics:\n  - match: a\n    scope: local\n", {"line 3", "topics[0].scope", "'local'", "process, host or fleet"}},
      {"topics:\n  - match: a\n    capacity: many\n", {"line 3", "topics[0].capacity", "'many'", "power of two"}},
      {"topics:\n  - match: a\n    capacity: 48\n", {"line 3", "48 is not a power of two"}},
      {"topics:\n  - match: a\n    capacity: [4]\n", {"line 3", "found a list"}},
      {"topics:\n  - scope: host\n", {"line 2", "topics[0]", "no 'match'"}},
      {"topics:\n  - match: \"cam*\"\n", {"line 2", "topics[0].match", "whole segment"}},
      {"topics:\n  - match: a\n    scope: fleet\n", {"line 2", "needs a network backend"}},
      {"topics:\n  - match: a\n    scope: host\n    backend: lcm\n", {"line 4", "fleet topics only", "host"}},
      {"topics:\n  - match: a\n    backend: zenoh\n", {"line 3", "unknown network backend 'zenoh'", "cyclonedds"}},
      {"topics:\n  - match: a\n    backend: shm\n", {"line 3", "scope: host"}},
      {"topics:\n  - match: a\n    reliability: sometimes\n", {"line 3", "best_effort or reliable"}},
      {"topics:\n  - match: a\n    durability: forever\n", {"line 3", "volatile or transient_local"}},
      {"network:\n  domain_id: 300\n", {"line 2", "network.domain_id", "'300'", "0 to 232"}},
      {"network:\n  domain_id: -1\n", {"line 2", "network.domain_id"}},
      {"network:\n  localhost_only: maybe\n", {"line 2", "network.localhost_only", "true or false"}},
      {"network:\n  backend: cyclonedds\n  backend: lcm\n", {"line 3", "network.backend", "given twice"}},
      {"topics:\n  match: a\n", {"line 2", "'topics'", "list of rules"}},
      {"network: [1, 2]\n", {"line 1", "'network'", "expected a map"}},
      {"network:\n  peers: 10.0.0.2\n", {"line 2", "network.peers", "a list of host names or IPv4 addresses"}},
      {"network:\n  peers: [10.0.0.2, \"robot 3\"]\n", {"line 2", "network.peers[1]", "'robot 3'", "has ' '"}},
      {"network:\n  peers:\n    - 10.0.0.256\n", {"line 3", "network.peers[0]", "not an IPv4 address"}},
      {"network:\n  peers:\n    - [a]\n", {"line 3", "network.peers[0]", "a host name or an IPv4 address"}},
      {"- a\n- b\n", {"line 1", "expected a map"}},
      {"topics:\n  - match: a\n    scope: [host\n", {"robot.yaml, line", "not valid YAML"}},
  };
  for (const auto& c : cases) {
    const std::string msg = parse_error(c.text);
    for (const auto& e : c.expected) EXPECT_NE(msg.find(e), std::string::npos) << "'" << e << "' not in: " << msg;
  }
}

TEST_F(ConfigTest, AnUnreadableFileIsAnErrorNamingIt) {
  auto c = Config::load("/nonexistent/horus.yaml");
  ASSERT_FALSE(c.has_value());
  EXPECT_NE(c.error().message().find("/nonexistent/horus.yaml"), std::string::npos) << c.error().message();
  EXPECT_NE(c.error().message().find("cannot be read"), std::string::npos) << c.error().message();
  auto empty = Config::parse("", "empty.yaml");
  ASSERT_TRUE(empty.has_value());  // an empty file is no rule
  EXPECT_TRUE(empty->rules().empty());
}

TEST_F(ConfigTest, CodeBeatsEnvironmentBeatsFileBeatsDefaults) {
  auto c = Config::parse(kExample, "robot.yaml");
  ASSERT_TRUE(c.has_value()) << c.error().message();
  // File.
  auto f = horus::choose("fleet.pose", {}, &*c);
  ASSERT_TRUE(f.has_value()) << f.error().message();
  EXPECT_EQ(f->backend, horus::Backend::Lcm);
  EXPECT_EQ(f->backend_from, Source::File);
  EXPECT_EQ(f->capacity, 64u);
  EXPECT_EQ(f->capacity_from, Source::File);
  EXPECT_EQ(f->reliability_from, Source::File);
  // network.backend for a fleet rule without its own backend.
  auto other = horus::choose("misc.thing", {}, &*c);
  ASSERT_TRUE(other.has_value());
  EXPECT_EQ(other->backend, horus::Backend::CycloneDds);
  // Environment over the file.
  ::setenv("HORUS_BACKEND", "inproc", 1);
  auto e = horus::choose("fleet.pose", {}, &*c);
  ASSERT_TRUE(e.has_value());
  EXPECT_EQ(e->backend, horus::Backend::InProcess);
  EXPECT_EQ(e->backend_from, Source::Environment);
  EXPECT_EQ(e->capacity_from, Source::File);  // HORUS_BACKEND says nothing of capacity
  // Code over both.
  horus::TopicOptions code;
  code.backend = horus::Backend::SharedMemory;
  code.capacity = 8;
  auto k = horus::choose("fleet.pose", code, &*c);
  ASSERT_TRUE(k.has_value());
  EXPECT_EQ(k->backend, horus::Backend::SharedMemory);
  EXPECT_EQ(k->backend_from, Source::Code);
  EXPECT_EQ(k->capacity, 8u);
  EXPECT_EQ(k->capacity_from, Source::Code);
  // Defaults: no file.
  ::unsetenv("HORUS_BACKEND");
  auto d = horus::choose("fleet.pose", {}, nullptr);
  ASSERT_TRUE(d.has_value());
  EXPECT_EQ(d->backend, horus::Backend::SharedMemory);
  EXPECT_EQ(d->backend_from, Source::Default);
  EXPECT_FALSE(d->capacity.has_value());
  // A bad HORUS_BACKEND is its error, file or not.
  ::setenv("HORUS_BACKEND", "carrier-pigeon", 1);
  auto bad = horus::choose("fleet.pose", {}, &*c);
  ASSERT_FALSE(bad.has_value());
  EXPECT_NE(bad.error().message().find("HORUS_BACKEND=carrier-pigeon"), std::string::npos);
}

TEST_F(ConfigTest, ATopicOpenedUnderHorusConfigGetsItsRuleScopeAndCapacity) {
  TempFile file("topics:\n  - match: \"debug.**\"\n    scope: process\n    capacity: 8\n  - match: \"**\"\n    scope: host\n");
  ::setenv("HORUS_CONFIG", file.path.c_str(), 1);
  auto dbg = horus::Topic<horus::msg::CmdVel>::open("debug.trace");
  ASSERT_TRUE(dbg.has_value()) << dbg.error().message();
  EXPECT_EQ(dbg->backend(), horus::Backend::InProcess);
  EXPECT_EQ(dbg->scope(), Scope::Process);
  EXPECT_EQ(dbg->capacity(), 8u);
  horus::TopicOptions code;
  code.capacity = 16;  // code wins over the file's 8
  auto coded = horus::Topic<horus::msg::CmdVel>::open("debug.coded", code);
  ASSERT_TRUE(coded.has_value()) << coded.error().message();
  EXPECT_EQ(coded->capacity(), 16u);
  EXPECT_EQ(coded->backend(), horus::Backend::InProcess);
  auto other = horus::Topic<horus::msg::CmdVel>::open("status.battery");  // the "**" rule: host
  ASSERT_TRUE(other.has_value()) << other.error().message();
  EXPECT_EQ(other->scope(), Scope::Host);
}

TEST_F(ConfigTest, AMalformedHorusConfigFailsEveryOpenNamingTheVariableFileAndLine) {
  TempFile file("topics:\n  - match: a\n    scope: sideways\n");
  ::setenv("HORUS_CONFIG", file.path.c_str(), 1);
  for (int i = 0; i < 2; ++i) {
    auto t = horus::Topic<horus::msg::CmdVel>::open("a");
    ASSERT_FALSE(t.has_value());
    EXPECT_EQ(t.error().code(), Errc::Config);
    const auto& m = t.error().message();
    EXPECT_NE(m.find("HORUS_CONFIG="), std::string::npos) << m;
    EXPECT_NE(m.find(file.path + ", line 3"), std::string::npos) << m;
    EXPECT_NE(m.find("'sideways'"), std::string::npos) << m;
  }
}

TEST_F(ConfigTest, TheFilesNetworkSectionIsTheTransportsDefaultAndTheEnvironmentOverridesIt) {
  TempFile file("network:\n  domain_id: 42\n  localhost_only: true\n");
  ::setenv("HORUS_CONFIG", file.path.c_str(), 1);
  auto c = horus::config_from_environment();
  ASSERT_TRUE(c.has_value()) << c.error().message();
  ASSERT_NE(*c, nullptr);
  auto n = horus::net::config_from_environment();
  ASSERT_TRUE(n.has_value()) << n.error().message();
  EXPECT_EQ(n->domain_id, 42u);
  EXPECT_TRUE(n->localhost_only);
  ::setenv("HORUS_DOMAIN_ID", "3", 1);
  ::setenv("HORUS_DDS_LOCALHOST", "0", 1);
  n = horus::net::config_from_environment();
  ASSERT_TRUE(n.has_value()) << n.error().message();
  EXPECT_EQ(n->domain_id, 3u);
  EXPECT_FALSE(n->localhost_only);
}

TEST_F(ConfigTest, PeersComeFromHorusPeersElseTheFileAndABadEntryIsNamed) {
  horus::Environment env;
  horus::net::FileDefaults file;
  file.peers = std::vector<std::string>{"robot-1.local", "10.0.0.3"};
  file.origin = "configuration file 'robot.yaml'";
  auto from_file = horus::net::config_from(env, file);
  ASSERT_TRUE(from_file.has_value()) << from_file.error().message();
  EXPECT_EQ(from_file->peers, (std::vector<std::string>{"robot-1.local", "10.0.0.3"}));
  EXPECT_EQ(from_file->peers_origin, "configuration file 'robot.yaml', network.peers");
  env.peers = "10.0.0.2, robot-3,,";
  auto from_env = horus::net::config_from(env, file);
  ASSERT_TRUE(from_env.has_value()) << from_env.error().message();
  EXPECT_EQ(from_env->peers, (std::vector<std::string>{"10.0.0.2", "robot-3"}));
  EXPECT_EQ(from_env->peers_origin, "environment variable HORUS_PEERS");
  for (const auto& [value, expected] : std::vector<std::pair<std::string, std::string>>{
           {"10.0.0.2,robot_3", "peer 2 'robot_3' has '_'"},
           {"1.2.3", "not an IPv4 address"},
           {"300.1.1.1", "not an IPv4 address"},
           {"-robot", "not a host name"},
           {",", "names no host"}}) {
    env.peers = value;
    auto bad = horus::net::config_from(env, file);
    ASSERT_FALSE(bad.has_value()) << value;
    EXPECT_EQ(bad.error().code(), horus::Errc::Config);
    EXPECT_NE(bad.error().message().find("HORUS_PEERS=" + value), std::string::npos) << bad.error().message();
    EXPECT_NE(bad.error().message().find(expected), std::string::npos) << bad.error().message();
  }
  auto c = Config::parse("network:\n  peers: [10.0.0.2, robot-3]\n", "robot.yaml");
  ASSERT_TRUE(c.has_value()) << c.error().message();
  EXPECT_EQ(c->network().peers, (std::vector<std::string>{"10.0.0.2", "robot-3"}));
}

TEST_F(ConfigTest, TheFleetSectionAndTheEnvironmentSetTheFleetLayer) {
  ::unsetenv("HORUS_FLEET_HEARTBEAT_MS");
  auto d = horus::fleet_settings();
  ASSERT_TRUE(d.has_value()) << d.error().message();
  EXPECT_EQ(d->heartbeat, std::chrono::milliseconds(100));
  EXPECT_EQ(d->misses, 3u);
  EXPECT_EQ(d->max_hosts, 1024u);
  EXPECT_EQ(d->forget_after, std::chrono::hours(1));
  EXPECT_TRUE(d->announce);
  EXPECT_EQ(d->transport, "");  // no network backend configured: the fleet layer has none
  TempFile file("network:\n  backend: lcm\nfleet:\n  heartbeat_ms: 250\n  announce_ms: 5000\n  misses: 5\n  announce: false\n"
                "  max_hosts: 200\n  forget_after: 10min\n");
  ::setenv("HORUS_CONFIG", file.path.c_str(), 1);
  auto f = horus::fleet_settings();
  ASSERT_TRUE(f.has_value()) << f.error().message();
  EXPECT_EQ(f->heartbeat, std::chrono::milliseconds(250));
  EXPECT_EQ(f->announce_period, std::chrono::milliseconds(5000));
  EXPECT_EQ(f->misses, 5u);
  EXPECT_EQ(f->max_hosts, 200u);
  EXPECT_EQ(f->forget_after, std::chrono::minutes(10));
  EXPECT_FALSE(f->announce);
  EXPECT_EQ(f->transport, "lcm");
  ::setenv("HORUS_FLEET_HEARTBEAT_MS", "40", 1);
  ::setenv("HORUS_BACKEND", "cyclonedds", 1);
  f = horus::fleet_settings();
  ASSERT_TRUE(f.has_value()) << f.error().message();
  EXPECT_EQ(f->heartbeat, std::chrono::milliseconds(40));  // the environment wins
  EXPECT_EQ(f->transport, "cyclonedds");
  for (const char* bad : {"0", "5", "fast", "100ms", "70000"}) {
    ::setenv("HORUS_FLEET_HEARTBEAT_MS", bad, 1);
    auto e = horus::fleet_settings();
    ASSERT_FALSE(e.has_value()) << bad;
    EXPECT_NE(e.error().message().find("HORUS_FLEET_HEARTBEAT_MS='" + std::string(bad) + "'"), std::string::npos)
        << e.error().message();
    EXPECT_NE(e.error().message().find("10 to 60000"), std::string::npos) << e.error().message();
  }
  ::unsetenv("HORUS_FLEET_HEARTBEAT_MS");
}

}  // namespace

namespace {

TEST_F(ConfigTest, TheCliChecksAFileAndExplainsWhatATopicGetsAndFromWhere) {
  TempFile good(kExample);
  std::string out;
  const std::string cli = HORUS_CLI;
  EXPECT_EQ(horus_test::run_command(cli + " config check " + good.path, out), 0) << out;
  EXPECT_NE(out.find("valid; 4 rules"), std::string::npos) << out;

  TempFile bad("topics:\n  - match: a\n    scope: sideways\n");
  EXPECT_EQ(horus_test::run_command(cli + " config check " + bad.path, out), 1) << out;
  EXPECT_NE(out.find(bad.path + ", line 3, key 'topics[0].scope'"), std::string::npos) << out;

  EXPECT_EQ(horus_test::run_command(cli + " config explain fleet.robot_1.pose --file " + good.path, out), 0) << out;
  EXPECT_NE(out.find("rule        'fleet.**' (line 7)"), std::string::npos) << out;
  EXPECT_NE(out.find("scope       fleet"), std::string::npos) << out;
  EXPECT_NE(out.find("backend     lcm"), std::string::npos) << out;
  EXPECT_NE(out.find("capacity    64"), std::string::npos) << out;
  EXPECT_NE(out.find("file " + good.path + ", line 7"), std::string::npos) << out;

  // HORUS_CONFIG is the default file; HORUS_BACKEND beats it.
  EXPECT_EQ(horus_test::run_command("HORUS_CONFIG=" + good.path + " HORUS_BACKEND=inproc " + cli +
                                        " config explain camera.front",
                                    out),
            0)
      << out;
  EXPECT_NE(out.find("scope       process          environment (HORUS_BACKEND)"), std::string::npos) << out;
  EXPECT_NE(out.find("capacity    4"), std::string::npos) << out;
  EXPECT_EQ(horus_test::run_command(cli + " config explain 'bad/name' --file " + good.path, out), 2) << out;
  EXPECT_NE(out.find("invalid topic name"), std::string::npos) << out;
}

// Under DDS-Security, explain says where the settings come from and how the governance signed
// from the file protects a fleet topic: the first rule with `protection:` that matches, as
// DDS-Security matches it (a single `*` in an encrypt rule also crosses dots), else encrypt.
TEST_F(ConfigTest, TheCliExplainsAFleetTopicsSecurityAndProtection) {
  TempFile file(
      "security:\n  keystore: keys\n  identity: robot1\n"
      "topics:\n"
      "  - match: robot1.status\n    scope: fleet\n    backend: cyclonedds\n    protection: sign\n"
      "  - match: robot1.*\n    scope: fleet\n    backend: cyclonedds\n    protection: encrypt\n"
      "  - match: \"robot1.**\"\n    scope: fleet\n    backend: cyclonedds\n    protection: sign\n"
      "  - match: \"radio.**\"\n    scope: fleet\n    backend: lcm\n"
      "  - match: \"**\"\n    scope: fleet\n    backend: cyclonedds\n");
  std::string out;
  const std::string unset = "env -u HORUS_SECURITY -u HORUS_SECURITY_KEYSTORE -u HORUS_SECURITY_IDENTITY ";
  const std::string cli = unset + HORUS_CLI;
  ASSERT_EQ(horus_test::run_command(cli + " config explain robot1.cam.left --file " + file.path, out), 0) << out;
  EXPECT_NE(out.find("security    enforce          configuration file '" + file.path +
                     "', line 2, security.keystore (a keystore without a mode: enforce)"),
            std::string::npos)
      << out;
  EXPECT_NE(out.find("identity 'robot1' in keystore"), std::string::npos) << out;
  // robot1.* is widened for encryption: it also takes robot1.cam.left, before robot1.**.
  EXPECT_NE(out.find("protection  encrypt          file " + file.path + ", line 9: rule 'robot1.*'"), std::string::npos) << out;
  ASSERT_EQ(horus_test::run_command(cli + " config explain robot1.status --file " + file.path, out), 0) << out;
  EXPECT_NE(out.find("protection  sign             file " + file.path + ", line 5: rule 'robot1.status'"), std::string::npos)
      << out;
  ASSERT_EQ(horus_test::run_command(cli + " config explain other.pose --file " + file.path, out), 0) << out;
  EXPECT_NE(out.find("protection  encrypt          default"), std::string::npos) << out;
  ASSERT_EQ(horus_test::run_command(cli + " config explain radio.ping --file " + file.path, out), 0) << out;
  EXPECT_NE(out.find("protection  none             LCM has no security: the topic is refused under enforce"), std::string::npos)
      << out;
  // The environment over the file.
  ASSERT_EQ(horus_test::run_command(unset + "HORUS_SECURITY=off " + HORUS_CLI + " config explain robot1.cam.left --file " +
                                        file.path,
                                    out),
            0)
      << out;
  EXPECT_NE(out.find("security    off"), std::string::npos) << out;
  EXPECT_EQ(out.find("protection"), std::string::npos) << out;
}

// What only a transport knows is checked too: LCM's URL (whenever the file gives one) and its
// refusal of peers (when a rule or network.backend uses LCM), with the file and the line.
TEST_F(ConfigTest, TheCliChecksTheLcmUrlAndPeersWithTheFileAndLine) {
  if (!horus::backend_available(horus::Backend::Lcm)) GTEST_SKIP() << "this build has no lcm backend";
  std::string out;
  const std::string cli = HORUS_CLI;
  TempFile bogus("network:\n  backend: cyclonedds\n  lcm_url: bogus\n");
  EXPECT_EQ(horus_test::run_command(cli + " config check " + bogus.path, out), 1) << out;
  EXPECT_NE(out.find(bogus.path + "', line 3, network.lcm_url"), std::string::npos) << out;
  EXPECT_NE(out.find("udpm://"), std::string::npos) << out;  // what is expected
  TempFile unicast("network:\n  lcm_url: udpm://10.1.2.3:7667?ttl=1\n");
  EXPECT_EQ(horus_test::run_command(cli + " config check " + unicast.path, out), 1) << out;
  EXPECT_NE(out.find("10.1.2.3 is not a multicast address"), std::string::npos) << out;
  TempFile peers("network:\n  peers: [10.0.0.2]\ntopics:\n  - match: \"fleet.**\"\n    scope: fleet\n    backend: lcm\n");
  EXPECT_EQ(horus_test::run_command(cli + " config check " + peers.path, out), 1) << out;
  EXPECT_NE(out.find(peers.path + "', line 2, network.peers lists peers"), std::string::npos) << out;
  // Peers with DDS, and a good URL, are fine.
  TempFile fine("network:\n  backend: cyclonedds\n  peers: [10.0.0.2]\n  lcm_url: udpm://239.255.76.67:7667?ttl=1\n");
  EXPECT_EQ(horus_test::run_command(cli + " config check " + fine.path, out), 0) << out;
}

}  // namespace

#ifdef HORUS_HAVE_LCM
namespace {

TEST_F(ConfigTest, ABadLcmUrlInTheFileFailsTheLcmTopicNamingTheFileAndKey) {
  ::unsetenv("HORUS_LCM_URL");
  ::unsetenv("LCM_DEFAULT_URL");
  TempFile file("network:\n  lcm_url: \"udpm://239.255.76.67:99999?ttl=0\"\ntopics:\n  - match: \"fleet.**\"\n"
                "    backend: lcm\n");
  ::setenv("HORUS_CONFIG", file.path.c_str(), 1);
  auto t = horus::Topic<horus::msg::CmdVel>::open("fleet.cmd");
  ASSERT_FALSE(t.has_value());
  const auto& m = t.error().message();
  EXPECT_NE(m.find("configuration file '" + file.path + "', line 2, network.lcm_url"), std::string::npos) << m;
  EXPECT_NE(m.find("99999"), std::string::npos) << m;
}

TEST_F(ConfigTest, PeersWithLcmAreAConfigurationErrorSayingLcmNeedsMulticast) {
  ::unsetenv("HORUS_LCM_URL");
  ::unsetenv("LCM_DEFAULT_URL");
  TempFile file("network:\n  peers: [10.0.0.2]\ntopics:\n  - match: \"fleet.**\"\n    backend: lcm\n");
  ::setenv("HORUS_CONFIG", file.path.c_str(), 1);
  auto t = horus::Topic<horus::msg::CmdVel>::open("fleet.cmd");
  ASSERT_FALSE(t.has_value());
  const auto& m = t.error().message();
  EXPECT_EQ(t.error().code(), horus::Errc::Config) << m;
  EXPECT_NE(m.find("configuration file '" + file.path + "', line 2, network.peers"), std::string::npos) << m;
  EXPECT_NE(m.find("needs multicast"), std::string::npos) << m;
}

}  // namespace
#endif
