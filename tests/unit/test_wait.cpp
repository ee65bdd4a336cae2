// Event-driven receive in one process: recv_for / wait_for, WaitSet and Trigger, Executor.
// Threads wait and wake each other here (label concurrency: the TSan pass runs these); the
// cross-process cases are in integration/test_shm_topic.cpp, DDS and LCM in their topic tests.
#include <gtest/gtest.h>
#include <pthread.h>
#include <signal.h>

#include <atomic>
#include <chrono>
#include <stdexcept>
#include <thread>
#include <vector>

#include "horus/executor.hpp"
#include "horus/msg/geometry.hpp"
#include "horus/msg/image.hpp"
#include "horus/msg/sensor.hpp"
#include "horus/topic.hpp"
#include "horus/waitset.hpp"
#include "test_support.hpp"

namespace {

using namespace std::chrono_literals;
using horus::Backend;
using horus::msg::CmdVel;
using horus::msg::Pose2D;
using Clock = std::chrono::steady_clock;

horus::TopicOptions on(Backend b) {
  horus::TopicOptions o;
  o.backend = b;
  return o;
}

template <class T>
horus::Topic<T> open(const std::string& name, Backend b) {
  auto t = horus::Topic<T>::open(name, on(b));
  if (!t) throw std::runtime_error(t.error().message());
  return std::move(*t);
}

// Spins (bounded) until `pred` holds: a helper thread waits for a waiter to be asleep.
template <class P>
bool eventually(P pred, std::chrono::milliseconds limit = 5000ms) {
  horus_test::Deadline d(limit);
  while (!pred()) {
    if (d.expired()) return false;
    std::this_thread::sleep_for(100us);
  }
  return true;
}

class Wait : public ::testing::TestWithParam<Backend> {
 protected:
  void SetUp() override { ::unsetenv("HORUS_BACKEND"); }
  std::string name(const char* base) { return horus_test::unique_name(base); }
};

TEST_P(Wait, RecvForReturnsAMessageAlreadyWaitingEvenWithAZeroOrNegativeTimeout) {
  const auto n = name("ready");
  auto sub = open<CmdVel>(n, GetParam());
  auto pub = open<CmdVel>(n, GetParam());
  pub.send(CmdVel::make(1.0f, 0.0f));
  pub.send(CmdVel::make(2.0f, 0.0f));
  auto a = sub.recv_for(0ns);
  ASSERT_TRUE(a);
  EXPECT_FLOAT_EQ(a->linear, 1.0f);
  EXPECT_TRUE(sub.wait_for(-5ms));
  auto b = sub.recv_for(-1s);
  ASSERT_TRUE(b);
  EXPECT_FLOAT_EQ(b->linear, 2.0f);
  EXPECT_FALSE(sub.recv_for(0ns));
  EXPECT_FALSE(sub.wait_for(-1ns));
  EXPECT_EQ(sub.waiter_count(), 0u);
}

TEST_P(Wait, RecvForTimesOutWhenNothingComesAndNeverReturnsEarly) {
  auto sub = open<CmdVel>(name("timeout"), GetParam());
  const auto t0 = Clock::now();
  EXPECT_FALSE(sub.recv_for(30ms));
  const auto took = Clock::now() - t0;
  EXPECT_GE(took, 30ms);
  EXPECT_LT(took, 2s);
  EXPECT_FALSE(sub.wait_for(10ms));
  EXPECT_EQ(sub.waiter_count(), 0u) << "a wait that ended left its registration behind";
  EXPECT_EQ(sub.metrics().recv_failures(), 1u);
}

TEST_P(Wait, ABlockedRecvForWakesWhenAnotherThreadSends) {
  const auto n = name("wake");
  auto sub = open<CmdVel>(n, GetParam());
  std::thread t([&] {
    auto pub = open<CmdVel>(n, GetParam());
    // Wait until the receiver is asleep: the wake-up must come from the send.
    EXPECT_TRUE(eventually([&] { return pub.waiter_count() == 1; }));
    pub.send(CmdVel::make(3.5f, 0.0f));
  });
  const auto t0 = Clock::now();
  auto m = sub.recv_for(10s);
  const auto took = Clock::now() - t0;
  t.join();
  ASSERT_TRUE(m);
  EXPECT_FLOAT_EQ(m->linear, 3.5f);
  EXPECT_LT(took, 5s);
  EXPECT_EQ(sub.waiter_count(), 0u);
}

TEST_P(Wait, WaitForSaysAMessageArrivedWithoutTakingIt) {
  const auto n = name("waitfor");
  auto sub = open<Pose2D>(n, GetParam());
  std::thread t([&] {
    auto pub = open<Pose2D>(n, GetParam());
    EXPECT_TRUE(eventually([&] { return pub.waiter_count() == 1; }));
    pub.send(Pose2D{7.0, 0.0, 0.0, 0});
  });
  EXPECT_TRUE(sub.wait_for(10s));
  t.join();
  EXPECT_TRUE(sub.wait_for(0ns));
  auto m = sub.recv();
  ASSERT_TRUE(m);
  EXPECT_DOUBLE_EQ(m->x, 7.0);
}

TEST_P(Wait, OneSendWakesEveryWaiterOfTheTopic) {
  const auto n = name("many");
  constexpr int kWaiters = 3;
  std::vector<horus::Topic<CmdVel>> subs;
  for (int i = 0; i < kWaiters; ++i) subs.push_back(open<CmdVel>(n, GetParam()));
  std::atomic<int> got{0};
  std::vector<std::thread> threads;
  for (auto& s : subs)
    threads.emplace_back([&s, &got] {
      if (auto m = s.recv_for(10s); m && m->linear == 9.0f) got.fetch_add(1);
    });
  auto pub = open<CmdVel>(n, GetParam());
  EXPECT_TRUE(eventually([&] { return pub.waiter_count() == kWaiters; }));
  pub.send(CmdVel::make(9.0f, 0.0f));
  for (auto& t : threads) t.join();
  EXPECT_EQ(got.load(), kWaiters);
  EXPECT_EQ(pub.waiter_count(), 0u);
}

TEST_P(Wait, AHundredSleepingWakeUpsAreCountedExactlyAndInOrder) {
  const auto n = name("hundred");
  auto sub = open<Pose2D>(n, GetParam());
  std::thread t([&] {
    auto pub = open<Pose2D>(n, GetParam());
    for (int i = 0; i < 100; ++i) {
      // Each message finds the receiver asleep (or about to be).
      eventually([&] { return pub.waiter_count() == 1; }, 200ms);
      pub.send(Pose2D{static_cast<double>(i), 0.0, 0.0, 0});
    }
  });
  int received = 0;
  bool in_order = true;
  while (received < 100) {
    auto m = sub.recv_for(5s);
    if (!m) break;
    in_order = in_order && m->x == received;
    ++received;
  }
  t.join();
  EXPECT_EQ(received, 100);
  EXPECT_TRUE(in_order);
  EXPECT_FALSE(sub.recv_for(10ms)) << "more than 100 messages";
}

TEST_P(Wait, SerializedAndLargeDataTopicsWakeTheirWaitersToo) {
  const auto n1 = name("ser");
  const auto n2 = name("img");
  auto ser = open<horus_test::Stamp>(n1, GetParam());
  auto img = open<horus::msg::Image>(n2, GetParam());
  std::thread t([&] {
    auto p1 = open<horus_test::Stamp>(n1, GetParam());
    auto p2 = open<horus::msg::Image>(n2, GetParam());
    EXPECT_TRUE(eventually([&] { return p1.waiter_count() == 1; }));
    p1.send(horus_test::Stamp::make(1, 5));
    EXPECT_TRUE(eventually([&] { return p2.waiter_count() == 1; }));
    auto loan = p2.loan(*horus::msg::Image::describe(4, 4, horus::msg::ImageEncoding::Rgb8));
    ASSERT_TRUE(loan);
    (*loan)->data_mut()[0] = 77;
    p2.send(std::move(*loan));
  });
  auto s = ser.recv_for(10s);
  ASSERT_TRUE(s);
  EXPECT_TRUE(s->intact());
  auto i = img.recv_for(10s);
  t.join();
  ASSERT_TRUE(i);
  EXPECT_EQ(i->data()[0], 77);
}

INSTANTIATE_TEST_SUITE_P(Backends, Wait, ::testing::Values(Backend::InProcess, Backend::SharedMemory),
                         [](const auto& p) { return std::string(p.param == Backend::InProcess ? "InProcess" : "SharedMemory"); });

// -- WaitSet and Trigger ------------------------------------------------------

class WaitSetTest : public ::testing::Test {
 protected:
  void SetUp() override { ::unsetenv("HORUS_BACKEND"); }
};

TEST_F(WaitSetTest, TellsWhichOfSeveralTopicsOfDifferentTypesAreReady) {
  const auto a = horus_test::unique_name("ws.a");
  const auto b = horus_test::unique_name("ws.b");
  const auto c = horus_test::unique_name("ws.c");
  horus::Topic<CmdVel> ta(a);
  horus::Topic<Pose2D> tb(b);
  horus::Topic<horus_test::Stamp> tc(c);
  horus::WaitSet ws;
  const auto ia = ws.attach(ta);
  const auto ib = ws.attach(tb);
  const auto ic = ws.attach(tc);
  EXPECT_EQ(ws.size(), 3u);
  EXPECT_TRUE(ws.wait(0ns).timed_out());
  EXPECT_TRUE(ws.wait(20ms).timed_out());

  std::thread t([&] {
    horus::Topic<Pose2D> pb(b);
    horus::Topic<horus_test::Stamp> pc(c);
    EXPECT_TRUE(eventually([&] { return pb.waiter_count() == 1 && pc.waiter_count() == 1; }));
    pb.send(Pose2D{1.0, 2.0, 3.0, 0});
  });
  const auto r = ws.wait(10s);
  t.join();
  EXPECT_FALSE(r.timed_out());
  EXPECT_TRUE(r.contains(ib));
  EXPECT_FALSE(r.contains(ia));
  EXPECT_FALSE(r.contains(ic));
  // A level: still ready until the message is taken.
  EXPECT_TRUE(ws.wait(0ns).contains(ib));
  ASSERT_TRUE(tb.recv());
  EXPECT_TRUE(ws.wait(0ns).timed_out());
}

TEST_F(WaitSetTest, ATriggerWakesAWaitFromAnotherThreadAndStaysReadyUntilReset) {
  horus::Topic<CmdVel> topic(horus_test::unique_name("ws.trig"));
  horus::Trigger trigger;
  horus::WaitSet ws;
  ws.attach(topic);
  const auto it = ws.attach(trigger);
  std::thread t([trigger]() mutable {  // a copy fires the same trigger
    std::this_thread::sleep_for(20ms);
    trigger.fire();
  });
  const auto r = ws.wait(10s);
  t.join();
  EXPECT_TRUE(r.contains(it));
  EXPECT_TRUE(trigger.fired());
  EXPECT_TRUE(ws.wait(0ns).contains(it));
  trigger.reset();
  EXPECT_TRUE(ws.wait(5ms).timed_out());
}

TEST_F(WaitSetTest, DetachingDuringAWaitTakesEffectAtOnce) {
  const auto n = horus_test::unique_name("ws.detach");
  horus::Topic<CmdVel> topic(n);
  horus::Trigger later;
  horus::WaitSet ws;
  const auto id = ws.attach(topic);
  ws.attach(later);
  std::atomic<bool> done{false};
  horus::WaitSet::Result r;
  std::thread waiter([&] {
    r = ws.wait(10s);
    done = true;
  });
  EXPECT_TRUE(eventually([&] { return topic.waiter_count() == 1; }));
  EXPECT_TRUE(ws.detach(id));
  EXPECT_FALSE(ws.detach(id));
  // The wait took the new list: the detached topic no longer holds it...
  EXPECT_TRUE(eventually([&] { return topic.waiter_count() == 0; }));
  horus::Topic<CmdVel> pub(n);
  pub.send(CmdVel::make(1.0f, 0.0f));
  std::this_thread::sleep_for(20ms);
  EXPECT_FALSE(done.load()) << "a detached topic woke the wait set";
  later.fire();  // ...and the rest still wakes it
  waiter.join();
  EXPECT_EQ(r.ready.size(), 1u);
  EXPECT_FALSE(r.contains(id));
}

TEST_F(WaitSetTest, ATopicHandleDestroyedWhileAttachedDetachesItself) {
  const auto n = horus_test::unique_name("ws.gone");
  horus::WaitSet ws;
  horus::Trigger t;
  ws.attach(t);
  {
    horus::Topic<CmdVel> topic(n);
    ws.attach(topic);
    EXPECT_EQ(ws.size(), 2u);
    horus::Topic<CmdVel> moved(std::move(topic));  // a moved handle stays attached
    EXPECT_EQ(ws.size(), 2u);
    horus::Topic<CmdVel> pub(n);
    pub.send(CmdVel::make(1.0f, 0.0f));
    EXPECT_EQ(ws.wait(0ns).ready.size(), 1u);
  }
  EXPECT_EQ(ws.size(), 1u);
  horus::Topic<CmdVel> pub(n);
  pub.send(CmdVel::make(1.0f, 0.0f));
  EXPECT_TRUE(ws.wait(10ms).timed_out());
}

TEST_F(WaitSetTest, DestroyingAWaitSetWakesItsWaitersWithClosed) {
  auto ws = std::make_unique<horus::WaitSet>();
  horus::Topic<CmdVel> topic(horus_test::unique_name("ws.close"));
  ws->attach(topic);
  std::atomic<int> closed{0};
  std::vector<std::thread> threads;
  horus::WaitSet* set = ws.get();  // the threads never read the unique_ptr that reset() writes
  for (int i = 0; i < 2; ++i)
    threads.emplace_back([set, &closed] {
      if (set->wait(30s).closed()) closed.fetch_add(1);
    });
  EXPECT_TRUE(eventually([&] { return topic.waiter_count() == 2; }));
  const auto t0 = Clock::now();
  ws.reset();  // returns once both waits have left
  EXPECT_LT(Clock::now() - t0, 5s);
  for (auto& t : threads) t.join();
  EXPECT_EQ(closed.load(), 2);
  EXPECT_EQ(topic.waiter_count(), 0u);
}

TEST_F(WaitSetTest, AttachingBeyondTheLimitIsAClearError) {
  horus::WaitSet ws;
  std::vector<horus::Trigger> triggers(horus::WaitSet::kMaxAttachments + 1);
  for (std::size_t i = 0; i < horus::WaitSet::kMaxAttachments; ++i) ws.attach(triggers[i]);
  try {
    ws.attach(triggers.back());
    FAIL() << "attached more than the limit";
  } catch (const horus::Exception& e) {
    EXPECT_EQ(e.error().code(), horus::Errc::LimitReached);
    EXPECT_NE(std::string(e.what()).find("futex_waitv"), std::string::npos) << e.what();
  }
}

// -- Executor -----------------------------------------------------------------

TEST_F(WaitSetTest, ExecutorHandlesEachTopicsMessagesInOrderAndGoesOnAfterAThrow) {
  const auto n = horus_test::unique_name("ex.order");
  horus::Executor ex;
  std::vector<double> seen;
  ex.subscribe<Pose2D>(n, [&](const Pose2D& p) {
    seen.push_back(p.x);
    if (static_cast<int>(p.x) % 10 == 3) throw std::runtime_error("every tenth message fails");
  });
  horus::Topic<Pose2D> pub(n);
  for (int i = 0; i < 200; ++i) pub.send(Pose2D{static_cast<double>(i), 0.0, 0.0, 0});
  horus_test::Deadline d(10000ms);
  while (seen.size() < 200 && !d.expired()) ex.spin_once(100ms);
  ASSERT_EQ(seen.size(), 200u);
  for (int i = 0; i < 200; ++i) EXPECT_EQ(seen[i], i);
  EXPECT_EQ(ex.callback_errors(), 20u);
  EXPECT_EQ(ex.callbacks_run(), 200u);
}

TEST_F(WaitSetTest, ExecutorRunsTimersAtTheirRateAndStopsFromAnotherThread) {
  horus::Executor ex;
  std::atomic<int> ticks{0};
  ex.every(10ms, [&] { ticks.fetch_add(1); });
  std::thread stopper([&] {
    std::this_thread::sleep_for(200ms);
    ex.stop();
  });
  const auto t0 = Clock::now();
  ex.spin();
  const auto took = Clock::now() - t0;
  stopper.join();
  EXPECT_GE(took, 190ms);
  EXPECT_LT(took, 5s);
  // 20 ticks at the rate; a loaded machine may skip some (counted as overruns).
  EXPECT_GE(ticks.load() + static_cast<int>(ex.timer_overruns()), 15);
  EXPECT_LE(ticks.load(), 21);
  EXPECT_THROW(ex.every(0ns, [] {}), horus::Exception);
}

horus::Executor* g_executor = nullptr;
extern "C" void stop_on_signal(int) { g_executor->stop(); }

TEST_F(WaitSetTest, ExecutorStopsFromASignalHandlerAndLargeDataArrivesWithoutACopy) {
  const auto n = horus_test::unique_name("ex.sig");
  horus::Executor ex;
  g_executor = &ex;
  bool borrowed = false;
  std::uint8_t first = 0;
  ex.subscribe<horus::msg::Image>(n, [&](const horus::msg::Image& m) {
    borrowed = m.buffer().borrowed();  // the bytes are the pool slot's, not a copy
    first = m.data()[0];
    ::kill(::getpid(), SIGUSR1);  // the handler stops the executor
  });
  struct sigaction sa{};
  sa.sa_handler = &stop_on_signal;
  ASSERT_EQ(::sigaction(SIGUSR1, &sa, nullptr), 0);
  horus::Topic<horus::msg::Image> pub(n);
  auto loan = pub.loan(*horus::msg::Image::describe(8, 8, horus::msg::ImageEncoding::Mono8));
  ASSERT_TRUE(loan);
  (*loan)->data_mut()[0] = 42;
  pub.send(std::move(*loan));
  const auto t0 = Clock::now();
  ex.spin_for(20s);
  EXPECT_LT(Clock::now() - t0, 10s) << "the signal handler's stop() did not end spin";
  ::signal(SIGUSR1, SIG_DFL);
  g_executor = nullptr;
  EXPECT_TRUE(borrowed);
  EXPECT_EQ(first, 42);
  // A stop before spin makes it return at once; the spin clears it.
  ex.stop();
  ex.spin();
  ex.spin_for(10ms);
}

TEST_F(WaitSetTest, AnExecutorCallbackMaySubscribeAndRemove) {
  const auto a = horus_test::unique_name("ex.a");
  const auto b = horus_test::unique_name("ex.b");
  horus::Executor ex;
  std::atomic<int> got_b{0};
  horus::Executor::Id id_a = 0;
  id_a = ex.subscribe<CmdVel>(a, [&](const CmdVel&) {
    ex.subscribe<CmdVel>(b, [&](const CmdVel&) { got_b.fetch_add(1); });
    EXPECT_TRUE(ex.remove(id_a));
  });
  horus::Topic<CmdVel> pa(a);
  horus::Topic<CmdVel> pb(b);
  pa.send(CmdVel::make(1.0f, 0.0f));
  horus_test::Deadline d(5000ms);
  while (ex.callbacks_run() < 1 && !d.expired()) ex.spin_once(50ms);
  pa.send(CmdVel::make(1.0f, 0.0f));  // nobody listens on a any more
  pb.send(CmdVel::make(2.0f, 0.0f));
  while (got_b.load() < 1 && !d.expired()) ex.spin_once(50ms);
  ex.spin_once(10ms);
  EXPECT_EQ(got_b.load(), 1);
  EXPECT_EQ(ex.callbacks_run(), 2u);
}

}  // namespace

