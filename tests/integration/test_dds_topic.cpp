// Topics on the DDS backends (Cyclone DDS, Fast DDS) between real processes on loopback
// (HORUS_DDS_LOCALHOST=1, a domain per test process): every message type round-trips, across
// vendors too; incompatible peers and malformed samples are reported; bad settings are errors.
#include <gtest/gtest.h>

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <string>
#include <thread>
#include <tuple>
#include <vector>

#include "horus/msg/all.hpp"
#include "horus/topic.hpp"
#include "horus/transport_registry.hpp"
#include "dds_support.hpp"
#include "message_samples.hpp"
#include "process_support.hpp"
#include "test_support.hpp"

extern char** environ;

namespace {

using horus::Backend;
using horus_test::on;
using horus_test::Peer;
using horus_test::round_trip_all;
using namespace std::chrono_literals;

// Loopback only, and a domain of our own (tests of other processes run at the same time).
class DdsTest : public ::testing::Test {
 protected:
  void SetUp() override {
    ::setenv("HORUS_DDS_LOCALHOST", "1", 1);
    ::setenv("HORUS_DOMAIN_ID", std::to_string(1 + ::getpid() % 200).c_str(), 1);
    ::unsetenv("HORUS_BACKEND");
  }
};

#define REQUIRE_BACKEND(b)                                                                          \
  if (!horus::backend_available(b))                                                                 \
  GTEST_SKIP() << "this build has no " << horus::to_string(b) << " backend (install its Debian package and rebuild)"


struct Pair {
  Backend mine;
  Backend peer;
};

class DdsPairs : public DdsTest, public ::testing::WithParamInterface<Pair> {};

TEST_P(DdsPairs, EveryMessageTypeRoundTripsFieldByField) {
  REQUIRE_BACKEND(GetParam().mine);
  REQUIRE_BACKEND(GetParam().peer);
  const auto prefix = horus_test::unique_name("dds.every");
  Peer peer(GetParam().peer, {"echo", prefix, "120"});
  ASSERT_TRUE(peer.ready()) << "the peer did not start";
  const auto failures = round_trip_all(GetParam().mine, prefix, horus_test::standard_types());
  for (const auto& f : failures) ADD_FAILURE() << f;
  EXPECT_EQ(peer.stop(), 0);
}

INSTANTIATE_TEST_SUITE_P(Backends, DdsPairs,
                         ::testing::Values(Pair{Backend::CycloneDds, Backend::CycloneDds},
                                           Pair{Backend::FastDds, Backend::FastDds},
                                           Pair{Backend::CycloneDds, Backend::FastDds},
                                           Pair{Backend::FastDds, Backend::CycloneDds}),
                         [](const auto& param_info) {
                           return std::string(horus::to_string(param_info.param.mine)) + "_to_" +
                                  std::string(horus::to_string(param_info.param.peer));
                         });

// ---------------------------------------------------------------------------
// One backend at a time.

class DdsBackend : public DdsTest, public ::testing::WithParamInterface<Backend> {};

TEST_P(DdsBackend, ABlockedRecvForWakesForEachMessageFromAnotherProcess) {
  REQUIRE_BACKEND(GetParam());
  const auto name = horus_test::unique_name("wait");
  auto sub = horus::Topic<horus::msg::Pose2D>::open(name, on(GetParam()));
  ASSERT_TRUE(sub) << sub.error().message();
  Peer peer(GetParam(), {"publish-pose", name, "60"});  // a Pose2D every 20 ms
  ASSERT_TRUE(peer.ready());
  auto first = sub->recv_for(20s);
  ASSERT_TRUE(first) << "nothing from the peer in 20 s";
  // Each recv_for sleeps until the transport's receive thread writes the next one into the ring.
  const auto t0 = std::chrono::steady_clock::now();
  double last = first->x;
  int got = 0;
  for (; got < 10; ++got) {
    auto m = sub->recv_for(5s);
    if (!m) break;
    EXPECT_GT(m->x, last);
    last = m->x;
  }
  const auto took = std::chrono::steady_clock::now() - t0;
  EXPECT_EQ(got, 10);
  EXPECT_GE(took, 100ms) << "ten messages 20 ms apart came at once: recv_for did not wait for them";
  EXPECT_EQ(sub->waiter_count(), 0u);
  EXPECT_EQ(peer.stop(), 0);
}

TEST_P(DdsBackend, HandlesOfOneProcessGetEachMessageOnce) {
  REQUIRE_BACKEND(GetParam());
  const auto name = horus_test::unique_name("dds.once");
  horus::Topic<horus::msg::Pose2D> pub = horus::Topic<horus::msg::Pose2D>::open(name, on(GetParam())).value();
  horus::Topic<horus::msg::Pose2D> sub = horus::Topic<horus::msg::Pose2D>::open(name, on(GetParam())).value();
  EXPECT_EQ(pub.backend(), GetParam());
  for (int i = 0; i < 10; ++i) pub.send(horus::msg::Pose2D{double(i), 0, 0, std::uint64_t(i)});
  for (int i = 0; i < 10; ++i) {
    auto m = sub.recv();
    ASSERT_TRUE(m);
    EXPECT_EQ(m->x, i);
  }
  // Nothing comes back through the network (no self-delivery).
  std::this_thread::sleep_for(300ms);
  EXPECT_FALSE(sub.recv());
}

TEST_P(DdsBackend, CountsRemoteEndpointsInPubAndSubCount) {
  REQUIRE_BACKEND(GetParam());
  const auto name = horus_test::unique_name("dds.count");
  auto sub = horus::Topic<horus::msg::Pose2D>::open(name, on(GetParam()));
  ASSERT_TRUE(sub) << sub.error().message();
  EXPECT_EQ(sub->pub_count(), 0u);
  Peer peer(GetParam(), {"publish-pose", name, "60"});
  ASSERT_TRUE(peer.ready());
  horus_test::Deadline d(20s);
  std::optional<horus::msg::Pose2D> got;
  while (!d.expired() && !got) {
    got = sub->recv();
    std::this_thread::sleep_for(5ms);
  }
  ASSERT_TRUE(got) << "nothing from the peer in 20 s";
  EXPECT_EQ(sub->pub_count(), 1u) << "the peer's writer";
  // This handle, plus the peer's reader: every endpoint has a writer and a reader.
  EXPECT_GE(sub->sub_count(), 1u);
  EXPECT_EQ(peer.stop(), 0);
  horus_test::Deadline gone(20s);
  while (!gone.expired() && sub->pub_count() != 0) std::this_thread::sleep_for(10ms);
  EXPECT_EQ(sub->pub_count(), 0u) << "the peer left";
}

// A reliable fleet topic whose subscriber reads slower than another host sends: the bridge
// waits for room in the host's ring instead of overwriting, DDS's flow control slows the
// sender, and every message arrives once, in order (a ring of 8 against a burst of 3000).
TEST_P(DdsBackend, AReliableTopicsSlowSubscriberLosesNothingFromABurst) {
  REQUIRE_BACKEND(GetParam());
  const auto name = horus_test::unique_name("dds.burst");
  horus::TopicOptions options = on(GetParam());
  options.reliability = horus::net::Reliability::Reliable;
  options.capacity = 8;
  auto sub = horus::Topic<horus::msg::Pose2D>::open(name, options);
  ASSERT_TRUE(sub) << sub.error().message();
  constexpr std::uint64_t kCount = 3000;
  Peer peer(GetParam(), {"burst", name, std::to_string(kCount), "60"});
  ASSERT_TRUE(peer.ready());
  horus_test::Deadline matched(20s);
  while (!matched.expired() && sub->pub_count() == 0) std::this_thread::sleep_for(10ms);
  ASSERT_EQ(sub->pub_count(), 1u) << "the peer's writer was not matched in 20 s";
  std::this_thread::sleep_for(300ms);  // the peer's writer matches our reader too
  ASSERT_TRUE(peer.say("g"));
  std::uint64_t next = 0, out_of_order = 0;
  horus_test::Deadline d(40s);
  while (next < kCount && !d.expired()) {
    if (auto m = sub->recv()) {
      if (static_cast<std::uint64_t>(m->x) != next) ++out_of_order;
      next = static_cast<std::uint64_t>(m->x) + 1;
      if (next % 4 == 0) std::this_thread::sleep_for(1ms);  // slower than the sender
    } else {
      std::this_thread::sleep_for(100us);
    }
  }
  EXPECT_EQ(next, kCount) << "the last message did not arrive";
  EXPECT_EQ(out_of_order, 0u) << "messages were skipped (overwritten) or reordered";
  EXPECT_EQ(sub->dropped_count(), 0u);
  EXPECT_EQ(peer.stop(), 0);
}

// A subscriber that never reads (stopped, in a debugger) holds a reliable topic back for
// 100 ms at most: then the bridge overwrites its oldest messages, counted, and the sender is
// not held up forever.
TEST_P(DdsBackend, AStuckSubscriberOfAReliableTopicIsOverwrittenAndCountedAfterAWhile) {
  REQUIRE_BACKEND(GetParam());
  const auto name = horus_test::unique_name("dds.stuck");
  horus::TopicOptions options = on(GetParam());
  options.reliability = horus::net::Reliability::Reliable;
  options.capacity = 8;
  auto stuck = horus::Topic<horus::msg::Pose2D>::open(name, options);
  ASSERT_TRUE(stuck) << stuck.error().message();
  constexpr std::uint64_t kCount = 2000;
  Peer peer(GetParam(), {"burst", name, std::to_string(kCount), "60"});
  ASSERT_TRUE(peer.ready());
  horus_test::Deadline matched(20s);
  while (!matched.expired() && stuck->pub_count() == 0) std::this_thread::sleep_for(10ms);
  ASSERT_EQ(stuck->pub_count(), 1u) << "the peer's writer was not matched in 20 s";
  std::this_thread::sleep_for(300ms);
  ASSERT_TRUE(peer.say("g"));
  horus_test::Deadline d(30s);
  while (!d.expired() && stuck->dropped_count() < kCount - 8) std::this_thread::sleep_for(20ms);
  EXPECT_EQ(stuck->dropped_count(), kCount - 8) << "all but the ring's 8 newest should be overwritten and counted";
  std::uint64_t last = 0, n = 0;
  while (auto m = stuck->recv()) {
    last = static_cast<std::uint64_t>(m->x);
    ++n;
  }
  EXPECT_EQ(n, 8u);
  EXPECT_EQ(last, kCount - 1) << "the ring keeps the newest";
  EXPECT_EQ(peer.stop(), 0);
}

TEST_P(DdsBackend, AnotherMessageTypeOnTheSameTopicIsReported) {
  REQUIRE_BACKEND(GetParam());
  const auto name = horus_test::unique_name("dds.mismatch");
  auto sub = horus::Topic<horus::msg::CmdVel>::open(name, on(GetParam()));
  ASSERT_TRUE(sub) << sub.error().message();
  Peer peer(GetParam(), {"publish-pose", name, "60"});  // Pose2D under the same DDS topic
  ASSERT_TRUE(peer.ready());
  horus_test::Deadline d(20s);
  while (!d.expired() && sub->network_errors() == 0) std::this_thread::sleep_for(10ms);
  EXPECT_GT(sub->network_errors(), 0u) << "the type mismatch was not reported";
  EXPECT_FALSE(sub->recv()) << "a Pose2D must never arrive as a CmdVel";
  EXPECT_EQ(peer.stop(), 0);
}

TEST_P(DdsBackend, MalformedSamplesAreCountedAndLaterGoodOnesStillArrive) {
  REQUIRE_BACKEND(GetParam());
  const auto name = horus_test::unique_name("dds.malformed");
  auto sub = horus::Topic<horus::msg::Pose2D>::open(name, on(GetParam()));
  ASSERT_TRUE(sub) << sub.error().message();
  Peer peer(GetParam(), {"raw", horus::wire_name(GetParam(), name).value(), "horus::msg::Pose2D", "60"});
  ASSERT_TRUE(peer.ready());
  horus_test::Deadline d(20s);
  int good = 0;
  while (!d.expired() && (good < 3 || sub->metrics().decode_failures() < 3)) {
    while (auto m = sub->recv()) {
      EXPECT_EQ(m->x, 42.0);
      EXPECT_EQ(m->timestamp_ns, 7u);
      ++good;
    }
    std::this_thread::sleep_for(5ms);
  }
  EXPECT_GE(good, 3);
  EXPECT_GE(sub->metrics().decode_failures(), 3u);
  EXPECT_EQ(peer.stop(), 0);
}

TEST_P(DdsBackend, ALatchedTopicReachesALateJoiner) {
  REQUIRE_BACKEND(GetParam());
  const auto prefix = horus_test::unique_name("dds.latched");
  // OccupancyGrid is transient local: the peer, started after the map was sent, still gets it.
  auto map = horus::Topic<horus::msg::OccupancyGrid>::open(prefix + ".OccupancyGrid", on(GetParam()));
  auto echo = horus::Topic<horus::msg::OccupancyGrid>::open(prefix + ".OccupancyGrid.echo", on(GetParam()));
  ASSERT_TRUE(map && echo);
  const auto sent = horus_test::sample<horus::msg::OccupancyGrid>();
  map->send(sent);
  Peer peer(GetParam(), {"echo", prefix, "60"});
  ASSERT_TRUE(peer.ready());
  horus_test::Deadline d(30s);
  std::optional<horus::msg::OccupancyGrid> got;
  while (!d.expired() && !(got = echo->recv())) std::this_thread::sleep_for(5ms);
  ASSERT_TRUE(got) << "the late joiner did not get the map";
  EXPECT_TRUE(horus_test::SameMessage(*got, sent));
  EXPECT_EQ(peer.stop(), 0);
}

TEST_P(DdsBackend, AHandleOpenedLaterReadsTheLatestMessageAsOnSharedMemory) {
  REQUIRE_BACKEND(GetParam());
  const auto name = horus_test::unique_name("dds.latest");
  auto pub = horus::Topic<horus::msg::Pose2D>::open(name, on(GetParam()));
  ASSERT_TRUE(pub) << pub.error().message();
  pub->send(horus::msg::Pose2D{1.0, 2.0, 3.0, 4});  // no subscriber in the process yet
  auto late = horus::Topic<horus::msg::Pose2D>::open(name, on(GetParam()));
  ASSERT_TRUE(late) << late.error().message();
  auto m = late->read_latest();
  ASSERT_TRUE(m);
  EXPECT_EQ(m->timestamp_ns, 4u);
}

TEST_P(DdsBackend, AnotherQosForAnOpenTopicIsAConfigMismatch) {
  REQUIRE_BACKEND(GetParam());
  const auto name = horus_test::unique_name("dds.qos");
  auto first = horus::Topic<horus::msg::Pose2D>::open(name, on(GetParam()));  // reliable by default
  ASSERT_TRUE(first) << first.error().message();
  auto options = on(GetParam());
  options.reliability = horus::net::Reliability::BestEffort;
  auto second = horus::Topic<horus::msg::Pose2D>::open(name, options);
  ASSERT_FALSE(second);
  EXPECT_EQ(second.error().code(), horus::Errc::ConfigMismatch);
  EXPECT_NE(second.error().message().find("reliable"), std::string::npos) << second.error().message();
  options.reliability = horus::net::Reliability::Reliable;
  EXPECT_TRUE(horus::Topic<horus::msg::Pose2D>::open(name, options)) << "the same QoS is accepted";
}

TEST_P(DdsBackend, AForkedChildGetsAClearErrorInsteadOfTheParentsParticipant) {
  REQUIRE_BACKEND(GetParam());
  const auto name = horus_test::unique_name("dds.fork");
  auto parent = horus::Topic<horus::msg::Pose2D>::open(name, on(GetParam()));
  ASSERT_TRUE(parent) << parent.error().message();
  const pid_t child = horus_test::spawn([&] {
    auto t = horus::Topic<horus::msg::Pose2D>::open(name + ".child", on(GetParam()));
    if (t) return 1;
    if (t.error().code() != horus::Errc::Io) return 2;
    return t.error().message().find("fork") != std::string::npos ? 0 : 3;
  });
  EXPECT_EQ(horus_test::wait_for(child, 30s), 0);
  parent->send(horus::msg::Pose2D{});  // the parent's participant still works
  EXPECT_EQ(parent->metrics().send_failures(), 0u);
}

TEST_P(DdsBackend, BadSettingsAreClearErrors) {
  REQUIRE_BACKEND(GetParam());
  const auto name = horus_test::unique_name("dds.bad");
  ::setenv("HORUS_DOMAIN_ID", "233", 1);
  auto t = horus::Topic<horus::msg::Pose2D>::open(name, on(GetParam()));
  ASSERT_FALSE(t);
  EXPECT_EQ(t.error().code(), horus::Errc::Config);
  EXPECT_NE(t.error().message().find("HORUS_DOMAIN_ID=233"), std::string::npos) << t.error().message();
  ::setenv("HORUS_DOMAIN_ID", "seven", 1);
  EXPECT_FALSE(horus::Topic<horus::msg::Pose2D>::open(name, on(GetParam())));
  ::setenv("HORUS_DOMAIN_ID", "7", 1);
  ::setenv("HORUS_DDS_LOCALHOST", "maybe", 1);
  t = horus::Topic<horus::msg::Pose2D>::open(name, on(GetParam()));
  ASSERT_FALSE(t);
  EXPECT_NE(t.error().message().find("HORUS_DDS_LOCALHOST=maybe"), std::string::npos) << t.error().message();
  ::setenv("HORUS_DDS_LOCALHOST", "1", 1);
  t = horus::Topic<horus::msg::Pose2D>::open(name + "-dash", on(GetParam()));
  ASSERT_FALSE(t);
  EXPECT_EQ(t.error().code(), horus::Errc::InvalidName);
  EXPECT_NE(t.error().message().find("'-'"), std::string::npos) << t.error().message();
}

INSTANTIATE_TEST_SUITE_P(Backends, DdsBackend, ::testing::Values(Backend::CycloneDds, Backend::FastDds),
                         [](const auto& param_info) { return std::string(horus::to_string(param_info.param)); });

TEST_F(DdsTest, BackendNamesAreCheckedInTheEnvironment) {
  ::setenv("HORUS_BACKEND", "cyclone", 1);
  auto b = horus::backend_from_environment();
  ASSERT_FALSE(b);
  EXPECT_NE(b.error().message().find("expected auto, shm, inproc, cyclonedds, fastdds or lcm"), std::string::npos)
      << b.error().message();
  for (Backend want : {Backend::CycloneDds, Backend::FastDds}) {
    ::setenv("HORUS_BACKEND", std::string(horus::to_string(want)).c_str(), 1);
    b = horus::backend_from_environment();
    if (horus::backend_available(want)) {
      ASSERT_TRUE(b) << b.error().message();
      EXPECT_EQ(*b, want);
    } else {
      EXPECT_FALSE(b);
    }
  }
  ::unsetenv("HORUS_BACKEND");
}

// With libhorus.so the DDS transports are plug-ins (docs/ABI.md): one that is not where the
// library looks is a clear error naming its file and HORUS_PLUGIN_PATH, not a crash. In a child
// forked before anything loaded the plug-in (ctest runs each test in a process of its own).
TEST(DdsPlugins, AMissingPlugInIsAnErrorThatNamesItsFile) {
  const std::string file = horus::net::transport_plugin_directory() + "/libhorus-cyclonedds.so";
  if (::access(file.c_str(), F_OK) != 0) GTEST_SKIP() << "this build has no plug-in " << file << " (a static build?)";
  int fds[2];
  ASSERT_EQ(::pipe(fds), 0);
  const pid_t pid = ::fork();
  ASSERT_GE(pid, 0);
  if (pid == 0) {
    ::close(fds[0]);
    ::setenv("HORUS_PLUGIN_PATH", "/nonexistent/horus-plugins", 1);
    ::setenv("HORUS_DDS_LOCALHOST", "1", 1);
    horus::TopicOptions o;
    o.backend = Backend::CycloneDds;
    auto t = horus::Topic<horus::msg::Pose2D>::open("plugin.missing", o);
    const std::string why = t ? std::string("opened") : t.error().message();
    (void)!::write(fds[1], why.data(), why.size());
    ::_exit(t ? 1 : 0);
  }
  ::close(fds[1]);
  std::string why;
  char buf[512];
  for (ssize_t n; (n = ::read(fds[0], buf, sizeof buf)) > 0;) why.append(buf, static_cast<std::size_t>(n));
  ::close(fds[0]);
  int status = 0;
  ASSERT_EQ(::waitpid(pid, &status, 0), pid);
  ASSERT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << "the topic opened without its plug-in: " << why;
  EXPECT_NE(why.find("/nonexistent/horus-plugins/libhorus-cyclonedds.so"), std::string::npos) << why;
  EXPECT_NE(why.find("HORUS_PLUGIN_PATH"), std::string::npos) << why;
}

}  // namespace
