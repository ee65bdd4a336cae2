// The fleet on three hosts (namespace hosts on a bridge, each with its own /dev/shm and
// hostname: netns.hpp): robots on two hosts publish Heartbeat, Pose2D and TransformStamped over
// DDS or LCM (udpm, ttl=1) and the monitor on the third receives all of them; three hosts with
// two processes each get every message of a reliable fleet topic exactly once and in order;
// host- and process-scoped topics never leave their scope. Skips when not root or without
// `ip netns`.
#include <gtest/gtest.h>

#include <fcntl.h>
#include <signal.h>
#include <sys/mman.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <list>
#include <string>
#include <thread>

#include "horus/shm/shm_segment.hpp"
#include "horus/topic.hpp"
#include "netns.hpp"
#include "test_support.hpp"

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

std::string unix_ms_from_now(std::chrono::milliseconds d) {
  return std::to_string(std::chrono::duration_cast<std::chrono::milliseconds>(
                            (std::chrono::system_clock::now() + d).time_since_epoch())
                            .count());
}

// Three hosts, two processes each, every process publishing 200 numbered messages and reading
// the topic: each process gets all 1200 exactly once, in each publisher's order. On each host
// one process bridges (one writer and one reader on the network per host, not per process).
TEST_P(MultiHost, ThreeHostsOfTwoProcessesGetEveryMessageExactlyOnceInOrder) {
  if (!horus::backend_available(GetParam()))
    GTEST_SKIP() << "this build has no " << horus::to_string(GetParam()) << " backend";
  horus_test::NetnsLan lan(3);
  if (!lan.ok()) GTEST_SKIP() << "no namespace hosts: " << lan.why();
  const std::vector<std::string> env = fleet_env(GetParam());
  const std::string topic = "fleet.once_" + std::to_string(::getpid());
  const std::string start = unix_ms_from_now(std::chrono::milliseconds(4000));  // after discovery
  std::vector<horus_test::HostProcess> members;
  for (int i = 0; i < 6; ++i)
    members.push_back(lan.spawn(i / 2, {FLEET_MEMBER, topic, "fleet", std::to_string(i + 1), "200", start, "6", "40"},
                                env));
  for (int i = 0; i < 6; ++i) {
    const int rc = members[static_cast<std::size_t>(i)].wait(60s);
    const std::string out = members[static_cast<std::size_t>(i)].output();
    EXPECT_EQ(rc, 0) << "process " << i + 1 << " on " << lan.host(i / 2) << " said:\n" << out;
    EXPECT_NE(out.find("received 1200 from 6 publishers; duplicates 0; out of order 0; missing 0"), std::string::npos)
        << out;
  }
}

// A host-scoped and a process-scoped topic: their messages reach their scope (another process
// of the host; the same process) and nothing else: a fleet subscriber of the same name on
// another host, and another process of the same host for the process scope, get nothing.
TEST_P(MultiHost, HostAndProcessScopedTopicsNeverLeaveTheirScope) {
  if (!horus::backend_available(GetParam()))
    GTEST_SKIP() << "this build has no " << horus::to_string(GetParam()) << " backend";
  horus_test::NetnsLan lan(2);
  if (!lan.ok()) GTEST_SKIP() << "no namespace hosts: " << lan.why();
  const std::vector<std::string> env = fleet_env(GetParam());
  const std::string host_topic = "fleet.hostonly_" + std::to_string(::getpid());
  const std::string proc_topic = "fleet.proconly_" + std::to_string(::getpid());
  const std::string start = unix_ms_from_now(std::chrono::milliseconds(3000));
  // Host 1: a publisher and a second reader of the host topic; a process-topic publisher and
  // a process-topic reader in another process.
  auto host_pub = lan.spawn(0, {FLEET_MEMBER, host_topic, "host", "1", "100", start, "1", "30"}, env);
  auto host_reader = lan.spawn(0, {FLEET_MEMBER, host_topic, "host", "0", "100", start, "1", "30"}, env);
  auto proc_pub = lan.spawn(0, {FLEET_MEMBER, proc_topic, "process", "1", "100", start, "1", "30"}, env);
  auto proc_other = lan.spawn(0, {FLEET_MEMBER, proc_topic, "process", "0", "100", start, "0", "30"}, env);
  // Host 2: fleet subscribers of both names (a DDS reader / LCM subscription of those names).
  auto far_host = lan.spawn(1, {FLEET_MEMBER, host_topic, "fleet", "0", "100", start, "0", "30"}, env);
  auto far_proc = lan.spawn(1, {FLEET_MEMBER, proc_topic, "fleet", "0", "100", start, "0", "30"}, env);
  struct Expect {
    horus_test::HostProcess* p;
    const char* what;
    const char* line;
  } expects[] = {
      {&host_pub, "the host-topic publisher (its own messages)", "received 100 from 1 publishers"},
      {&host_reader, "another process of the host (host topic)", "received 100 from 1 publishers"},
      {&proc_pub, "the process-topic publisher (its own messages)", "received 100 from 1 publishers"},
      {&proc_other, "another process of the host (process topic)", "received 0 from 0 publishers"},
      {&far_host, "a fleet subscriber on another host (host topic)", "received 0 from 0 publishers"},
      {&far_proc, "a fleet subscriber on another host (process topic)", "received 0 from 0 publishers"},
  };
  for (auto& e : expects) {
    const int rc = e.p->wait(60s);
    const std::string out = e.p->output();
    EXPECT_EQ(rc, 0) << e.what << " said:\n" << out;
    EXPECT_NE(out.find(e.line), std::string::npos) << e.what << " said:\n" << out;
  }
}

