// The fleet layer across namespace hosts (netns.hpp: each host its own network, /dev/shm and
// hostname), on each backend: three hosts see each other within a second of starting; a host
// whose link goes down is lost on the others after 3 missed heartbeats (+ one period), and
// rejoins when the link comes back; a reliable fleet topic loses nothing that was sent while
// the link was up. Skips when not root or without `ip netns`.
#include <gtest/gtest.h>

#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <set>
#include <utility>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>

#include "horus/topic.hpp"
#include "netns.hpp"

namespace {

using namespace std::chrono_literals;

class Fleet : public ::testing::TestWithParam<horus::Backend> {};

std::vector<std::string> fleet_env(horus::Backend b) {
  return {"HORUS_BACKEND=" + std::string(horus::to_string(b)),
          "HORUS_DOMAIN_ID=" + std::to_string(1 + (::getpid() + 77) % 200), "HORUS_DDS_LOCALHOST=0",
          "HORUS_LCM_URL=udpm://239.255.76.68:" + std::to_string(20000 + (::getpid() * 11 + 3) % 20000) +
              "?ttl=1&recv_buf_size=2097152",
          "HORUS_FLEET_HEARTBEAT_MS=100"};
}

// The JSON object in a CLI's output (stderr is merged in: a log line or a hint may come before
// or after it).
nlohmann::json json_of(const std::string& out) {
  const auto first = out.find('{');
  const auto last = out.rfind('}');
  if (first == std::string::npos || last == std::string::npos || last < first) return nlohmann::json::object();
  return nlohmann::json::parse(out.substr(first, last - first + 1));
}

std::int64_t unix_ms() {
  return std::chrono::duration_cast<std::chrono::milliseconds>(std::chrono::system_clock::now().time_since_epoch())
      .count();
}

// The watcher's lines: "start T", "event KIND HOST T", ...
struct Watch {
  std::int64_t start = -1;
  std::multimap<std::string, std::pair<std::string, std::int64_t>> events;  // host -> (kind, time)
  std::string received;
  std::map<std::string, std::string> hosts;  // name -> the rest of its "host" line
  explicit Watch(const std::string& out) {
    std::istringstream in(out);
    std::string l;
    while (std::getline(in, l)) {
      std::istringstream w(l);
      std::string word;
      w >> word;
      if (word == "start") {
        w >> start;
      } else if (word == "event") {
        std::string kind, host;
        std::int64_t t = 0;
        w >> kind >> host >> t;
        events.emplace(host, std::make_pair(kind, t));
      } else if (word == "received") {
        received = l;
      } else if (word == "host") {
        std::string name;
        w >> name;
        std::string rest;
        std::getline(w, rest);
        hosts[name] = rest;
      }
    }
  }
  // The first event of a kind for host, at or after `after`; -1 when none.
  std::int64_t first(const std::string& host, const std::string& kind, std::int64_t after = 0) const {
    std::int64_t best = -1;
    auto [b, e] = events.equal_range(host);
    for (auto it = b; it != e; ++it)
      if (it->second.first == kind && it->second.second >= after && (best < 0 || it->second.second < best))
        best = it->second.second;
    return best;
  }
};

TEST_P(Fleet, HostsSeeEachOtherALostLinkIsDetectedAndRejoinsWithoutLosingReliableMessages) {
  if (!horus::backend_available(GetParam()))
    GTEST_SKIP() << "this build has no " << horus::to_string(GetParam()) << " backend";
  horus_test::NetnsLan lan(3);
  if (!lan.ok()) GTEST_SKIP() << "no namespace hosts: " << lan.why();
  const auto env = fleet_env(GetParam());
  const std::string topic = "fleet.counter_" + std::to_string(::getpid());
  const std::int64_t pub_start = unix_ms() + 2000;
  auto w1 = lan.spawn(0, {FLEET_WATCH, "14", "--publish", topic, std::to_string(pub_start), "100"}, env);
  auto w2 = lan.spawn(1, {FLEET_WATCH, "14"}, env);
  auto w3 = lan.spawn(2, {FLEET_WATCH, "14", "--subscribe", topic}, env);
  // Host 3's link goes down at +5 s for 2 s.
  std::this_thread::sleep_for(std::chrono::milliseconds(pub_start + 3000 - unix_ms()));
  const std::int64_t down = unix_ms();
  ASSERT_EQ(horus_test::run_command({"ip", "-n", lan.host(2), "link", "set", "eth0", "down"}), 0);
  std::this_thread::sleep_for(2s);
  const std::int64_t up = unix_ms();
  ASSERT_EQ(horus_test::run_command({"ip", "-n", lan.host(2), "link", "set", "eth0", "up"}), 0);
  // The kernel dropped the multicast route with the link; a host's network setup puts it back.
  ASSERT_EQ(horus_test::run_command({"ip", "-n", lan.host(2), "route", "replace", "224.0.0.0/4", "dev", "eth0"}), 0);
  for (auto* w : {&w1, &w2, &w3}) (void)w->wait(30s);
  const Watch v1(w1.output()), v2(w2.output()), v3(w3.output());
  const std::string all = "host 1:\n" + w1.output() + "\nhost 2:\n" + w2.output() + "\nhost 3:\n" + w3.output();
  const Watch* views[] = {&v1, &v2, &v3};

  // Each sees the other two (and itself) within a second of both having started.
  for (int i = 0; i < 3; ++i) {
    ASSERT_GE(views[i]->start, 0) << all;
    for (int j = 0; j < 3; ++j) {
      const std::int64_t joined = views[i]->first(lan.host(j), "joined");
      ASSERT_GE(joined, 0) << "host " << i + 1 << " never saw " << lan.host(j) << "\n" << all;
      EXPECT_LE(joined - std::max(views[i]->start, views[j]->start), 1000)
          << "host " << i + 1 << " saw " << lan.host(j) << " late\n" << all;
    }
  }
  // Hosts 1 and 2 lose host 3: after 3 periods (300 ms) + one of tolerance, not before.
  for (const Watch* v : {&v1, &v2}) {
    const std::int64_t lost = v->first(lan.host(2), "lost", down - 50);
    ASSERT_GE(lost, 0) << "host 3 was never lost\n" << all;
    EXPECT_GE(lost - down, 250) << all;
    EXPECT_LE(lost - down, 400 + 150) << "lost " << lost - down << " ms after the link went down\n" << all;
    const std::int64_t rejoined = v->first(lan.host(2), "rejoined", up);
    ASSERT_GE(rejoined, 0) << "host 3 never rejoined\n" << all;
    EXPECT_LE(rejoined - up, 5000) << all;
    EXPECT_NE(v->hosts.at(lan.host(2)).find("rejoined rejoins 1"), std::string::npos) << all;
  }
  // Host 3 loses the other two as well, and gets them back.
  EXPECT_GE(v3.first(lan.host(0), "lost", down - 50), 0) << all;
  EXPECT_GE(v3.first(lan.host(0), "rejoined", up), 0) << all;
  // The counter: everything sent while the link was up arrived (50 ms of margin around the cut).
  ASSERT_FALSE(v3.received.empty()) << all;
  std::istringstream rec(v3.received.substr(v3.received.find(':') + 1));
  const double period_ms = 10.0;
  long long s = 0;
  while (rec >> s) {
    const double sent_at = static_cast<double>(pub_start) + static_cast<double>(s) * period_ms;
    EXPECT_TRUE(sent_at > static_cast<double>(down) - 50 && sent_at < static_cast<double>(up) + 100)
        << "message " << s << ", sent while the link was up, is missing\n" << v3.received;
  }
  EXPECT_NE(v3.received.find("first 0 "), std::string::npos) << v3.received;
  // Heartbeats carried RTTs, and nothing malformed came.
  EXPECT_NE(w1.output().find("malformed 0"), std::string::npos) << all;
  EXPECT_EQ(v1.hosts.at(lan.host(1)).find("rtt_us -"), std::string::npos) << all;
}

// Runs the horus CLI on host i; its output (stdout and stderr) and exit status.
std::pair<int, std::string> cli(const horus_test::NetnsLan& lan, int i, const std::vector<std::string>& env,
                                std::vector<std::string> args) {
  args.insert(args.begin(), HORUS_CLI);
  auto p = lan.spawn(i, args, env);
  const int rc = p.wait(30s);
  return {rc, p.output()};
}

// The CLI on one host sees what another host publishes, on every backend: horus fleet, topic
// list/info/echo/hz/bw of a topic that exists only there (a standard type, and a type the CLI
// was not compiled with), pub to a subscriber there; a host on another DDS domain or LCM URL is
// not seen; raw bytes and forged announcements are counted and ignored.
TEST_P(Fleet, TheCliSeesAndReachesTopicsOfAnotherHost) {
  if (!horus::backend_available(GetParam()))
    GTEST_SKIP() << "this build has no " << horus::to_string(GetParam()) << " backend";
  horus_test::NetnsLan lan(3);
  if (!lan.ok()) GTEST_SKIP() << "no namespace hosts: " << lan.why();
  const auto env = fleet_env(GetParam());
  const std::string count_topic = "fleet.count_" + std::to_string(::getpid());
  const std::string battery_topic = "fleet.battery_" + std::to_string(::getpid());
  const std::string cmd_topic = "fleet.cmd_" + std::to_string(::getpid());
  auto robot = lan.spawn(0, {FLEET_WATCH, "28", "--publish", count_topic, std::to_string(unix_ms()), "50",
                             "--user-type", battery_topic, "--subscribe", cmd_topic},
                         env);
  auto watcher = lan.spawn(1, {FLEET_WATCH, "28"}, env);
  // Host 3 is on another network: another DDS domain, another LCM port.
  auto other_env = env;
  other_env[1] = "HORUS_DOMAIN_ID=" + std::to_string(1 + (::getpid() + 78) % 200);
  other_env[3] = "HORUS_LCM_URL=udpm://239.255.76.68:" + std::to_string(20000 + (::getpid() * 11 + 4) % 20000) + "?ttl=1";
  auto stranger = lan.spawn(2, {FLEET_WATCH, "28", "--user-type", "fleet.strange"}, other_env);
  std::this_thread::sleep_for(2s);
  const std::string robot_host = lan.host(0);
  // Meanwhile, garbage on the announcement topic from host 1: counted and ignored on host 2.
  // On DDS it starts once both hosts' bridges (the robot's, the watcher's) read the
  // announcements: a reader that matched late missed some (a CI run counted 10 of 20). LCM has
  // no discovery to wait for: 3 s.
  const char* readers = GetParam() == horus::Backend::Lcm ? "1" : "2";
  auto garbage = lan.spawn(0, {FLEET_WATCH, "1", "--garbage", "10", "--garbage-readers", readers}, env);

  // horus fleet --json --once: the robot's host with its topics, this host, not the stranger.
  {
    auto [rc, out] = cli(lan, 1, env, {"fleet", "--json", "--once", "--wait", "1500"});
    ASSERT_EQ(rc, 0) << out;
    const auto j = json_of(out);
    std::map<std::string, nlohmann::json> hosts;
    for (const auto& h : j.at("hosts")) hosts[h.at("host").get<std::string>()] = h;
    ASSERT_TRUE(hosts.contains(robot_host)) << out;
    ASSERT_TRUE(hosts.contains(lan.host(1))) << out;
    EXPECT_FALSE(hosts.contains(lan.host(2))) << "a host on another network was shown:\n" << out;
    const auto& r = hosts[robot_host];
    EXPECT_EQ(r.at("state"), "alive") << out;
    EXPECT_LT(r.at("age_ms").get<int>(), 400) << out;
    EXPECT_FALSE(r.at("rtt_us").is_null()) << out;
    EXPECT_TRUE(hosts[lan.host(1)].at("self").get<bool>()) << out;
    std::set<std::string> topics;
    for (const auto& t : r.at("topics")) topics.insert(t.at("topic").get<std::string>());
    EXPECT_TRUE(topics.contains(count_topic) && topics.contains(battery_topic)) << out;
  }
  // topic list: the robot's topics, with the host that has them.
  {
    auto [rc, out] = cli(lan, 1, env, {"topic", "list", "--json"});
    ASSERT_EQ(rc, 0) << out;
    const auto j = nlohmann::json::parse(out.substr(out.find('[')));
    bool found = false;
    for (const auto& t : j)
      if (t.at("topic") == count_topic) {
        found = true;
        EXPECT_EQ(t.at("type"), "horus::msg::Pose2D") << out;
        EXPECT_EQ(t.at("hosts"), nlohmann::json::array({robot_host})) << out;
        EXPECT_NEAR(t.value("rate_hz", 0.0), 50.0, 15.0) << out;
      }
    EXPECT_TRUE(found) << out;
  }
  // topic info, echo of a type the CLI lacks, hz, bw.
  {
    auto [rc, out] = cli(lan, 1, env, {"topic", "info", battery_topic});
    ASSERT_EQ(rc, 0) << out;
    EXPECT_NE(out.find("watch::Battery"), std::string::npos) << out;
    EXPECT_NE(out.find(robot_host), std::string::npos) << out;
  }
  {
    auto [rc, out] = cli(lan, 1, env, {"topic", "echo", battery_topic, "-n", "2", "--json", "--timeout", "10"});
    ASSERT_EQ(rc, 0) << out;
    std::istringstream in(out);
    std::string l;
    int lines = 0;
    while (std::getline(in, l)) {
      if (l.empty() || l[0] != '{') continue;
      const auto b = nlohmann::json::parse(l);
      EXPECT_EQ(b.at("chemistry"), "LiFePo4") << l;
      EXPECT_EQ(b.at("tag"), "rack7") << l;
      EXPECT_EQ(b.at("history"), nlohmann::json::array({100, 99, 65535})) << l;
      EXPECT_EQ(b.at("cells").at(1).at("temp_dc"), -12) << l;
      EXPECT_DOUBLE_EQ(b.at("cells").at(0).at("volts").get<double>(), 3.25) << l;
      EXPECT_EQ(b.at("label").get<std::string>().rfind("pack-", 0), 0U) << l;
      ++lines;
    }
    EXPECT_EQ(lines, 2) << out;
  }
  // hz, bw and record run at once (each for a few seconds: the suite's time).
  const std::string file = "/tmp/horus-fleet-rec-" + std::to_string(::getpid()) + ".mcap";
  auto hz = lan.spawn(1, {HORUS_CLI, "topic", "hz", count_topic, "--duration", "4.5"}, env);  // the last window counts
  auto bw = lan.spawn(1, {HORUS_CLI, "topic", "bw", count_topic, "--duration", "3.5"}, env);
  auto rec = lan.spawn(1, {HORUS_CLI, "record", "-o", file, "--topics", "fleet.**", "--duration", "4"}, env);
  {
    const int rc = hz.wait(30s);
    const std::string out = hz.output();
    ASSERT_EQ(rc, 0) << out;
    const auto at = out.rfind("average rate: ");
    ASSERT_NE(at, std::string::npos) << out;
    EXPECT_NEAR(std::atof(out.c_str() + at + 14), 50.0, 10.0) << out;
  }
  {
    const int rc = bw.wait(30s);
    const std::string out = bw.output();
    ASSERT_EQ(rc, 0) << out;
    // Pose2D is 4 doubles: 32 bytes of XCDR1, 40 with LCM's fingerprint. The recorder started
    // beside it opens the topic on this host too: when bw finds it in this host's shared memory
    // first, it reads the 32-byte message there (seen once in a loaded run), not the datagram.
    const bool wire_size = out.find("mean: 32 B") != std::string::npos ||
                           (GetParam() == horus::Backend::Lcm && out.find("mean: 40 B") != std::string::npos);
    EXPECT_TRUE(wire_size) << out;
    EXPECT_NE(out.find("B/s from"), std::string::npos) << out;
  }
  // horus record on host 2 records the topic that only host 1 has (found through the fleet
  // layer); the file reads back with its messages, and a type it lacks is named, not recorded.
  {
    const int rc = rec.wait(30s);
    const std::string out = rec.output();
    ASSERT_EQ(rc, 0) << out;
    EXPECT_NE(out.find("+ " + count_topic + " (horus::msg::Pose2D, fleet)"), std::string::npos) << out;
    EXPECT_NE(out.find("not recording '" + battery_topic + "'"), std::string::npos) << out;
    auto [irc, info] = cli(lan, 1, env, {"record", "info", "--json", file});
    ASSERT_EQ(irc, 0) << info;
    const auto j = nlohmann::json::parse(info.substr(info.find('{')));
    bool found = false;
    for (const auto& t : j.at("topics"))
      if (t.at("topic") == count_topic) {
        found = true;
        EXPECT_EQ(t.at("scope"), "fleet") << info;
        EXPECT_GE(t.at("messages").get<int>(), 60) << "50 Hz for 4 s, less discovery\n" << out << info;
        EXPECT_NEAR(t.at("rate_hz").get<double>(), 50.0, 10.0) << info;
      }
    EXPECT_TRUE(found) << out << info;
    std::remove(file.c_str());
  }
  // pub: to the robot's subscriber; a bad field names it; an unknown topic names those that exist.
  {
    auto [rc, out] = cli(lan, 1, env, {"topic", "pub", cmd_topic, "Pose2D", R"({"x": 7, "theta": 0.5})", "--count", "3", "--rate", "10"});
    EXPECT_EQ(rc, 0) << out;
    EXPECT_NE(out.find("published 3 messages"), std::string::npos) << out;
    auto [rc2, out2] = cli(lan, 1, env, {"topic", "pub", cmd_topic, "Pose2D", R"({"z": 7})"});
    EXPECT_EQ(rc2, 2) << out2;
    EXPECT_NE(out2.find("'z'"), std::string::npos) << out2;
    auto [rc3, out3] = cli(lan, 1, env, {"topic", "echo", "fleet.nowhere", "-n", "1", "--wait", "1000"});
    EXPECT_EQ(rc3, 1) << out3;
    EXPECT_NE(out3.find(count_topic), std::string::npos) << out3;
  }
  EXPECT_EQ(garbage.wait(30s), 0) << garbage.output();
  if (const auto g = garbage.output().find("garbage readers"); g != std::string::npos)
    std::printf("%s\n", garbage.output().substr(g, garbage.output().find('\n', g) - g).c_str());
  // Done: the watchers print what they saw and end (SIGTERM ends their 28 s early).
  for (auto* p : {&robot, &watcher, &stranger}) p->terminate();
  for (auto* p : {&robot, &watcher, &stranger}) EXPECT_EQ(p->wait(20s), 0) << p->output();
  const std::string robot_out = robot.output(), watcher_out = watcher.output();
  EXPECT_NE(robot_out.find("received 1 first 7 last 7"), std::string::npos) << robot_out;
  const auto at = watcher_out.rfind("malformed ");
  ASSERT_NE(at, std::string::npos) << watcher_out;
  EXPECT_GE(std::atoll(watcher_out.c_str() + at + 10), 20) << watcher_out;
  EXPECT_EQ(watcher_out.find("forged"), std::string::npos) << watcher_out;
  EXPECT_NE(watcher_out.find("host " + robot_host + " alive"), std::string::npos) << watcher_out;
  EXPECT_EQ(watcher_out.find(lan.host(2)), std::string::npos) << watcher_out;
}

// Link quality and a fleet view that remembers: host 2's clock is 2.5 s ahead (the test hook
// HORUS_TEST_CLOCK_OFFSET_MS shifts its heartbeats' realtime stamps) and it drops half of the
// datagrams it sends (nftables numgen); host 1's `horus fleet --json --once` shows the offset
// (within its uncertainty), the heartbeats' loss and the round trip. (With Cyclone DDS fewer
// heartbeats are lost than datagrams, 12-14%: a heartbeat seems to travel more than once.) Then host 2's link goes down: a `horus fleet
// --once` started afterwards on host 1 lists it lost at once, with since when, from the view
// host 1's agent kept (it never heard host 2 itself).
TEST_P(Fleet, LinkQualityAndClockOffsetAreMeasuredAndTheViewRemembersLostHosts) {
  if (!horus::backend_available(GetParam()))
    GTEST_SKIP() << "this build has no " << horus::to_string(GetParam()) << " backend";
  if (horus_test::run_command({"nft", "--version"}) != 0) GTEST_SKIP() << "needs nftables (nft)";
  horus_test::NetnsLan lan(2);
  if (!lan.ok()) GTEST_SKIP() << "no namespace hosts: " << lan.why();
  const auto env = fleet_env(GetParam());
  auto shifted = env;
  shifted.push_back("HORUS_TEST_CLOCK_OFFSET_MS=2500");
  const std::string h2 = lan.host(1);
  for (const char* rule : {"add table inet loss", "add chain inet loss out { type filter hook output priority 0 ; }",
                           "add rule inet loss out meta l4proto udp numgen random mod 100 < 50 drop"})
    ASSERT_EQ(horus_test::run_command({"ip", "netns", "exec", h2, "nft", rule}), 0) << rule;
  const std::string topic = "fleet.view_" + std::to_string(::getpid());
  // A process on each host keeps a fleet topic open (its agent speaks for the host).
  // (Until the test ends them.)
  auto a = lan.spawn(0, {FLEET_MEMBER, topic, "fleet", "0", "1", std::to_string(unix_ms()), "-1", "60"}, env);
  auto b = lan.spawn(1, {FLEET_MEMBER, topic, "fleet", "0", "1", std::to_string(unix_ms()), "-1", "60"}, shifted);
  // Discovery through a link that drops half the datagrams takes a while on a loaded machine: ask
  // until host 2's figures are known and its loss shows (over 10 heartbeats and more), at most 36 s.
  // The first figure may come from 10 heartbeats only, and on a loaded machine a stalled receiver
  // adds to the link's losses for a moment (once 0.85 in CI): a figure outside the range is
  // printed and asked again; the last one within the 36 s is judged.
  const double min_loss = GetParam() == horus::Backend::CycloneDds ? 0.01 : 0.05, max_loss = 0.75;
  {
    std::string out;
    nlohmann::json host2;
    const auto deadline = std::chrono::steady_clock::now() + 36s;
    auto settled = [&] {
      if (host2.is_null() || host2.at("loss").is_null() || host2.at("clock_offset_us").is_null()) return false;
      const double loss = host2.at("loss").get<double>();
      if (loss >= min_loss && loss <= max_loss) return true;
      std::printf("host 2's loss reads %.2f (after %lld heartbeats): asking again\n", loss,
                  static_cast<long long>(host2.value("heartbeats", 0LL)));
      return false;
    };
    do {
      auto [rc, text] = cli(lan, 0, env, {"fleet", "--json", "--once", "--wait", "1500"});
      ASSERT_EQ(rc, 0) << text;
      out = text;
      host2 = nullptr;
      const auto j = json_of(out);
      for (const auto& h : j.at("hosts"))
        if (h.at("host") == h2) host2 = h;
    } while (!settled() && std::chrono::steady_clock::now() < deadline);
    ASSERT_FALSE(host2.is_null()) << out;
    ASSERT_FALSE(host2.at("clock_offset_us").is_null()) << out;
    const auto offset = host2.at("clock_offset_us").get<std::int64_t>();
    const auto uncertainty = host2.at("clock_uncertainty_us").get<std::int64_t>();
    EXPECT_LE(std::abs(offset - 2'500'000), uncertainty + 20'000) << out;
    EXPECT_LT(uncertainty, 100'000) << out;
    ASSERT_FALSE(host2.at("loss").is_null()) << out;
    // (Cyclone DDS loses fewer heartbeats than datagrams, 8-14% here: any loss must show.)
    EXPECT_GE(host2.at("loss").get<double>(), min_loss) << out;
    EXPECT_LE(host2.at("loss").get<double>(), max_loss) << out;
    std::printf("%s: host 2's clock offset %lld us (+- %lld us), loss %.2f, rtt %lld us\n",
                std::string(horus::to_string(GetParam())).c_str(), static_cast<long long>(offset),
                static_cast<long long>(uncertainty), host2.at("loss").get<double>(),
                static_cast<long long>(host2.at("rtt_us").get<std::int64_t>()));
    EXPECT_FALSE(host2.at("rtt_us").is_null()) << out;
  }
  // The loss ends (with half the heartbeats lost, host 2 is now and then lost for a moment: 3 in
  // a row); then host 2's link goes down, and a CLI started 1.5 s later shows it lost, without a
  // discovery round.
  ASSERT_EQ(horus_test::run_command({"ip", "netns", "exec", h2, "nft", "delete table inet loss"}), 0);
  std::this_thread::sleep_for(1s);
  const std::int64_t down = unix_ms();
  ASSERT_EQ(horus_test::run_command({"ip", "-n", h2, "link", "set", "eth0", "down"}), 0);
  std::this_thread::sleep_for(1500ms);
  const auto started = std::chrono::steady_clock::now();
  auto [rc, out] = cli(lan, 0, env, {"fleet", "--json", "--once", "--wait", "3000"});
  const auto took = std::chrono::steady_clock::now() - started;
  ASSERT_EQ(rc, 0) << out;
  const auto j = json_of(out);
  nlohmann::json host2;
  for (const auto& h : j.at("hosts"))
    if (h.at("host") == h2) host2 = h;
  ASSERT_FALSE(host2.is_null()) << "the lost host is not in the view:\n" << out;
  EXPECT_EQ(host2.at("state"), "lost") << out;
  ASSERT_FALSE(host2.at("lost_since_unix_ms").is_null()) << out;
  EXPECT_GE(host2.at("lost_since_unix_ms").get<std::int64_t>(), down) << out;
  EXPECT_LE(host2.at("lost_since_unix_ms").get<std::int64_t>(), down + 1000) << out;
  EXPECT_LE(host2.at("last_seen_unix_ms").get<std::int64_t>(), down + 50) << out;
  EXPECT_LT(took, 2500ms) << "the CLI waited for a discovery round instead of reading the view";
}  // a and b end (SIGTERM)

INSTANTIATE_TEST_SUITE_P(Backends, Fleet, ::testing::Values(horus::Backend::CycloneDds, horus::Backend::FastDds,
                                                                horus::Backend::Lcm),
                         [](const auto& param_info) { return std::string(horus::to_string(param_info.param)); });

}  // namespace

// A flood of 100 000 heartbeats, each from another forged host id (20 000 a second, from a
// process of the same namespace host), against a watcher whose file says fleet.max_hosts 64 and
// fleet.forget_after 1 s: its Fleet never holds more than 64 hosts, what did not fit is counted
// in malformed(), its RSS does not grow with the flood, and the forged hosts, lost after their
// one heartbeat, are forgotten 1 s later.
TEST(FleetLimits, AFloodOfForgedHostIdsKeepsTheTablesBounded) {
  const horus::Backend b = horus::backend_available(horus::Backend::Lcm) ? horus::Backend::Lcm : horus::Backend::CycloneDds;
  if (!horus::backend_available(b)) GTEST_SKIP() << "this build has no network backend";
  horus_test::NetnsLan lan(1);
  if (!lan.ok()) GTEST_SKIP() << "no namespace hosts: " << lan.why();
  const std::string config = "/tmp/horus_test_fleet_limits_" + std::to_string(::getpid()) + ".yaml";
  {
    std::ofstream f(config);
    f << "fleet:\n  max_hosts: 64\n  forget_after: 1s\n";
  }
  auto env = fleet_env(b);
  env.push_back("HORUS_CONFIG=" + config);
  auto watcher = lan.spawn(0, {FLEET_WATCH, "11", "--memory"}, env);
  ASSERT_TRUE(watcher.wait_for_output("memory ", 20s)) << watcher.output();
  auto forger = lan.spawn(0, {FLEET_WATCH, "1", "--forge-heartbeats", "100000"}, env);
  EXPECT_EQ(forger.wait(60s), 0) << forger.output();
  EXPECT_NE(forger.output().find("forged sent 100000"), std::string::npos) << forger.output();
  ASSERT_EQ(watcher.wait(60s), 0) << watcher.output();
  std::remove(config.c_str());
  const std::string out = watcher.output();
  // memory <ms> rss_kb <n> hosts <n> malformed <n>
  std::istringstream lines(out);
  std::string l;
  long rss_flood_start = -1, rss_max = 0;
  std::size_t hosts_max = 0;
  std::uint64_t malformed = 0;
  while (std::getline(lines, l)) {
    long ms = 0, rss = 0;
    std::size_t hosts = 0;
    unsigned long long bad = 0;
    if (std::sscanf(l.c_str(), "memory %ld rss_kb %ld hosts %zu malformed %llu", &ms, &rss, &hosts, &bad) != 4) continue;
    hosts_max = std::max(hosts_max, hosts);
    malformed = bad;
    if (bad >= 2000 && rss_flood_start < 0) rss_flood_start = rss;
    if (rss_flood_start >= 0) rss_max = std::max(rss_max, rss);
  }
  std::printf("forged flood: at most %zu hosts held, %llu refused (malformed), RSS %ld kB at the flood's start, at most "
              "%ld kB after\n",
              hosts_max, static_cast<unsigned long long>(malformed), rss_flood_start, rss_max);
  EXPECT_LE(hosts_max, 64u) << out;
  EXPECT_GE(malformed, 10000u) << "the flood hardly reached the watcher\n" << out;
  ASSERT_GE(rss_flood_start, 0) << out;
  EXPECT_LT(rss_max - rss_flood_start, 8 * 1024) << "RSS grew with the flood (kB)\n" << out;
  // The forged hosts were lost, then forgotten: the last list has this host alone.
  const auto last_list = out.find("\nhost ");
  ASSERT_NE(last_list, std::string::npos) << out;
  EXPECT_EQ(out.find("host forged-", last_list), std::string::npos) << out;
}
