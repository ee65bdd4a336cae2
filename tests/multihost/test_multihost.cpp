// The fleet on three hosts (network namespaces on a bridge): robots on two hosts publish
// Heartbeat, Pose2D and TransformStamped over DDS or LCM (udpm, ttl=1); the monitor on the third
// receives all of them. Skips when not root or without `ip netns`.
#include <gtest/gtest.h>

#include <string>

#include "horus/topic.hpp"
#include "netns.hpp"

namespace {

using namespace std::chrono_literals;

class MultiHost : public ::testing::TestWithParam<horus::Backend> {};

// The settings every host gets: the backend, a DDS domain or an LCM port of this test process.
std::vector<std::string> fleet_env(horus::Backend b) {
  return {"HORUS_BACKEND=" + std::string(horus::to_string(b)),
          "HORUS_DOMAIN_ID=" + std::to_string(1 + ::getpid() % 200), "HORUS_DDS_LOCALHOST=0",
          // ttl=1: the LAN (the bridge), not beyond a router; the hosts have a multicast route.
          "HORUS_LCM_URL=udpm://239.255.76.67:" + std::to_string(20000 + (::getpid() * 7 + 5) % 20000) +
              "?ttl=1&recv_buf_size=2097152"};
}

TEST_P(MultiHost, AMonitorOnAThirdHostReceivesTwoRobots) {
  if (!horus::backend_available(GetParam()))
    GTEST_SKIP() << "this build has no " << horus::to_string(GetParam()) << " backend";
  horus_test::NetnsLan lan(3);
  if (!lan.ok()) GTEST_SKIP() << "no namespace hosts: " << lan.why();
  const std::vector<std::string> env = fleet_env(GetParam());
  auto robot1 = lan.spawn(0, {FLEET_DEMO, "--role", "robot", "--id", "1", "--duration", "30"}, env);
  auto robot2 = lan.spawn(1, {FLEET_DEMO, "--role", "robot", "--id", "2", "--duration", "30"}, env);
  auto monitor = lan.spawn(2, {FLEET_DEMO, "--role", "monitor", "--robots", "2", "--duration", "8"}, env);
  const int rc = monitor.wait(60s);
  const std::string out = monitor.output();
  EXPECT_EQ(rc, 0) << "the monitor on " << lan.host(2) << " said:\n" << out << "\nrobot 1:\n" << robot1.output();
  EXPECT_NE(out.find("from 2 robots; 0 silent"), std::string::npos) << out;
}

TEST_P(MultiHost, ATypeMismatchAcrossHostsIsReported) {
  if (!horus::backend_available(GetParam()))
    GTEST_SKIP() << "this build has no " << horus::to_string(GetParam()) << " backend";
  horus_test::NetnsLan lan(2);
  if (!lan.ok()) GTEST_SKIP() << "no namespace hosts: " << lan.why();
  const std::vector<std::string> env = fleet_env(GetParam());
  const std::string topic = "fleet.mismatch_" + std::to_string(::getpid());
  auto publisher = lan.spawn(0, {DDS_PEER, "publish-pose", topic, "30"}, env);      // Pose2D on host 1
  auto checker = lan.spawn(1, {DDS_PEER, "expect-mismatch", topic, "20"}, env);    // CmdVel on host 2
  const int rc = checker.wait(40s);
  EXPECT_EQ(rc, 0) << "host 2 (CmdVel) said:\n" << checker.output() << "\nhost 1 (Pose2D) said:\n"
                   << publisher.output();
}

INSTANTIATE_TEST_SUITE_P(Backends, MultiHost, ::testing::Values(horus::Backend::CycloneDds, horus::Backend::FastDds,
                                                                     horus::Backend::Lcm),
                         [](const auto& param_info) { return std::string(horus::to_string(param_info.param)); });

}  // namespace