// -- deadline and lifespan (TopicOptions) ---------------------------------------

namespace {
namespace deadline_tests {

std::uint64_t unix_ns() {
  return static_cast<std::uint64_t>(
      std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::system_clock::now().time_since_epoch()).count());
}

// A watchdog on cmd_vel: while a publisher sends every 10 ms the 60 ms deadline is kept; once
// it stops, the executor calls back (within a period or so) and the misses keep counting.
TEST_F(WaitSetTest, AnExecutorWatchdogFiresWhenCmdVelStopsAndNotWhileItFlows) {
  for (const Backend b : {Backend::InProcess, Backend::SharedMemory}) {
    const auto n = horus_test::unique_name("ex.deadline");
    horus::Executor ex;
    horus::TopicOptions o = on(b);
    o.deadline = 60ms;
    std::atomic<int> received{0};
    const auto id = ex.subscribe<CmdVel>(n, o, [&](const CmdVel&) { received.fetch_add(1); });
    std::vector<horus::DeadlineMissed> events;
    Clock::time_point first_event{};
    ex.on_deadline_missed(id, [&](const horus::DeadlineMissed& e) {
      if (events.empty()) first_event = Clock::now();
      events.push_back(e);
      if (e.total_count >= 3) ex.stop();
    });
    std::atomic<bool> sending{true};
    Clock::time_point last_send{};
    std::thread pub([&] {
      auto t = open<CmdVel>(n, b);
      for (int i = 0; i < 30; ++i) {
        t.send(CmdVel::make(0.5f, 0.0f));
        last_send = Clock::now();
        std::this_thread::sleep_for(10ms);
      }
      sending = false;
    });
    // While it flows (a loaded machine may stall the sender for a period: then a miss is real).
    while (sending) ex.spin_once(5ms);
    pub.join();
    const std::size_t while_flowing = events.size();
    ex.spin_for(5s);  // the third miss stops it
    ASSERT_GE(events.size(), 1u) << horus::to_string(b);
    EXPECT_LE(while_flowing, 1u) << horus::to_string(b) << ": misses while cmd_vel flowed every 10 ms";
    EXPECT_EQ(received.load(), 30) << horus::to_string(b);
    const auto after = first_event - last_send;
    EXPECT_GE(after, 55ms) << horus::to_string(b) << ": a miss before the deadline";
    EXPECT_LT(after, 2000ms) << horus::to_string(b);
    EXPECT_EQ(events.back().topic, n);
    EXPECT_GE(events.back().total_count, 3u);
    EXPECT_GE(events.back().silent_for, 3 * 60ms);
    std::uint64_t sum = 0;
    for (const auto& e : events) sum += e.total_count_change;
    EXPECT_EQ(sum, events.back().total_count) << "each miss reported once";
    EXPECT_EQ(ex.metrics(id)->messages_received(), 30u);
  }
}

TEST_F(WaitSetTest, APublishersOfferedDeadlineCountsThePeriodsBetweenItsSends) {
  const auto n = horus_test::unique_name("deadline.offered");
  horus::TopicOptions o = on(Backend::SharedMemory);
  o.deadline = 20ms;
  auto pub = horus::Topic<CmdVel>::open(n, o);
  ASSERT_TRUE(pub) << pub.error().message();
  pub->send(CmdVel::make(1.0f, 0.0f));
  const auto t0 = Clock::now();
  std::this_thread::sleep_for(70ms);
  pub->send(CmdVel::make(1.0f, 0.0f));
  const auto gap = Clock::now() - t0;
  const auto expected = static_cast<std::uint64_t>(gap / 20ms);
  EXPECT_GE(pub->deadline_missed_count(), expected - 1);
  EXPECT_LE(pub->deadline_missed_count(), expected);
  EXPECT_GE(pub->deadline_missed_count(), 3u);
  // Without a deadline nothing counts; a watchdog on such a topic is refused, saying why.
  auto plain = open<CmdVel>(n, Backend::SharedMemory);
  EXPECT_EQ(plain.deadline_missed_count(), 0u);
  horus::Executor ex;
  const auto id = ex.subscribe<CmdVel>(n, on(Backend::SharedMemory), [](const CmdVel&) {});
  try {
    ex.on_deadline_missed(id, [](const horus::DeadlineMissed&) {});
    ADD_FAILURE() << "a topic without a deadline took a watchdog";
  } catch (const horus::Exception& e) {
    EXPECT_EQ(e.error().code(), horus::Errc::InvalidArgument);
    EXPECT_NE(std::string(e.what()).find("has no deadline"), std::string::npos) << e.what();
  }
  EXPECT_THROW(ex.on_deadline_missed(12345, [](const horus::DeadlineMissed&) {}), horus::Exception);
}

// Lifespan: a message whose timestamp is older than it is not delivered (counted); fresh ones
// and those without a timestamp are.
TEST_F(WaitSetTest, ALifespanSkipsMessagesOlderThanItAndCountsThem) {
  for (const Backend b : {Backend::InProcess, Backend::SharedMemory}) {
    const auto n = horus_test::unique_name("lifespan");
    horus::TopicOptions o = on(b);
    o.lifespan = 500ms;
    auto sub = horus::Topic<CmdVel>::open(n, o);
    ASSERT_TRUE(sub) << sub.error().message();
    auto pub = open<CmdVel>(n, b);
    const std::uint64_t now = unix_ns();
    pub.send(CmdVel{now - 2'000'000'000ull, 1.0f, 0.0f});  // 2 s old: expired
    pub.send(CmdVel{now, 2.0f, 0.0f});
    pub.send(CmdVel{0, 3.0f, 0.0f});                        // no timestamp: never expires
    pub.send(CmdVel{now - 600'000'000ull, 4.0f, 0.0f});     // 600 ms old: expired
    std::vector<float> got;
    while (auto m = sub->recv_for(100ms)) got.push_back(m->linear);
    EXPECT_EQ(got, (std::vector<float>{2.0f, 3.0f})) << horus::to_string(b);
    EXPECT_EQ(sub->expired_count(), 2u);
    EXPECT_GE(sub->dropped_count(), 2u);
    // read_latest gives nothing when the newest expired.
    pub.send(CmdVel{now - 3'000'000'000ull, 5.0f, 0.0f});
    EXPECT_FALSE(sub->read_latest().has_value());
    // The timestamp is a message's timestamp_ns (member or method) or CmdVel's stamp_nanos.
    EXPECT_EQ(horus::message_timestamp_ns(Pose2D{0, 0, 0, 42}), 42u);
  }
}

}  // namespace deadline_tests
}  // namespace
