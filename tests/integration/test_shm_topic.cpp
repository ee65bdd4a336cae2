// Topic<T> between real processes (fork()): delivery, late joiners, serialized messages,
// type mismatch, backend choice, and publishers killed in the middle of sending.
#include <gtest/gtest.h>

#include <fcntl.h>
#include <signal.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cstdint>
#include <cstdlib>
#include <string>
#include <thread>
#include <vector>

#include "horus/msg/geometry.hpp"
#include "horus/shm/doorbell.hpp"
#include "horus/shm/shm_segment.hpp"
#include "horus/topic.hpp"
#include "process_support.hpp"
#include "test_support.hpp"

namespace shm_topic_test {
struct Blob {
  std::string label;
  std::vector<std::uint32_t> values;
  friend bool operator==(const Blob&, const Blob&) = default;
};
HORUS_REFLECT(Blob, label, values)
}  // namespace shm_topic_test

namespace {

using horus::Topic;
using horus_test::Pipe;
using horus_test::spawn;
using horus_test::wait_for;
using horus_test::Stamp;
using shm_topic_test::Blob;

using ShmTopic = horus_test::ShmProcessTest;  // HORUS_BACKEND unset; no /dev/shm leak after a test

TEST_F(ShmTopic, AnotherProcessReceivesEveryMessageOnceInOrder) {
  const auto name = horus_test::unique_name("xproc");
  auto sub = Topic<Stamp>::with_capacity(name, 1024);
  ASSERT_TRUE(sub) << sub.error().message();
  EXPECT_EQ(sub->backend(), horus::Backend::SharedMemory);
  constexpr std::uint64_t kCount = 5000;
  const pid_t child = spawn([&] {
    Topic<Stamp> pub(name);
    for (std::uint64_t i = 0; i < kCount; ++i) {
      while (!pub.try_send(Stamp::make(3, i))) std::this_thread::yield();
    }
    return 0;
  });
  std::uint64_t next = 0;
  const horus_test::Deadline deadline(std::chrono::seconds(30));
  while (next < kCount && !deadline.expired()) {
    if (auto m = sub->recv()) {
      ASSERT_TRUE(m->intact());
      ASSERT_EQ(m->seq, next);
      ++next;
    } else {
      std::this_thread::yield();
    }
  }
  EXPECT_EQ(wait_for(child), 0);
  EXPECT_EQ(next, kCount);
  EXPECT_EQ(sub->dropped_count(), 0u);
}

TEST_F(ShmTopic, ALateJoiningProcessGetsOnlyLaterMessagesAndReadLatestTheNewest) {
  const auto name = horus_test::unique_name("late");
  Topic<Stamp> pub(name);
  pub.send(Stamp::make(1, 1));
  pub.send(Stamp::make(1, 2));
  Pipe joined, sent;
  const pid_t child = spawn([&] {
    Topic<Stamp> sub(name);
    auto latest = sub.read_latest();
    if (!latest || latest->seq != 2) return 10;
    joined.signal();
    if (!sent.wait()) return 11;
    auto m = sub.recv();
    if (!m || m->seq != 3 || !m->intact()) return 12;
    return sub.recv() ? 13 : 0;
  });
  ASSERT_TRUE(joined.wait());
  pub.send(Stamp::make(1, 3));
  sent.signal();
  EXPECT_EQ(wait_for(child), 0);
}

TEST_F(ShmTopic, SerializedMessagesCrossProcesses) {
  const auto name = horus_test::unique_name("blob");
  Topic<Blob> sub(name);
  const pid_t child = spawn([&] {
    Topic<Blob> pub(name);
    for (std::uint32_t i = 0; i < 10; ++i) pub.send(Blob{"blob" + std::to_string(i), std::vector<std::uint32_t>(i * 100, i)});
    return 0;
  });
  EXPECT_EQ(wait_for(child), 0);
  for (std::uint32_t i = 0; i < 10; ++i) {
    auto m = sub.recv();
    ASSERT_TRUE(m) << i;
    EXPECT_EQ(*m, (Blob{"blob" + std::to_string(i), std::vector<std::uint32_t>(i * 100, i)}));
  }
}

TEST_F(ShmTopic, AnotherProcessOpeningTheNameWithAnotherTypeGetsAnErrorNamingBoth) {
  const auto name = horus_test::unique_name("mismatch");
  Topic<Stamp> holder(name);
  const pid_t child = spawn([&] {
    auto other = Topic<horus_test::Other>::open(name);
    if (other) return 10;
    if (other.error().code() != horus::Errc::TypeMismatch) return 11;
    const auto& msg = other.error().message();
    return msg.find("horus_test::Stamp") != std::string::npos && msg.find("horus_test::Other") != std::string::npos
               ? 0
               : 12;
  });
  EXPECT_EQ(wait_for(child), 0);
}

TEST_F(ShmTopic, AnInProcessTopicIsInvisibleToOtherProcesses) {
  const auto name = horus_test::unique_name("inproc");
  auto local = Topic<Stamp>::open(name, horus::TopicOptions{horus::Backend::InProcess, {}, {}});
  ASSERT_TRUE(local);
  EXPECT_EQ(local->backend(), horus::Backend::InProcess);
  const pid_t child = spawn([&] {
    auto other = Topic<horus_test::Other>::open(name);  // no conflict: the name is not on this host's shm
    return other && other->backend() == horus::Backend::SharedMemory ? 0 : 10;
  });
  EXPECT_EQ(wait_for(child), 0);
  auto clash = Topic<Stamp>::open(name, horus::TopicOptions{horus::Backend::SharedMemory, {}, {}});
  ASSERT_FALSE(clash);
  EXPECT_EQ(clash.error().code(), horus::Errc::ConfigMismatch);
}

TEST_F(ShmTopic, HorusBackendSelectsTheBackendAndABadValueIsNamed) {
  ::setenv("HORUS_BACKEND", "inproc", 1);
  Topic<Stamp> a(horus_test::unique_name("env"));
  EXPECT_EQ(a.backend(), horus::Backend::InProcess);
  ::setenv("HORUS_BACKEND", "carrier-pigeon", 1);
  auto bad = Topic<Stamp>::open(horus_test::unique_name("env"));
  ASSERT_FALSE(bad);
  EXPECT_EQ(bad.error().code(), horus::Errc::Config);
  EXPECT_NE(bad.error().message().find("HORUS_BACKEND=carrier-pigeon"), std::string::npos);
  EXPECT_NE(bad.error().message().find("expected auto, shm, inproc, cyclonedds, fastdds or lcm"), std::string::npos);
  ::unsetenv("HORUS_BACKEND");
}

TEST_F(ShmTopic, TwoNamespacesNeverShareATopic) {
  const auto name = horus_test::unique_name("ns");
  ::setenv("HORUS_NAMESPACE", "test_ns_a", 1);
  Topic<Stamp> a(name);
  ::setenv("HORUS_NAMESPACE", "test_ns_b", 1);
  auto b = Topic<horus_test::Other>::open(name);  // same name, other type: no conflict across namespaces
  ::unsetenv("HORUS_NAMESPACE");
  ASSERT_TRUE(b) << b.error().message();
  a.send(Stamp::make(1, 1));
  EXPECT_FALSE(b->recv());
  EXPECT_EQ(a.pub_count(), 1u);
  EXPECT_EQ(b->pub_count(), 0u);  // a's publisher is not on b's topic
  EXPECT_EQ(b->sub_count(), 1u);
}

TEST_F(ShmTopic, HorusShmModeWidensPermissionsAndABadValueIsNamed) {
  const auto name = horus_test::unique_name("mode");
  ::setenv("HORUS_SHM_MODE", "0660", 1);
  auto t = Topic<Stamp>::open(name);
  ::setenv("HORUS_SHM_MODE", "0755", 1);  // execute bits: not for shared memory
  auto bad = Topic<Stamp>::open(horus_test::unique_name("mode"));
  ::setenv("HORUS_SHM_MODE", "0066", 1);  // the owner cannot lock out itself
  auto bad2 = Topic<Stamp>::open(horus_test::unique_name("mode"));
  ::unsetenv("HORUS_SHM_MODE");
  ASSERT_TRUE(t) << t.error().message();
  struct stat st{};
  ASSERT_EQ(::stat(("/dev/shm" + horus::shm::segment_name(*horus::shm::shm_namespace(), name)).c_str(), &st), 0);
  EXPECT_EQ(st.st_mode & 0777, 0660u);
  for (auto* r : {&bad, &bad2}) {
    ASSERT_FALSE(*r);
    EXPECT_EQ(r->error().code(), horus::Errc::Config);
    EXPECT_NE(r->error().message().find("HORUS_SHM_MODE="), std::string::npos) << r->error().message();
  }
}

TEST_F(ShmTopic, ManyPublisherAndSubscriberProcessesEachGetEveryMessageInPublisherOrder) {
  const auto name = horus_test::unique_name("many");
  constexpr int kPublishers = 3, kSubscribers = 3;
  constexpr std::uint64_t kEach = 2000;
  // Creates the segment with room for every message; closed once the subscribers hold it (an
  // idle subscriber would rightly make try_send wait for it).
  auto keep = Topic<Stamp>::with_capacity(name, 8192);
  ASSERT_TRUE(keep);
  std::vector<Pipe> ready(kSubscribers);
  Pipe go;
  std::vector<pid_t> subs;
  for (int s = 0; s < kSubscribers; ++s) {
    subs.push_back(spawn([&, s] {
      Topic<Stamp> sub(name);
      ready[static_cast<std::size_t>(s)].signal();
      std::vector<std::uint64_t> next(kPublishers, 0);
      std::uint64_t total = 0;
      const horus_test::Deadline deadline(std::chrono::seconds(30));
      while (total < kPublishers * kEach && !deadline.expired()) {
        auto m = sub.recv();
        if (!m) continue;
        if (!m->intact() || m->publisher >= kPublishers) return 10;
        if (m->seq != next[m->publisher]) return 11;  // exactly once, in order, per publisher
        ++next[m->publisher];
        ++total;
      }
      return total == kPublishers * kEach && sub.dropped_count() == 0 ? 0 : 12;
    }));
  }
  for (auto& r : ready) ASSERT_TRUE(r.wait());
  keep = horus::Topic<Stamp>::with_capacity(horus_test::unique_name("many_other"), 1);  // closes ours
  std::vector<pid_t> pubs;
  for (int p = 0; p < kPublishers; ++p) {
    pubs.push_back(spawn([&, p] {
      Topic<Stamp> pub(name);
      for (std::uint64_t i = 0; i < kEach; ++i)
        while (!pub.try_send(Stamp::make(static_cast<std::uint32_t>(p), i))) std::this_thread::yield();
      return 0;
    }));
  }
  for (pid_t p : pubs) EXPECT_EQ(wait_for(p), 0);
  for (pid_t s : subs) EXPECT_EQ(wait_for(s), 0);
}

// A publisher killed at a random point of a stream of sends, many times over: the subscriber
// never returns a torn message, and the next publisher continues the topic.
TEST_F(ShmTopic, APublisherKilledWhileSendingNeverDeliversATornMessage) {
  const auto name = horus_test::unique_name("kill");
  auto sub = Topic<Stamp>::with_capacity(name, 64);
  ASSERT_TRUE(sub);
  const int kills = std::getenv("HORUS_KILL_LOOPS") ? std::atoi(std::getenv("HORUS_KILL_LOOPS")) : 25;
  std::uint64_t received = 0;
  for (int k = 0; k < kills; ++k) {
    Pipe started;
    const pid_t child = spawn([&] {
      Topic<Stamp> pub(name);
      started.signal();
      for (std::uint64_t i = 0;; ++i) pub.send(Stamp::make(static_cast<std::uint32_t>(k), i));
      return 0;
    });
    ASSERT_TRUE(started.wait());
    const auto until = std::chrono::steady_clock::now() + std::chrono::microseconds(200 + (k * 397) % 3000);
    while (std::chrono::steady_clock::now() < until) {
      if (auto m = sub->recv()) {
        ASSERT_TRUE(m->intact()) << "torn message in round " << k;
        ++received;
      }
    }
    ::kill(child, SIGKILL);
    ASSERT_EQ(wait_for(child), 128 + SIGKILL);
    while (auto m = sub->recv()) {
      ASSERT_TRUE(m->intact()) << "torn message after the kill in round " << k;
      ++received;
    }
  }
  EXPECT_GT(received, 0u);
  // The dead publishers' lanes are reclaimed: a new publisher gets one and is heard.
  Topic<Stamp> pub(name);
  pub.send(Stamp::make(999, 1));
  std::optional<Stamp> last;
  while (auto m = sub->recv()) last = m;
  ASSERT_TRUE(last);
  EXPECT_EQ(last->publisher, 999u);
}

// -- Event-driven receive between processes (doorbell.hpp) -----------------------------------

// Bounded wait until a condition holds (a publisher waits for the other process to be asleep).
template <class P>
bool eventually(P pred, std::chrono::milliseconds limit) {
  const horus_test::Deadline d(limit);
  while (!pred()) {
    if (d.expired()) return false;
    std::this_thread::sleep_for(std::chrono::microseconds(100));
  }
  return true;
}

// The two classes of waiters: a ring for handles only (what a fleet bridge imports) leaves a
// bridge's export thread asleep, a ring for all wakes it; a handle wakes for either.
TEST(Doorbell, AHandlesOnlyRingLeavesTheBridgeClassAsleepAndAFullRingWakesIt) {
  using horus::shm::Doorbell;
  using namespace std::chrono_literals;
  for (const std::uint32_t armed : {Doorbell::kArmedBridge, Doorbell::kArmedReader}) {
    Doorbell bell;
    bell.process_private = 1;
    // The predicate counts its calls: wait_any looks before arming, after arming, and again
    // when its first slice (kFirstSlice) ends; the third look means it sleeps till the deadline.
    struct Ready {
      std::atomic<bool> flag{false};
      mutable std::atomic<int> looks{0};
    } state;
    std::atomic<bool> done{false};
    const horus::shm::WaitItem item{&bell, nullptr,
                                    [](const void* c) noexcept {
                                      const auto& r = *static_cast<const Ready*>(c);
                                      r.looks.fetch_add(1);
                                      return r.flag.load();
                                    },
                                    &state, armed};
    bool ready = false;
    std::thread waiter([&] {
      ready = horus::shm::wait_any({&item, 1}, std::chrono::steady_clock::now() + 5s);
      done = true;
    });
    // Asleep past its first slice, armed with its class's bit.
    ASSERT_TRUE(eventually([&] { return state.looks.load() >= 3 && (bell.word.load() & armed) != 0; }, 2000ms));
    state.flag = true;
    const bool rang = horus::shm::ring_doorbell(bell, Doorbell::kArmedReader);
    if (armed == Doorbell::kArmedBridge) {
      EXPECT_FALSE(rang) << "a handles-only ring found the bridge class armed";
      // Nothing may happen: only a window of time can show it (the waiter sleeps till 5 s).
      std::this_thread::sleep_for(200ms);
      EXPECT_FALSE(done.load()) << "a handles-only ring woke a waiter of the bridge class";
      EXPECT_TRUE(horus::shm::ring_doorbell(bell)) << "the bridge class was not armed any more";
    } else {
      EXPECT_TRUE(rang);
    }
    EXPECT_TRUE(eventually([&] { return done.load(); }, 2000ms)) << "the waiter was not woken";
    waiter.join();
    EXPECT_TRUE(ready);
  }
}

TEST_F(ShmTopic, AProcessBlockedInRecvForIsWokenByEachOfAHundredSendsExactly) {
  const auto name = horus_test::unique_name("wake");
  Pipe ready;
  const pid_t child = spawn([&] {
    Topic<Stamp> sub(name);
    ready.signal();
    for (std::uint64_t i = 0; i < 100; ++i) {
      auto m = sub.recv_for(std::chrono::seconds(10));
      if (!m) return 3;                           // a wake-up was lost
      if (m->seq != i || !m->intact()) return 4;  // out of order or torn
    }
    return sub.recv_for(std::chrono::milliseconds(50)) ? 5 : 0;  // 5: more than 100
  });
  ASSERT_TRUE(ready.wait());
  Topic<Stamp> pub(name);
  int slept = 0;
  for (std::uint64_t i = 0; i < 100; ++i) {
    // The receiver sleeps in the kernel before each message: every one is a real wake-up.
    if (eventually([&] { return pub.waiter_count() == 1; }, std::chrono::milliseconds(2000))) ++slept;
    pub.send(Stamp::make(1, i));
  }
  EXPECT_EQ(wait_for(child), 0);
  EXPECT_GE(slept, 95) << "the receiver was seldom blocked: the test did not test wake-ups";
  EXPECT_EQ(pub.waiter_count(), 0u);
}

TEST_F(ShmTopic, AWaiterKilledWhileBlockedLeavesNoRegistrationBehind) {
  const auto name = horus_test::unique_name("killedwaiter");
  Topic<horus::msg::CmdVel> pub(name);
  Pipe ready;
  const pid_t child = spawn([&] {
    Topic<horus::msg::CmdVel> sub(name);
    ready.signal();
    (void)sub.recv_for(std::chrono::seconds(60));
    return 0;
  });
  ASSERT_TRUE(ready.wait());
  ASSERT_TRUE(eventually([&] { return pub.waiter_count() == 1; }, std::chrono::milliseconds(10000)));
  ::kill(child, SIGKILL);
  EXPECT_EQ(wait_for(child), 128 + SIGKILL);
  // The first send wakes nobody (and disarms); the count is taken back by the sends that keep
  // finding it registered and unarmed (kStaleCheck), without a syscall each.
  for (std::uint32_t i = 0; i <= horus::shm::kStaleCheck + 1 && pub.waiter_count() != 0; ++i)
    pub.send(horus::msg::CmdVel::make(1.0f, 0.0f));
  EXPECT_EQ(pub.waiter_count(), 0u);
  // A new waiter is woken as before.
  Topic<horus::msg::CmdVel> sub(name);
  std::thread t([&] {
    eventually([&] { return pub.waiter_count() == 1; }, std::chrono::milliseconds(5000));
    pub.send(horus::msg::CmdVel::make(2.0f, 0.0f));
  });
  auto m = sub.recv_for(std::chrono::seconds(10));
  t.join();
  ASSERT_TRUE(m);
  EXPECT_FLOAT_EQ(m->linear, 2.0f);
}

TEST_F(ShmTopic, APublisherKilledNeverKeepsAWaiterPastItsTimeout) {
  const auto name = horus_test::unique_name("killedpub");
  Topic<horus::msg::CmdVel> sub(name);
  Pipe ready;
  const pid_t child = spawn([&] {
    Topic<horus::msg::CmdVel> pub(name);
    pub.send(horus::msg::CmdVel::make(1.0f, 0.0f));
    ready.signal();
    for (int i = 0; i < 600; ++i) std::this_thread::sleep_for(std::chrono::milliseconds(100));  // until killed
    return 0;
  });
  ASSERT_TRUE(ready.wait());
  ASSERT_TRUE(sub.recv_for(std::chrono::seconds(10)));
  std::thread killer([&] {
    eventually([&] { return sub.waiter_count() == 1; }, std::chrono::milliseconds(5000));
    ::kill(child, SIGKILL);
  });
  const auto t0 = std::chrono::steady_clock::now();
  EXPECT_FALSE(sub.recv_for(std::chrono::milliseconds(300)));
  const auto took = std::chrono::steady_clock::now() - t0;
  killer.join();
  EXPECT_EQ(wait_for(child), 128 + SIGKILL);
  EXPECT_GE(took, std::chrono::milliseconds(300));
  EXPECT_LT(took, std::chrono::seconds(3));
}

}  // namespace