// The header of a topic's segment on a namespace host, read through its holder's mount
// namespace (/proc/<pid>/root/dev/shm), read-only.
class HostSegment {
 public:
  HostSegment(pid_t holder, const std::string& topic) {
    const std::string path = "/proc/" + std::to_string(holder) + "/root/dev/shm/horus.u" +
                             std::to_string(::getuid()) + "." + topic;
    const int fd = ::open(path.c_str(), O_RDONLY);
    if (fd < 0) return;
    void* p = ::mmap(nullptr, sizeof(horus::shm::SegmentHeader), PROT_READ, MAP_SHARED, fd, 0);
    ::close(fd);
    if (p != MAP_FAILED) header_ = static_cast<const horus::shm::SegmentHeader*>(p);
  }
  ~HostSegment() {
    if (header_ != nullptr) ::munmap(const_cast<horus::shm::SegmentHeader*>(header_), sizeof(*header_));
  }
  bool ok() const { return header_ != nullptr; }
  pid_t bridge_pid() const { return static_cast<pid_t>(header_->bridge.owner.load() >> 32); }
  std::uint64_t claims() const { return header_->bridge.claims.load(); }

 private:
  const horus::shm::SegmentHeader* header_ = nullptr;
};

// Waits until the process holding `topic`'s bridge on a namespace host (through its holder
// `ns_holder`) is `want`, or `timeout` passed; returns the holder seen last (0: none). The claim
// word lives in the other host's /dev/shm and nothing there wakes this process: it is looked at
// every millisecond until the deadline.
pid_t await_bridge_holder(pid_t ns_holder, const std::string& topic, pid_t want, std::chrono::milliseconds timeout) {
  pid_t seen = 0;
  for (horus_test::Deadline d(timeout); !d.expired(); std::this_thread::sleep_for(1ms)) {
    HostSegment seg(ns_holder, topic);  // mapped again until the topic's segment exists
    if (seg.ok() && (seen = seg.bridge_pid()) == want) break;
  }
  return seen;
}

// A number after `key` in `text` ("missing 3" -> 3), or -1.
long long number_after(const std::string& text, const std::string& key) {
  const auto at = text.rfind(key);
  return at == std::string::npos ? -1 : std::atoll(text.c_str() + at + key.size());
}

