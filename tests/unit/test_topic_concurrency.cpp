// Topic<T> across threads: many publishers and subscribers under contention.
// These tests also run under ThreadSanitizer (the `tsan` preset, label `concurrency`).
// Every loop is bounded by a deadline: a bug makes a test fail, never hang.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <optional>
#include <cstdlib>
#include <string>
#include <chrono>
#include <thread>
#include <vector>

#include "horus/fleet.hpp"
#include "horus/msg/geometry.hpp"
#include "horus/topic.hpp"
#include "log_capture.hpp"
#include "test_support.hpp"

using horus::Topic;
using horus_test::Deadline;
using horus_test::Stamp;
using horus_test::unique_name;
using namespace std::chrono_literals;

namespace {

constexpr auto kTestBudget = std::chrono::milliseconds(60000);

// Sanitizer builds run 5-20x slower: they check the same interleavings on fewer messages.
#if defined(__SANITIZE_THREAD__) || defined(__SANITIZE_ADDRESS__)
constexpr std::uint64_t kScale = 4;
#else
constexpr std::uint64_t kScale = 1;
#endif

struct SubscriberReport {
  std::uint64_t received = 0;
  std::uint64_t dropped = 0;
  std::uint64_t torn = 0;
  std::uint64_t out_of_order = 0;  // a message older than or equal to one already seen from its publisher
  bool timed_out = false;
};

// Receives until all publishers are done and nothing is left; checks integrity and
// per-publisher order.
SubscriberReport run_subscriber(Topic<Stamp>& sub, std::uint32_t pubs, const std::atomic<int>& publishers_done) {
  SubscriberReport rep;
  std::vector<std::int64_t> last(pubs, -1);
  Deadline deadline(kTestBudget);
  for (;;) {
    if (auto m = sub.recv()) {
      if (!m->intact() || m->publisher >= pubs) {
        ++rep.torn;
        continue;
      }
      if (static_cast<std::int64_t>(m->seq) <= last[m->publisher]) ++rep.out_of_order;
      last[m->publisher] = static_cast<std::int64_t>(m->seq);
      ++rep.received;
      continue;
    }
    // Empty: finished once all publishers are done and nothing is left.
    if (publishers_done.load(std::memory_order_acquire) == static_cast<int>(pubs) && !sub.has_message()) break;
    if (deadline.expired()) {
      rep.timed_out = true;
      break;
    }
    std::this_thread::yield();
  }
  rep.dropped = sub.dropped_count();
  return rep;
}

void run(std::uint32_t pubs, std::uint32_t subs, std::uint64_t per_pub, std::uint32_t capacity, bool blocking) {
  const auto name = unique_name(blocking ? "contention_blocking" : "contention_overwrite");
  std::vector<Topic<Stamp>> sub_handles;
  for (std::uint32_t s = 0; s < subs; ++s) {
    auto t = Topic<Stamp>::with_capacity(name, capacity);
    ASSERT_TRUE(t) << t.error().message();
    sub_handles.push_back(std::move(*t));
  }
  std::atomic<int> publishers_done{0};
  std::atomic<std::uint64_t> blocking_timeouts{0};
  std::vector<SubscriberReport> reports(subs);
  std::vector<std::thread> threads;
  for (std::uint32_t s = 0; s < subs; ++s)
    threads.emplace_back([&, s] { reports[s] = run_subscriber(sub_handles[s], pubs, publishers_done); });
  for (std::uint32_t p = 0; p < pubs; ++p) {
    threads.emplace_back([&, p] {
      Topic<Stamp> pub(name);
      for (std::uint64_t i = 0; i < per_pub; ++i) {
        if (blocking) {
          if (!pub.send_blocking(Stamp::make(p, i), 20s)) blocking_timeouts.fetch_add(1);
        } else {
          pub.send(Stamp::make(p, i));
        }
      }
      publishers_done.fetch_add(1, std::memory_order_release);
    });
  }
  for (auto& t : threads) t.join();

  const std::uint64_t sent = static_cast<std::uint64_t>(pubs) * per_pub;
  EXPECT_EQ(blocking_timeouts.load(), 0u);
  for (std::uint32_t s = 0; s < subs; ++s) {
    SCOPED_TRACE("subscriber " + std::to_string(s));
    const auto& r = reports[s];
    EXPECT_FALSE(r.timed_out);
    EXPECT_EQ(r.torn, 0u);
    EXPECT_EQ(r.out_of_order, 0u);
    // Nothing is silently lost: every message was either received or counted as dropped.
    EXPECT_EQ(r.received + r.dropped, sent);
    if (blocking) {
      EXPECT_EQ(r.dropped, 0u);
    }
  }
}

}  // namespace

