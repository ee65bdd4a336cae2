// `horus bench`: ping on one namespace host, pong on another (each its own network, /dev/shm
// and hostname, netns.hpp), on every network backend, with a standard message and with large
// data through the pool; ping and pong on one host through shared memory; the errors a user
// meets (an unknown type, a size a type cannot take, no pong, a configuration that keeps the
// topics on the host); `horus bench local` prints the floor and the ratios. The namespace tests
// skip when not root.
#include <gtest/gtest.h>

#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>

#include "horus/backend.hpp"
#include "netns.hpp"

namespace {

using namespace std::chrono_literals;

std::string read_file(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  std::stringstream s;
  s << f.rdbuf();
  return s.str();
}

// A scratch file name unique to this test process.
std::string scratch(const std::string& what) {
  return "/tmp/horus_test_bench_" + std::to_string(::getpid()) + "_" + what;
}

// Runs the CLI on this host (the default namespaces) with extra environment entries.
horus_test::HostProcess run_here(const std::vector<std::string>& env, const std::vector<std::string>& args) {
  static int counter = 0;
  std::vector<std::string> full = {"env"};
  full.insert(full.end(), env.begin(), env.end());
  full.emplace_back(HORUS_CLI);
  full.insert(full.end(), args.begin(), args.end());
  return horus_test::start_logged(std::move(full), scratch("out_" + std::to_string(counter++)));
}

// Waits (at most 20 s) until the pong says it answers: its control topic is open, so the ping's
// first hello reaches it.
bool pong_listening(const horus_test::HostProcess& pong) {
  const auto deadline = std::chrono::steady_clock::now() + 20s;
  while (std::chrono::steady_clock::now() < deadline) {
    if (pong.output().find("answering on") != std::string::npos) return true;
    std::this_thread::sleep_for(10ms);
  }
  return false;
}

bool have_gnuplot() { return std::system("command -v gnuplot > /dev/null 2>&1") == 0; }

std::vector<std::string> shm_env() {
  return {"HORUS_NAMESPACE=tb" + std::to_string(::getpid()), "HORUS_BACKEND=shm", "HORUS_CONFIG="};
}

// The summary a ping wrote: every field there, and the counts add up.
nlohmann::json check_summary(const std::string& json_file, const std::string& output) {
  const std::string text = read_file(json_file);
  EXPECT_FALSE(text.empty()) << "no JSON written\n" << output;
  if (text.empty()) return {};
  const auto j = nlohmann::json::parse(text);
  for (const char* k : {"tool", "type", "payload", "message_bytes", "tag", "topics", "backend", "where", "host",
                        "pong_host", "pong_pid", "mode", "rate_hz", "window", "warmup_s", "duration_s", "sent",
                        "received", "lost", "late", "reordered", "duplicates", "refused", "dropped", "one_way_ns",
                        "throughput", "start_unix_ns", "clock", "by_clock"})
    EXPECT_TRUE(j.contains(k)) << "the JSON lacks " << k << "\n" << text;
  for (const char* k : {"min", "p50", "p90", "p99", "p99_9", "max", "mean", "stddev", "jitter"})
    EXPECT_TRUE(j.at("one_way_ns").contains(k)) << "one_way_ns lacks " << k << "\n" << text;
  EXPECT_TRUE(j.at("throughput").contains("msgs_per_s") && j.at("throughput").contains("mb_per_s")) << text;
  const auto sent = j.at("sent").get<std::uint64_t>(), received = j.at("received").get<std::uint64_t>(),
             lost = j.at("lost").get<std::uint64_t>();
  EXPECT_EQ(sent, received + lost) << text;
  EXPECT_GT(received, 0u) << text;
  const auto& l = j.at("one_way_ns");
  EXPECT_LE(l.at("min").get<std::uint64_t>(), l.at("p50").get<std::uint64_t>()) << text;
  EXPECT_LE(l.at("p50").get<std::uint64_t>(), l.at("p99").get<std::uint64_t>()) << text;
  EXPECT_LE(l.at("p99").get<std::uint64_t>(), l.at("max").get<std::uint64_t>()) << text;
  EXPECT_GT(l.at("min").get<std::uint64_t>(), 0u) << text;
  return j;
}

class BenchBetweenHosts : public ::testing::TestWithParam<horus::Backend> {};

// Pong on host 2, ping on host 1 with --remote: a Pose2D stream at a rate, then large data
// (an Image through the pool and the network); JSON, CSV and the PNG plot. Before the pong
// starts, the ping says no pong answered and what to check. Host 2's clock is 2.5 s ahead (the
// fleet's test hook): one-way by clock corrects it by the offset the fleet's heartbeats measured,
// and with --clocks-synced (no correction) the way there takes the 2.5 s.
TEST_P(BenchBetweenHosts, PingMeasuresRoundTripsToAPongOnAnotherHost) {
  if (!horus::backend_available(GetParam()))
    GTEST_SKIP() << "this build has no " << horus::to_string(GetParam()) << " backend";
  horus_test::NetnsLan lan(2);
  if (!lan.ok()) GTEST_SKIP() << "no namespace hosts: " << lan.why();
  const std::vector<std::string> env = {
      "HORUS_BACKEND=" + std::string(horus::to_string(GetParam())),
      "HORUS_DOMAIN_ID=" + std::to_string(1 + (::getpid() + 91) % 200), "HORUS_DDS_LOCALHOST=0",
      "HORUS_LCM_URL=udpm://239.255.76.68:" + std::to_string(20000 + (::getpid() * 13 + 5) % 20000) +
          "?ttl=1&recv_buf_size=2097152",
      "HORUS_CONFIG="};
  const auto cli = [&](int host, std::vector<std::string> args) {
    args.insert(args.begin(), HORUS_CLI);
    return lan.spawn(host, args, env);
  };
  // No pong yet: the error names the topic, the backend and what to check.
  {
    auto ping = cli(0, {"bench", "ping", "--remote", "--warmup", "1", "--duration", "1"});
    EXPECT_EQ(ping.wait(30s), 3) << ping.output();
    const auto out = ping.output();
    EXPECT_NE(out.find("no pong answered on bench.control"), std::string::npos) << out;
    EXPECT_NE(out.find(std::string(horus::to_string(GetParam()))), std::string::npos) << out;
    EXPECT_NE(out.find("firewall"), std::string::npos) << out;
    EXPECT_NE(out.find(GetParam() == horus::Backend::Lcm ? "multicast route" : "DDS domain"), std::string::npos) << out;
  }
  auto pong_env = env;
  pong_env.emplace_back("HORUS_TEST_CLOCK_OFFSET_MS=2500");
  auto pong = lan.spawn(1, {HORUS_CLI, "bench", "pong"}, pong_env);
  ASSERT_TRUE(pong_listening(pong)) << pong.output();
  const std::string json = scratch("remote.json"), csv = scratch("remote.csv"), png = scratch("remote.png");
  std::remove(csv.c_str());
  std::remove(png.c_str());
  const bool plot = have_gnuplot();
  if (!plot) std::printf("gnuplot is not installed (scripts/install-deps.sh installs it): --plot not tested\n");
  {
    std::vector<std::string> args = {"bench", "ping", "--remote", "--type", "Pose2D", "--rate", "500", "--duration",
                                     "2", "--warmup", "3", "--json", json, "--csv", csv};
    if (plot) args.insert(args.end(), {"--plot", png});
    auto ping = cli(0, args);
    const int rc = ping.wait(60s);
    const auto out = ping.output();
    ASSERT_EQ(rc, 0) << out << "\npong:\n" << pong.output();
    const auto j = check_summary(json, out);
    EXPECT_EQ(j.at("pong_host"), lan.host(1)) << out;
    EXPECT_EQ(j.at("host"), lan.host(0)) << out;
    EXPECT_EQ(j.at("type"), "horus::msg::Pose2D") << out;
    EXPECT_EQ(j.at("backend"), std::string(horus::to_string(GetParam()))) << out;
    EXPECT_NEAR(j.at("sent").get<double>(), 1000.0, 300.0) << out;
    EXPECT_NE(out.find("one-way latency (round trip / 2)"), std::string::npos) << out;
    EXPECT_NE(out.find("p99.9"), std::string::npos) << out;
    EXPECT_NE(out.find(" s] sent "), std::string::npos) << "no progress line\n" << out;
    // Each way by clock, host 2's clock corrected by the fleet's offset (within 50 ms of 2.5 s).
    const auto& clock = j.at("clock");
    ASSERT_EQ(clock.at("source"), "fleet") << out;
    EXPECT_NEAR(clock.at("offset_ns").get<double>(), 2.5e9, 5e7) << out;
    const auto& by_clock = j.at("by_clock");
    EXPECT_GE(by_clock.at("samples").get<std::uint64_t>(), 500u) << out;
    for (const char* way : {"forward_ns", "return_ns"}) {
      const auto p50 = by_clock.at(way).at("p50").get<std::uint64_t>();
      EXPECT_GT(p50, 0u) << way << "\n" << out;
      EXPECT_LT(p50, 50'000'000u) << way << "\n" << out;
    }
    EXPECT_NE(out.find("one-way latency by clock (" + lan.host(1) + "'s clock - ours: +2."), std::string::npos) << out;
    const auto rows = read_file(csv);
    EXPECT_EQ(std::count(rows.begin(), rows.end(), '\n'), 2) << rows;
    EXPECT_EQ(rows.rfind("backend,", 0), 0u) << rows;
    if (plot) {
      const auto image = read_file(png);
      ASSERT_GE(image.size(), 8u) << out;
      EXPECT_EQ(image.substr(0, 8), std::string("\x89PNG\r\n\x1a\n", 8)) << out;
      std::remove(png.c_str());
    }
  }
  // The clocks taken as they are: the way there takes host 2's 2.5 s, the way back less than 0.
  {
    auto ping = cli(0, {"bench", "ping", "--remote", "--rate", "200", "--count", "100", "--warmup", "1",
                        "--clocks-synced", "--json", json, "-q"});
    const int rc = ping.wait(60s);
    const auto out = ping.output();
    ASSERT_EQ(rc, 0) << out << "\npong:\n" << pong.output();
    const auto j = check_summary(json, out);
    EXPECT_EQ(j.at("clock").at("source"), "synced") << out;
    const auto& by_clock = j.at("by_clock");
    EXPECT_GT(by_clock.at("forward_ns").at("p50").get<double>(), 2.4e9) << out;
    EXPECT_EQ(by_clock.at("below_zero"), by_clock.at("samples")) << out;
  }
  // Large data: an Image of 200 000 bytes through the pool and the network.
  {
    auto ping = cli(0, {"bench", "ping", "--remote", "--size", "200000", "--rate", "50", "--count", "25", "--warmup",
                        "3", "--json", json, "-q"});
    const int rc = ping.wait(60s);
    const auto out = ping.output();
    ASSERT_EQ(rc, 0) << out << "\npong:\n" << pong.output();
    const auto j = check_summary(json, out);
    EXPECT_EQ(j.at("type"), "horus::msg::Image") << out;
    EXPECT_EQ(j.at("sent"), 25) << out;
    EXPECT_GE(j.at("message_bytes").get<std::uint64_t>(), 200000u) << out;
  }
  const auto pong_out = pong.output();
  EXPECT_NE(pong_out.find("echoed"), std::string::npos) << pong_out;
  EXPECT_NE(pong_out.find(lan.host(0)), std::string::npos) << "the pong names the ping's host\n" << pong_out;
  std::remove(json.c_str());
  std::remove(csv.c_str());
}

INSTANTIATE_TEST_SUITE_P(Backends, BenchBetweenHosts,
                         ::testing::Values(horus::Backend::CycloneDds, horus::Backend::FastDds, horus::Backend::Lcm),
                         [](const auto& p) { return std::string(horus::to_string(p.param)); });

// One host, shared memory: a flood of a fixed number of messages (nothing lost on one host),
// a serialized sized payload; counts add up.
TEST(BenchOneHost, PingAndPongThroughSharedMemory) {
  const auto env = shm_env();
  auto pong = run_here(env, {"bench", "pong"});
  ASSERT_TRUE(pong_listening(pong)) << pong.output();
  const std::string json = scratch("shm.json");
  {
    auto ping = run_here(env, {"bench", "ping", "--flood", "--count", "20000", "--warmup", "1", "--timeout", "30",
                               "--json", json, "-q"});
    const int rc = ping.wait(60s);
    const auto out = ping.output();
    ASSERT_EQ(rc, 0) << out << "\npong:\n" << pong.output();
    const auto j = check_summary(json, out);
    EXPECT_EQ(j.at("sent"), 20000) << out;
    EXPECT_EQ(j.at("lost"), 0) << out;
    EXPECT_EQ(j.at("mode"), "flood") << out;
    EXPECT_EQ(j.at("backend"), "shm") << out;
  }
  {
    // A window smaller than the rings: nothing can be overwritten, so nothing may be lost.
    auto ping = run_here(env, {"bench", "ping", "--size", "4096", "--flood", "--window", "4", "--count", "2000",
                               "--warmup", "1", "--timeout", "30", "--json", json, "-q"});
    const int rc = ping.wait(60s);
    const auto out = ping.output();
    ASSERT_EQ(rc, 0) << out;
    const auto j = check_summary(json, out);
    EXPECT_EQ(j.at("type"), "horus::msg::CompressedImage") << out;
    EXPECT_GE(j.at("message_bytes").get<std::uint64_t>(), 4096u) << out;
    EXPECT_EQ(j.at("lost"), 0) << out;
  }
  std::remove(json.c_str());
}

// What a user gets wrong, each named with what was expected.
TEST(BenchOneHost, BadArgumentsAndAMissingPongAreNamed) {
  const auto env = shm_env();
  struct Case {
    std::vector<std::string> args;
    int rc;
    std::string says;
  };
  const std::string config = scratch("host_only.yaml");
  {
    std::ofstream f(config);
    f << "topics:\n  - match: \"bench.**\"\n    scope: host\n";
  }
  const std::vector<Case> cases = {
      {{"bench", "ping", "--type", "Pose9D"}, 2, "unknown message type 'Pose9D'"},
      {{"bench", "ping", "--type", "Pose2D", "--size", "100"}, 2, "has no payload to size"},
      {{"bench", "ping", "--type", "Image", "--size", "2000000000"}, 2, "beyond the largest slot"},
      {{"bench", "ping", "--rate", "0"}, 2, "--rate 0 must be above 0"},
      {{"bench", "ping", "--topic-prefix", "bad..name"}, 2, "--topic-prefix 'bad..name'"},
      {{"bench", "ping", "--backend", "carrier-pigeon"}, 2, "'carrier-pigeon' is not a backend of this build"},
      {{"bench", "ping", "--warmup", "0.5", "--topic-prefix", "nobody"}, 3, "Start `horus bench pong` here"},
  };
  for (const auto& c : cases) {
    auto p = run_here(env, c.args);
    EXPECT_EQ(p.wait(30s), c.rc) << p.output();
    EXPECT_NE(p.output().find(c.says), std::string::npos) << "expected '" << c.says << "' in\n" << p.output();
  }
  // A configuration that keeps the bench topics on this host, with a remote pong expected:
  // refused at once, naming the file, the line and the rule.
  auto env_file = env;
  env_file[1] = "HORUS_BACKEND=";
  env_file[2] = "HORUS_CONFIG=" + config;
  auto p = run_here(env_file, {"bench", "ping", "--remote"});
  EXPECT_EQ(p.wait(30s), 2) << p.output();
  const auto out = p.output();
  EXPECT_NE(out.find("--remote: the configuration keeps bench.ping.Pose2D on this host"), std::string::npos) << out;
  EXPECT_NE(out.find(config + ", line 2: rule 'bench.**'"), std::string::npos) << out;
  std::remove(config.c_str());
}

// horus bench local: the floor (when two CPUs are allowed) and each path's ratio to it.
TEST(BenchOneHost, LocalPrintsTheFloorAndEachPathsRatio) {
  const std::string json = scratch("local.json");
  auto p = run_here(shm_env(), {"bench", "local", "--type", "CmdVel", "--duration", "0.3", "--json", json});
  const int rc = p.wait(120s);
  const auto out = p.output();
  ASSERT_EQ(rc, 0) << out;
  const auto j = nlohmann::json::parse(read_file(json));
  std::remove(json.c_str());
  const bool two_cpus = j.at("cpus").size() == 2;
  EXPECT_NE(out.find(two_cpus ? "true floor (cache-line ping-pong with pause" : "true floor: not measured"),
            std::string::npos) << out;
  int rows = 0;
  for (const auto& r : j.at("rows")) {
    ++rows;
    EXPECT_EQ(r.at("sent").get<std::uint64_t>(), r.at("received").get<std::uint64_t>() + r.at("lost").get<std::uint64_t>()) << out;
    EXPECT_GT(r.at("received").get<std::uint64_t>(), 0u) << out;
    EXPECT_GT(r.at("msgs_per_s").get<double>(), 0.0) << out;
    const std::string path = r.at("path");
    if (two_cpus && path.find("flood") == std::string::npos) {
      EXPECT_GT(r.at("vs_floor").get<double>(), 0.0) << out;
      EXPECT_NE(out.find(path), std::string::npos) << out;
    }
  }
  EXPECT_EQ(rows, two_cpus ? 6 : 4) << out;
  if (two_cpus) {
    EXPECT_GT(j.at("floor_ns").at("best").get<std::uint64_t>(), 0u) << out;
    EXPECT_NE(out.find("x\n"), std::string::npos) << "a ratio column\n" << out;
  }
}

}  // namespace