// SIGKILL of the process that bridges the publishing host, again and again (20 rounds;
// HORUS_TAKEOVER_ROUNDS=100 for the long run): another process of the host holds the bridge
// within a few ms (median; at most 1 s on a loaded machine), and the subscriber on the other host gets every message once or
// it is counted as dropped on the publishing host; never twice.
TEST_P(MultiHost, KillingTheBridgeHandsItOverWithNoDuplicateAndEveryLossCounted) {
  if (!horus::backend_available(GetParam()))
    GTEST_SKIP() << "this build has no " << horus::to_string(GetParam()) << " backend";
  horus_test::NetnsLan lan(2);
  if (!lan.ok()) GTEST_SKIP() << "no namespace hosts: " << lan.why();
  const char* r = std::getenv("HORUS_TAKEOVER_ROUNDS");
  const int rounds = r != nullptr ? std::max(1, std::atoi(r)) : 20;
  const int count = 600 + rounds * 150;
  const std::string seconds = std::to_string(30 + rounds);
  std::vector<std::string> env = fleet_env(GetParam());
  const std::string topic = "fleet.takeover_" + std::to_string(::getpid());
  const std::string start = unix_ms_from_now(std::chrono::milliseconds(3000));
  // Host 1: bridge candidates (they only listen) and the publisher, which never bridges.
  auto candidate = [&] {
    return lan.spawn(0, {FLEET_MEMBER, topic, "fleet", "0", std::to_string(count), start, "-1", seconds}, env);
  };
  std::list<horus_test::HostProcess> candidates;
  candidates.push_back(candidate());
  candidates.push_back(candidate());
  std::vector<std::string> pub_env = env;
  pub_env.push_back("HORUS_BRIDGE=0");
  auto publisher =
      lan.spawn(0, {FLEET_MEMBER, topic, "fleet", "1", std::to_string(count), start, "1", seconds}, pub_env);
  auto subscriber =
      lan.spawn(1, {FLEET_MEMBER, topic, "fleet", "0", std::to_string(count), start, "1", seconds}, env);
  std::this_thread::sleep_for(std::chrono::milliseconds(3500));  // publishing has begun
  HostSegment seg(lan.holder(0), topic);
  ASSERT_TRUE(seg.ok()) << "no segment of " << topic << " on " << lan.host(0);
  std::vector<double> takeover_ms;
  for (int round = 0; round < rounds; ++round) {
    const pid_t holder = seg.bridge_pid();
    auto it = std::find_if(candidates.begin(), candidates.end(), [&](auto& c) { return c.pid() == holder; });
    ASSERT_NE(it, candidates.end()) << "round " << round << ": the bridge is held by pid " << holder
                                    << ", not by a candidate (the publisher has HORUS_BRIDGE=0)";
    const std::uint64_t claims = seg.claims();
    ::kill(holder, SIGKILL);
    const auto t0 = std::chrono::steady_clock::now();
    while (seg.claims() == claims && std::chrono::steady_clock::now() - t0 < std::chrono::seconds(5))
      std::this_thread::sleep_for(std::chrono::microseconds(200));
    takeover_ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
    ASSERT_NE(seg.claims(), claims) << "round " << round << ": nobody took the bridge over in 5 s";
    (void)it->wait(std::chrono::seconds(5));
    candidates.erase(it);
    candidates.push_back(candidate());
    std::this_thread::sleep_for(std::chrono::milliseconds(150));  // the new candidate opens the topic
  }
  std::sort(takeover_ms.begin(), takeover_ms.end());
  std::printf("takeovers: %d, median %.1f ms, max %.1f ms\n", rounds, takeover_ms[takeover_ms.size() / 2],
              takeover_ms.back());
  // Event-driven (the holder's pidfd): the median is a few ms; polling the holder's liveness
  // (every 50 ms) would put it above 20 ms. A killed process's exit takes longer on a loaded
  // machine (153 ms once beside two busy loops): the slowest is bounded at 1 s, and the time
  // under load is the benchmark's to show, not a test's.
  EXPECT_LE(takeover_ms[takeover_ms.size() / 2], 20.0) << "the median takeover took longer than 20 ms";
  EXPECT_LE(takeover_ms.back(), 1000.0) << "a takeover took longer than 1 s";
  const int pub_rc = publisher.wait(std::chrono::seconds(90));
  const int sub_rc = subscriber.wait(std::chrono::seconds(90));
  const std::string pub_out = publisher.output();
  const std::string sub_out = subscriber.output();
  (void)pub_rc;
  (void)sub_rc;
  const long long received = number_after(sub_out, "received ");
  const long long duplicates = number_after(sub_out, "duplicates ");
  const long long missing = number_after(sub_out, "missing ");
  const long long dropped = number_after(pub_out, "dropped ");
  ASSERT_GE(received, 0) << "the subscriber said:\n" << sub_out;
  ASSERT_GE(dropped, 0) << "the publisher said:\n" << pub_out;
  std::printf("subscriber: %s publisher: %s", sub_out.substr(sub_out.rfind("received")).c_str(),
              pub_out.substr(pub_out.rfind("received")).c_str());
  EXPECT_EQ(duplicates, 0) << sub_out;
  // Lost: never received, at the end (missing) or in a gap a takeover left ("out of order").
  const long long lost = count - received;
  EXPECT_GE(lost, missing) << sub_out;
  EXPECT_LE(lost, dropped) << "messages lost without being counted; subscriber:\n"
                              << sub_out << "\npublisher:\n"
                              << pub_out;
}