TEST(TopicConcurrency, WithBlockingSendsEveryMessageArrivesExactlyOnceAndInOrderPerPublisher) {
  run(/*pubs=*/4, /*subs=*/3, /*per_pub=*/100000 / kScale, /*capacity=*/64, /*blocking=*/true);
}

TEST(TopicConcurrency, WithOverwritingSendsEveryMessageIsReceivedOrCountedAsDroppedNeverTornOrReordered) {
  run(/*pubs=*/4, /*subs=*/3, /*per_pub=*/200000 / kScale, /*capacity=*/8, /*blocking=*/false);
}

TEST(TopicConcurrency, ASinglePublisherAndSubscriberOnTwoThreadsLoseNothingWithBlockingSends) {
  run(/*pubs=*/1, /*subs=*/1, /*per_pub=*/1000000 / kScale, /*capacity=*/256, /*blocking=*/true);
}

TEST(TopicConcurrency, ReadLatestNeverReturnsATornMessageWhileAPublisherOverwrites) {
  const auto name = unique_name("latest_race");
  auto reader = Topic<Stamp>::with_capacity(name, 2);
  ASSERT_TRUE(reader);
  std::atomic<bool> stop{false};
  std::thread writer([&] {
    Topic<Stamp> pub(name);
    Deadline deadline(kTestBudget);
    for (std::uint64_t i = 0; !stop.load(std::memory_order_relaxed) && !deadline.expired(); ++i)
      pub.send(Stamp::make(1, i));
  });
  std::uint64_t seen = 0, torn = 0, backwards = 0, last = 0;
  Deadline deadline(5s);
  while (seen < 200000 && !deadline.expired()) {
    if (auto m = reader->read_latest()) {
      if (!m->intact()) ++torn;
      if (m->seq < last) ++backwards;
      last = m->seq;
      ++seen;
    }
  }
  stop = true;
  writer.join();
  EXPECT_GT(seen, 0u);
  EXPECT_EQ(torn, 0u);
  EXPECT_EQ(backwards, 0u);
}

TEST(TopicConcurrency, HandlesOpenAndCloseWhilePublishersSend) {
  const auto name = unique_name("churn");
  Topic<Stamp> probe(name);  // keeps the topic alive for the whole test
  std::atomic<bool> stop{false};
  std::atomic<std::uint64_t> torn{0}, received{0};
  std::atomic<bool> publishing{false};
  std::thread pub_thread([&] {
    Topic<Stamp> pub(name);
    Deadline deadline(kTestBudget);
    for (std::uint64_t i = 0; !stop.load() && !deadline.expired(); ++i) {
      pub.send(Stamp::make(0, i));
      if (i == 0) {
        publishing = true;
        publishing.notify_all();
      }
    }
    publishing = true;  // also when the budget ran out before a send
    publishing.notify_all();
  });
  // The churn starts once the publisher sends (on a loaded machine its thread may start late).
  publishing.wait(false);
  std::vector<std::thread> churners;
  for (int c = 0; c < 2; ++c) {
    churners.emplace_back([&] {
      for (int k = 0; k < 300; ++k) {
        Topic<Stamp> sub(name);
        for (int j = 0; j < 50; ++j) {
          if (auto m = sub.recv()) {
            received.fetch_add(1);
            if (!m->intact()) torn.fetch_add(1);
          }
        }
      }
    });
  }
  for (auto& t : churners) t.join();
  EXPECT_EQ(probe.sub_count(), 1u);  // every churned subscription was released; only the probe is left
  stop = true;
  pub_thread.join();
  EXPECT_EQ(torn.load(), 0u);
  EXPECT_EQ(probe.pub_count(), 0u);  // the publisher's lane was released
  EXPECT_GT(probe.metrics().topic_messages_sent(), 0u);
}

TEST(TopicConcurrency, ReadLatestWithTwoPublishersNeverGoesBackInTimePerPublisher) {
  const auto name = unique_name("latest_two");
  auto reader = Topic<Stamp>::with_capacity(name, 4);
  ASSERT_TRUE(reader);
  std::atomic<bool> stop{false};
  std::vector<std::thread> writers;
  for (std::uint32_t p = 0; p < 2; ++p) {
    writers.emplace_back([&, p] {
      Topic<Stamp> pub(name);
      Deadline deadline(kTestBudget);
      for (std::uint64_t i = 0; !stop.load(std::memory_order_relaxed) && !deadline.expired(); ++i)
        pub.send(Stamp::make(p, i));
    });
  }
  std::uint64_t seen = 0, torn = 0, backwards = 0;
  std::int64_t last[2] = {-1, -1};
  Deadline deadline(3s);
  while (seen < 100000 && !deadline.expired()) {
    if (auto m = reader->read_latest()) {
      if (!m->intact() || m->publisher > 1) {
        ++torn;
        continue;
      }
      if (static_cast<std::int64_t>(m->seq) < last[m->publisher]) ++backwards;
      last[m->publisher] = static_cast<std::int64_t>(m->seq);
      ++seen;
    }
  }
  stop = true;
  for (auto& w : writers) w.join();
  EXPECT_GT(seen, 0u);
  EXPECT_EQ(torn, 0u);
  EXPECT_EQ(backwards, 0u);
}

// The host's fleet state (the agent, its view, the bridges' boards) lives in shared memory under
// HORUS_NAMESPACE. Other test processes of this host run fleet topics at the same time with their
// own settings (another heartbeat period, another LCM URL): a namespace of this process keeps
// theirs out of this test (seen: this host's period read as another process's 100 ms).
static void isolate_fleet_state() { ::setenv("HORUS_NAMESPACE", ("tc" + std::to_string(::getpid())).c_str(), 1); }

// A fleet topic (LCM over udpm with ttl=0: multicast loopback, nothing leaves the host) with its
// bridge running: the bridge's thread exports every message of two publishing threads while a
// subscribing thread reads them from the ring, and LCM loops every exported message back to
// the bridge, which recognizes it as its own (the echo ledger): each message arrives exactly
// once, in order per publisher. Under TSan this checks the export thread, the transport's
// thread and the user threads against each other. (Not memq://: liblcm's in-process queue
// synchronizes with glib locks TSan cannot see, so it would report liblcm's own accesses.)
TEST(TopicConcurrency, AFleetTopicsBridgeExportsEveryMessageOnceWhileThreadsPublishAndRead) {
  if (!horus::backend_available(horus::Backend::Lcm)) GTEST_SKIP() << "this build has no lcm backend";
  const int port = 20000 + static_cast<int>((::getpid() * 11 + 3) % 40000);
  isolate_fleet_state();
  ::setenv("HORUS_LCM_URL", ("udpm://239.255.76.67:" + std::to_string(port) + "?ttl=0&recv_buf_size=4194304").c_str(), 1);
  horus::TopicOptions fleet;
  fleet.backend = horus::Backend::Lcm;
  fleet.capacity = 1024;
  const auto name = unique_name("conc.fleet");
  auto opened = Topic<Stamp>::open(name, fleet);
  if (!opened && opened.error() == horus::Errc::Io) GTEST_SKIP() << "udpm is not available here: " << opened.error().message();
  ASSERT_TRUE(opened) << opened.error().message();
  auto sub = std::move(*opened);
  constexpr std::uint64_t kPerPublisher = 2000 / kScale;
  std::vector<std::thread> pubs;
  for (std::uint32_t p = 0; p < 2; ++p)
    pubs.emplace_back([&, p] {
      auto pub = Topic<Stamp>::open(name, fleet).value();
      for (std::uint64_t i = 0; i < kPerPublisher; ++i) {
        ASSERT_TRUE(pub.send_blocking(Stamp::make(p, i), 5s)) << i;  // the bridge is a subscriber too
      }
    });
  std::uint64_t next[2] = {0, 0}, received = 0, wrong = 0;
  const Deadline d(kTestBudget);
  while (received < 2 * kPerPublisher && !d.expired()) {
    if (auto m = sub.recv_for(100ms)) {
      ++received;
      const auto p = m->publisher % 2;
      if (m->seq != next[p]) ++wrong;
      next[p] = m->seq + 1;
    }
  }
  for (auto& t : pubs) t.join();
  EXPECT_EQ(received, 2 * kPerPublisher);
  EXPECT_EQ(wrong, 0u) << "a message out of order or twice";
  std::this_thread::sleep_for(100ms);
  EXPECT_FALSE(sub.recv()) << "a message came back through the transport";
  EXPECT_EQ(sub.dropped_count(), 0u);
}