// The bridge follows the host's publisher (fleet/README.md, the hand-over): on host 1 a listener
// opens the topic first and holds the bridge, then a publisher of the host sends; the listener,
// which publishes nothing, hands the bridge over while messages flow, so that the publisher's
// sends export inline. Every message reaches the other host exactly once and in order across the
// hand-over, and the other host's messages, sent after it, reach both processes of host 1 (the
// import moved with the bridge).
TEST_P(MultiHost, TheBridgeFollowsTheHostsPublisherWithEveryMessageOnceBothWays) {
  if (!horus::backend_available(GetParam()))
    GTEST_SKIP() << "this build has no " << horus::to_string(GetParam()) << " backend";
  horus_test::NetnsLan lan(2);
  if (!lan.ok()) GTEST_SKIP() << "no namespace hosts: " << lan.why();
  const std::vector<std::string> env = fleet_env(GetParam());
  const std::string topic = "fleet.follow_" + std::to_string(::getpid());
  const std::string start = unix_ms_from_now(std::chrono::milliseconds(4000));  // after discovery
  const std::string far_start = unix_ms_from_now(std::chrono::milliseconds(7000));
  auto member = [&](int host, const char* id, const std::string& at) {
    return lan.spawn(host, {FLEET_MEMBER, topic, "fleet", id, "300", at, "2", "30", "period=5"}, env);
  };
  auto listener = member(0, "0", start);
  // The listener holds host 1's bridge before the publisher opens the topic.
  const pid_t holder = await_bridge_holder(lan.holder(0), topic, listener.pid(), 10s);
  ASSERT_EQ(holder, listener.pid()) << "the listener did not hold the bridge; it said:\n" << listener.output();
  auto publisher = member(0, "1", start);
  auto far = member(1, "2", far_start);
  // Handed over within 3 s of the first send (it takes a few hundred ms).
  const pid_t after = await_bridge_holder(lan.holder(0), topic, publisher.pid(), 7s);
  EXPECT_EQ(after, publisher.pid()) << "host 1's bridge stayed with pid " << after;
  std::printf("the bridge went from the listener (pid %d) to pid %d\n", static_cast<int>(holder),
              static_cast<int>(after));
  std::fflush(stdout);  // a run that stops later shows how far it came
  struct Member {
    horus_test::HostProcess* p;
    const char* what;
  } members[] = {{&listener, "the listener of host 1"}, {&publisher, "the publisher of host 1"},
                 {&far, "the publisher of host 2"}};
  for (auto& m : members) {
    const int rc = m.p->wait(60s);
    const std::string out = m.p->output();
    EXPECT_EQ(rc, 0) << m.what << " said:\n" << out;
    EXPECT_NE(out.find("received 600 from 2 publishers; duplicates 0; out of order 0; missing 0"), std::string::npos)
        << m.what << " said:\n" << out;
    // Nothing came from the network during the hand-over: nothing to count as lost either.
    EXPECT_EQ(number_after(out, "dropped "), 0) << m.what << " said:\n" << out;
  }
}

INSTANTIATE_TEST_SUITE_P(Backends, MultiHost, ::testing::Values(horus::Backend::CycloneDds, horus::Backend::FastDds,
                                                                     horus::Backend::Lcm),
                         [](const auto& param_info) { return std::string(horus::to_string(param_info.param)); });

}  // namespace