// The fleet layer in one process (LCM udpm, ttl=0): a fleet topic starts the process's agent,
// which holds the host's bridge and announces the host; a horus::Fleet on its own thread sees
// this host alive, announced with the topic and its type's signature, while another thread
// publishes. Under TSan this checks the agent's thread, the Fleet's executor thread, the
// transport's thread and the user's threads against each other.
TEST(TopicConcurrency, AProcessWithAFleetTopicAnnouncesItsHostToAFleetOnAnotherThread) {
  if (!horus::backend_available(horus::Backend::Lcm)) GTEST_SKIP() << "this build has no lcm backend";
  const int port = 20000 + static_cast<int>((::getpid() * 13 + 5) % 40000);
  isolate_fleet_state();
  ::setenv("HORUS_LCM_URL", ("udpm://239.255.76.67:" + std::to_string(port) + "?ttl=0").c_str(), 1);
  ::setenv("HORUS_FLEET_HEARTBEAT_MS", "20", 1);
  horus::TopicOptions fleet;
  fleet.backend = horus::Backend::Lcm;
  const auto name = unique_name("conc.announced");
  auto opened = Topic<Stamp>::open(name, fleet);
  if (!opened && opened.error() == horus::Errc::Io) GTEST_SKIP() << "udpm is not available here: " << opened.error().message();
  ASSERT_TRUE(opened) << opened.error().message();
  std::atomic<bool> stop{false};
  std::thread pub([&] {
    auto p = Topic<Stamp>::open(name, fleet).value();
    for (std::uint64_t i = 0; !stop.load(); ++i) {
      p.send(Stamp::make(0, i));
      std::this_thread::sleep_for(1ms);
    }
  });
  horus::FleetOptions options;
  options.transport = "lcm";
  auto f = horus::Fleet::open(options);
  ASSERT_TRUE(f) << f.error().message();
  std::atomic<int> events{0};
  (*f)->on_change([&](const horus::FleetEvent&) { events.fetch_add(1); });
  // The Fleet's thread may have reported this host (joined, its topics) before the callback
  // was registered: a topic opened now changes the host's announcement once more, after it.
  auto later = Topic<Stamp>::open(unique_name("conc.announced_later"), fleet);
  ASSERT_TRUE(later) << later.error().message();
  std::optional<horus::FleetHost> self;
  const auto deadline = std::chrono::steady_clock::now() + 10s;
  while (std::chrono::steady_clock::now() < deadline) {
    self = (*f)->host(horus::fleet::host_name());
    if (self && self->announced && self->heartbeats >= 5 && events.load() >= 1 &&
        std::any_of(self->topics.begin(), self->topics.end(), [&](const auto& t) { return t.name == name; }))
      break;
    std::this_thread::sleep_for(10ms);
  }
  stop.store(true);
  pub.join();
  ASSERT_TRUE(self.has_value()) << "this host was never seen";
  EXPECT_TRUE(self->self);
  EXPECT_EQ(self->id, (*f)->self_id());
  EXPECT_EQ(self->state, horus::HostState::Alive);
  EXPECT_EQ(self->period, 20ms);
  EXPECT_GE(self->heartbeats, 5u);
  const auto t = std::find_if(self->topics.begin(), self->topics.end(), [&](const auto& x) { return x.name == name; });
  ASSERT_NE(t, self->topics.end()) << "the topic was never announced";
  EXPECT_EQ(t->scope, "fleet");
  EXPECT_EQ(t->transport, "lcm");
  EXPECT_EQ(t->type_hash, horus::type_hash<Stamp>);
  EXPECT_EQ(t->signature, horus::reflect::type_signature<Stamp>());
  EXPECT_FALSE(std::any_of(self->topics.begin(), self->topics.end(),
                           [](const auto& x) { return x.name.starts_with("horus.fleet."); }));
  EXPECT_GE(events.load(), 1);  // joined (and changed) arrived on the Fleet's thread
  EXPECT_EQ((*f)->malformed(), 0u);
  ::unsetenv("HORUS_FLEET_HEARTBEAT_MS");
}

// Verbose handles of one topic on several threads share the topic's limit on lines: every send
// is a line or counted as held back, whichever thread made it.
TEST(TopicConcurrency, VerboseHandlesOnManyThreadsShareTheTopicsLimit) {
  horus_test::LogCapture log;
  const std::string name = unique_name("verbose");
  constexpr int kThreads = 4;
  const std::uint64_t kSends = 20000 / kScale;
  {
    horus::TopicOptions o;
    o.backend = horus::Backend::InProcess;
    o.verbose = true;
    o.log_rate_hz = 50;
    auto keep = Topic<horus::msg::CmdVel>::open(name, o);  // the topic stays open until all are done
    ASSERT_TRUE(keep);
    std::vector<std::thread> threads;
    std::atomic<int> failed{0};
    for (int t = 0; t < kThreads; ++t) {
      threads.emplace_back([&, t] {
        auto pub = Topic<horus::msg::CmdVel>::open(name, o);
        if (!pub) {
          ++failed;
          return;
        }
        for (std::uint64_t i = 0; i < kSends; ++i) pub->send(horus::msg::CmdVel::make(static_cast<float>(t), 0.0f));
      });
    }
    for (auto& th : threads) th.join();
    ASSERT_EQ(failed.load(), 0);
  }
  const auto c = horus_test::count_traffic(log, name);
  EXPECT_GE(c.sends, 50u) << log.text();
  EXPECT_EQ(c.sends + c.held_in_lines + c.held_at_close, kThreads * kSends) << log.text();
  EXPECT_EQ(c.held_in_lines + c.held_at_close, c.held_in_all);
}
