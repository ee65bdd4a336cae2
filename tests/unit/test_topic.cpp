// Topic<T> in one thread: every method, its edge cases, names and type checks.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "horus/topic.hpp"
#include "test_support.hpp"

using horus::Errc;
using horus::Topic;
using horus_test::Other;
using horus_test::Stamp;
using horus_test::unique_name;

namespace {

template <class T>
Topic<T> must(horus::Result<Topic<T>> r) {
  if (!r) throw horus::Exception(r.error());
  return std::move(*r);
}

std::vector<std::uint64_t> drain(Topic<Stamp>& t) {
  std::vector<std::uint64_t> seqs;
  while (auto m = t.recv()) {
    EXPECT_TRUE(m->intact());
    seqs.push_back(m->seq);
  }
  return seqs;
}

// Opens kMaxPublishers handles on `name` that each hold a lane (every lane is then taken).
std::vector<Topic<Stamp>> take_every_lane(const std::string& name) {
  std::vector<Topic<Stamp>> pubs;
  for (std::uint32_t p = 0; p < horus::shm::kMaxPublishers; ++p) {
    pubs.emplace_back(name);
    pubs.back().send(Stamp::make(p, 0));
  }
  return pubs;
}

std::vector<std::uint64_t> range(std::uint64_t from, std::uint64_t to) {
  std::vector<std::uint64_t> v;
  for (auto i = from; i < to; ++i) v.push_back(i);
  return v;
}

}  // namespace

// -- names --------------------------------------------------------------------

TEST(TopicName, AcceptsDotSeparatedNamesWithLettersDigitsUnderscoresAndDashes) {
  for (const char* name : {"cmd_vel", "sensors.imu", "robot-1.pose", "fleet.robot_7.tf", "A9", "x"})
    EXPECT_TRUE(horus::validate_topic_name(name).has_value()) << name;
  EXPECT_TRUE(horus::validate_topic_name(std::string(horus::kMaxTopicNameLength, 'a')).has_value());
}

TEST(TopicName, RejectsASlashAndSaysWhereAndWhatIsExpected) {
  auto r = horus::validate_topic_name("robot/cmd_vel");
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code(), Errc::InvalidName);
  const auto& msg = r.error().message();
  EXPECT_NE(msg.find("'/'"), std::string::npos) << msg;
  EXPECT_NE(msg.find("position 5"), std::string::npos) << msg;
  EXPECT_NE(msg.find("use '.'"), std::string::npos) << msg;
  EXPECT_NE(msg.find("expected"), std::string::npos) << msg;
}

TEST(TopicName, RejectsEmptyTooLongMalformedSegmentsAndOddCharacters) {
  const std::vector<std::string> bad{"",      std::string(horus::kMaxTopicNameLength + 1, 'a'),
                                     ".imu",  "imu.",
                                     "a..b",  "-imu",
                                     "a b",   "imu\n",
                                     "caf\xc3\xa9", "a:b"};
  for (const auto& name : bad) {
    auto r = horus::validate_topic_name(name);
    ASSERT_FALSE(r) << name;
    EXPECT_EQ(r.error().code(), Errc::InvalidName);
    EXPECT_NE(r.error().message().find("invalid topic name"), std::string::npos);
  }
}

TEST(Topic, ThrowingConstructorThrowsHorusExceptionForABadName) {
  try {
    Topic<Stamp> t("bad/name");
    FAIL() << "no exception";
  } catch (const horus::Exception& e) {
    EXPECT_EQ(e.code(), Errc::InvalidName);
    EXPECT_NE(std::string(e.what()).find("bad/name"), std::string::npos);
  }
  EXPECT_FALSE(Topic<Stamp>::open("bad/name"));
}

// -- connection and order -------------------------------------------------------

TEST(Topic, TwoHandlesWithTheSameNameAreConnected) {
  const auto name = unique_name("connect");
  Topic<Stamp> pub(name);
  Topic<Stamp> sub(name);
  EXPECT_EQ(pub.name(), name);
  EXPECT_EQ(pub.backend(), horus::Backend::SharedMemory);  // the default
  pub.send(Stamp::make(1, 42));
  auto m = sub.recv();
  ASSERT_TRUE(m);
  EXPECT_EQ(m->seq, 42u);
  EXPECT_TRUE(m->intact());
  EXPECT_FALSE(sub.recv());
}

TEST(Topic, RecvOnAnEmptyTopicReturnsNothingAndCountsAReceiveFailure) {
  Topic<Stamp> sub(unique_name("empty"));
  EXPECT_FALSE(sub.recv());
  EXPECT_FALSE(sub.try_recv());
  EXPECT_FALSE(sub.has_message());
  EXPECT_EQ(sub.pending_count(), 0u);
  EXPECT_EQ(sub.metrics().recv_failures(), 2u);
  EXPECT_EQ(sub.metrics().messages_received(), 0u);
}

TEST(Topic, EverySubscriberGetsEveryMessageOnceInFifoOrder) {
  const auto name = unique_name("fifo");
  Topic<Stamp> a(name), b(name), pub(name);
  for (std::uint64_t i = 0; i < 10; ++i) pub.send(Stamp::make(0, i));
  EXPECT_EQ(drain(a), range(0, 10));
  EXPECT_EQ(drain(b), range(0, 10));
  EXPECT_EQ(drain(a), std::vector<std::uint64_t>{});
}

TEST(Topic, ASubscriberOpenedAfterASendGetsOnlyLaterMessagesButReadLatestSeesTheLastOne) {
  const auto name = unique_name("late");
  Topic<Stamp> pub(name);
  pub.send(Stamp::make(0, 1));
  Topic<Stamp> late(name);
  EXPECT_FALSE(late.has_message());
  auto latest = late.read_latest();
  ASSERT_TRUE(latest);
  EXPECT_EQ(latest->seq, 1u);
  pub.send(Stamp::make(0, 2));
  EXPECT_EQ(drain(late), std::vector<std::uint64_t>{2});
}

TEST(Topic, WrapAroundKeepsOrderOverManyLaps) {
  const auto name = unique_name("wrap");
  auto pub = must(Topic<Stamp>::with_capacity(name, 2));
  Topic<Stamp> sub(name);
  std::uint64_t next = 0;
  for (int lap = 0; lap < 500; ++lap) {
    const int burst = 1 + lap % 2;  // 1 or 2 messages: never more than the capacity
    for (int i = 0; i < burst; ++i) pub.send(Stamp::make(0, next + static_cast<std::uint64_t>(i)));
    EXPECT_EQ(drain(sub), range(next, next + static_cast<std::uint64_t>(burst)));
    next += static_cast<std::uint64_t>(burst);
  }
  EXPECT_EQ(sub.dropped_count(), 0u);
}

// -- overwrite and drops ----------------------------------------------------------

TEST(Topic, AFullRingOverwritesTheOldestAndCountsTheDropForTheSubscriberThatLostIt) {
  const auto name = unique_name("overwrite");
  auto fast = must(Topic<Stamp>::with_capacity(name, 4));
  Topic<Stamp> slow(name);
  Topic<Stamp> pub(name);
  std::vector<std::uint64_t> fast_got;
  for (std::uint64_t i = 0; i < 10; ++i) {
    pub.send(Stamp::make(0, i));
    for (auto s : drain(fast)) fast_got.push_back(s);
  }
  EXPECT_EQ(fast_got, range(0, 10));
  EXPECT_EQ(fast.dropped_count(), 0u);
  // The slow subscriber sees its losses before reading, and then the newest 4 in order.
  EXPECT_EQ(slow.dropped_count(), 6u);
  EXPECT_EQ(slow.pending_count(), 4u);
  EXPECT_EQ(drain(slow), range(6, 10));
  EXPECT_EQ(slow.dropped_count(), 6u);
  // The publisher sees the drops of all its subscribers.
  EXPECT_EQ(pub.dropped_count(), 6u);
  EXPECT_EQ(pub.metrics().messages_dropped(), 6u);
}

TEST(Topic, CapacityOneKeepsOnlyTheNewestMessage) {
  const auto name = unique_name("cap1");
  auto sub = must(Topic<Stamp>::with_capacity(name, 1));
  Topic<Stamp> pub(name);
  for (std::uint64_t i = 0; i < 5; ++i) pub.send(Stamp::make(0, i));
  EXPECT_EQ(drain(sub), std::vector<std::uint64_t>{4});
  EXPECT_EQ(sub.dropped_count(), 4u);
}

// -- read_latest ------------------------------------------------------------------

TEST(Topic, ReadLatestReturnsTheNewestRepeatedlyAndSkipsOlderMessagesForThisHandleOnly) {
  const auto name = unique_name("latest");
  Topic<Stamp> watcher(name), other(name), pub(name);
  EXPECT_FALSE(watcher.read_latest());
  for (std::uint64_t i = 1; i <= 3; ++i) pub.send(Stamp::make(0, i));
  for (int k = 0; k < 3; ++k) {
    auto m = watcher.read_latest();
    ASSERT_TRUE(m);
    EXPECT_EQ(m->seq, 3u);
  }
  EXPECT_FALSE(watcher.recv());
  EXPECT_EQ(watcher.dropped_count(), 0u);
  pub.send(Stamp::make(0, 4));
  EXPECT_EQ(drain(watcher), std::vector<std::uint64_t>{4});
  EXPECT_EQ(drain(other), range(1, 5));
}

// -- try_send and send_blocking ------------------------------------------------------

TEST(Topic, TrySendGivesTheMessageBackWhenASubscriberWouldLoseIt) {
  const auto name = unique_name("trysend");
  auto sub = must(Topic<Stamp>::with_capacity(name, 4));
  Topic<Stamp> pub(name);
  for (std::uint64_t i = 0; i < 4; ++i) EXPECT_TRUE(pub.try_send(Stamp::make(0, i)));
  auto refused = pub.try_send(Stamp::make(0, 99));
  ASSERT_FALSE(refused);
  EXPECT_EQ(refused.error().seq, 99u);
  EXPECT_TRUE(refused.error().intact());
  EXPECT_EQ(pub.metrics().send_failures(), 1u);
  ASSERT_TRUE(sub.recv());
  EXPECT_TRUE(pub.try_send(Stamp::make(0, 4)));
  EXPECT_EQ(drain(sub), range(1, 5));
  EXPECT_EQ(sub.dropped_count(), 0u);
}

TEST(Topic, TrySendAlwaysSucceedsWithoutSubscribers) {
  const auto name = unique_name("trysend_nosub");
  auto pub = must(Topic<Stamp>::with_capacity(name, 2));
  pub.send(Stamp::make(0, 0));  // first send: pure publisher, not a subscriber of itself
  for (std::uint64_t i = 1; i < 10; ++i) EXPECT_TRUE(pub.try_send(Stamp::make(0, i)));
  EXPECT_EQ(pub.sub_count(), 0u);
}

TEST(Topic, SendBlockingTimesOutWhenTheRingStaysFullAndSaysSo) {
  const auto name = unique_name("blocking");
  auto sub = must(Topic<Stamp>::with_capacity(name, 2));
  Topic<Stamp> pub(name);
  pub.send(Stamp::make(0, 0));
  pub.send(Stamp::make(0, 1));
  auto r = pub.send_blocking(Stamp::make(0, 2), std::chrono::milliseconds(5));
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code(), Errc::Timeout);
  EXPECT_NE(r.error().message().find(name), std::string::npos);
  EXPECT_EQ(drain(sub), range(0, 2));
  EXPECT_TRUE(pub.send_blocking(Stamp::make(0, 2), std::chrono::milliseconds(5)));
  EXPECT_EQ(drain(sub), range(2, 3));
}

// -- type and configuration checks ----------------------------------------------------

TEST(Topic, OpeningANameThatCarriesAnotherTypeFailsNamingBothTypes) {
  const auto name = unique_name("mismatch");
  Topic<Stamp> first(name);
  auto second = Topic<Other>::open(name);
  ASSERT_FALSE(second);
  EXPECT_EQ(second.error().code(), Errc::TypeMismatch);
  const auto& msg = second.error().message();
  EXPECT_NE(msg.find("horus_test::Stamp"), std::string::npos) << msg;
  EXPECT_NE(msg.find("horus_test::Other"), std::string::npos) << msg;
  EXPECT_NE(msg.find(name), std::string::npos) << msg;
  EXPECT_THROW(Topic<Other>{name}, horus::Exception);
}

TEST(Topic, WithCapacityRejectsCapacitiesThatAreNotPowersOfTwoOrTooLarge) {
  for (std::uint32_t cap : {0u, 3u, 1000u, horus::shm::kMaxCapacity * 2}) {
    auto r = Topic<Stamp>::with_capacity(unique_name("cap"), cap);
    ASSERT_FALSE(r) << cap;
    EXPECT_EQ(r.error().code(), Errc::InvalidArgument);
    EXPECT_NE(r.error().message().find("capacity " + std::to_string(cap) + " "), std::string::npos)
        << r.error().message();
  }
}

TEST(Topic, WithCapacityRejectsASlotSmallerThanTheMessage) {
  auto r = Topic<Stamp>::with_capacity(unique_name("slot"), 8, 4);
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code(), Errc::InvalidArgument);
  EXPECT_NE(r.error().message().find("slot_size 4"), std::string::npos);
  EXPECT_TRUE(Topic<Stamp>::with_capacity(unique_name("slot"), 8, sizeof(Stamp)));
}

TEST(Topic, ReopeningWithAnotherCapacityIsAnErrorButOpenAcceptsTheExistingOne) {
  const auto name = unique_name("capmismatch");
  auto first = must(Topic<Stamp>::with_capacity(name, 8));
  auto again = Topic<Stamp>::with_capacity(name, 16);
  ASSERT_FALSE(again);
  EXPECT_EQ(again.error().code(), Errc::ConfigMismatch);
  auto plain = must(Topic<Stamp>::open(name));
  EXPECT_EQ(plain.capacity(), 8u);
}

TEST(Topic, DefaultCapacityGrowsForSmallMessagesWithinSixteenTo1024) {
  EXPECT_EQ(horus::shm::default_capacity(16), 1024u);
  EXPECT_EQ(horus::shm::default_capacity(1500), 32u);
  EXPECT_EQ(horus::shm::default_capacity(1u << 20), 16u);
  Topic<Stamp> t(unique_name("defcap"));
  EXPECT_EQ(t.capacity(), horus::shm::default_capacity(sizeof(Stamp)));
}

TEST(Topic, ATopicIsForgottenWhenItsLastHandleCloses) {
  const auto name = unique_name("forget");
  { Topic<Stamp> t(name); }
  EXPECT_TRUE(Topic<Other>::open(name));
}

// -- counts, metrics, lanes --------------------------------------------------------------

TEST(Topic, PublisherAndSubscriberCountsFollowTheHandles) {
  const auto name = unique_name("counts");
  Topic<Stamp> sub(name);
  EXPECT_EQ(sub.sub_count(), 1u);
  EXPECT_EQ(sub.pub_count(), 0u);
  {
    Topic<Stamp> pub(name);
    EXPECT_EQ(sub.sub_count(), 2u);  // not yet known to be a publisher
    pub.send(Stamp::make(0, 0));
    EXPECT_EQ(sub.pub_count(), 1u);
    EXPECT_EQ(sub.sub_count(), 1u);
  }
  EXPECT_EQ(sub.pub_count(), 0u);
  EXPECT_EQ(drain(sub), std::vector<std::uint64_t>{0});  // messages outlive their publisher
}

TEST(Topic, AHandleThatReceivedFirstStaysASubscriberWhenItAlsoSends) {
  const auto name = unique_name("both");
  Topic<Stamp> node(name);
  EXPECT_FALSE(node.recv());
  node.send(Stamp::make(0, 7));
  EXPECT_EQ(node.sub_count(), 1u);
  EXPECT_EQ(drain(node), std::vector<std::uint64_t>{7});
}

TEST(Topic, HasMessageAndPendingCountTrackUnreadMessages) {
  const auto name = unique_name("pending");
  Topic<Stamp> sub(name), pub(name);
  for (std::uint64_t i = 0; i < 3; ++i) pub.send(Stamp::make(0, i));
  EXPECT_TRUE(sub.has_message());
  EXPECT_EQ(sub.pending_count(), 3u);
  ASSERT_TRUE(sub.recv());
  EXPECT_EQ(sub.pending_count(), 2u);
  drain(sub);
  EXPECT_FALSE(sub.has_message());
  EXPECT_EQ(sub.pending_count(), 0u);
}

TEST(Topic, MetricsCountSendsReceivesAndFailuresPerHandle) {
  const auto name = unique_name("metrics");
  auto sub = must(Topic<Stamp>::with_capacity(name, 2));
  Topic<Stamp> pub(name);
  pub.send(Stamp::make(0, 0));
  pub.send(Stamp::make(0, 1));
  EXPECT_FALSE(pub.try_send(Stamp::make(0, 2)));
  drain(sub);  // 2 messages, then one empty recv
  const auto pm = pub.metrics();
  EXPECT_EQ(pm.messages_sent(), 2u);
  EXPECT_EQ(pm.send_failures(), 1u);
  EXPECT_EQ(pm.topic_messages_sent(), 2u);
  const auto sm = sub.metrics();
  EXPECT_EQ(sm.messages_received(), 2u);
  EXPECT_EQ(sm.recv_failures(), 1u);
  EXPECT_EQ(sm.messages_sent(), 0u);
}

TEST(Topic, ALaneFreedByAClosedPublisherIsReusedAndItsSequenceContinues) {
  const auto name = unique_name("lane_reuse");
  Topic<Stamp> sub(name);
  {
    Topic<Stamp> first(name);
    for (std::uint64_t i = 0; i < 3; ++i) first.send(Stamp::make(0, i));
  }
  Topic<Stamp> second(name);
  for (std::uint64_t i = 3; i < 6; ++i) second.send(Stamp::make(0, i));
  EXPECT_EQ(sub.pub_count(), 1u);
  EXPECT_EQ(drain(sub), range(0, 6));
}

TEST(Topic, MessagesFromSeveralPublishersAreAllDeliveredInOrderPerPublisher) {
  const auto name = unique_name("multipub");
  Topic<Stamp> sub(name);
  std::vector<Topic<Stamp>> pubs;
  for (int p = 0; p < 5; ++p) pubs.emplace_back(name);
  for (std::uint64_t i = 0; i < 20; ++i)
    for (std::uint32_t p = 0; p < 5; ++p) pubs[p].send(Stamp::make(p, i));
  std::vector<std::uint64_t> next(5, 0);
  int total = 0;
  while (auto m = sub.recv()) {
    ASSERT_TRUE(m->intact());
    ASSERT_EQ(m->seq, next[m->publisher]++);
    ++total;
  }
  EXPECT_EQ(total, 100);
  EXPECT_EQ(sub.pub_count(), 5u);
}

TEST(Topic, WhenEveryLaneIsTakenFurtherPublishersAreRefusedAndCounted) {
  const auto name = unique_name("lanes_full");
  Topic<Stamp> sub(name);
  auto pubs = take_every_lane(name);
  Topic<Stamp> extra(name);
  extra.send(Stamp::make(999, 0));
  EXPECT_EQ(extra.metrics().send_failures(), 1u);
  EXPECT_EQ(extra.metrics().messages_sent(), 0u);
  EXPECT_FALSE(extra.try_send(Stamp::make(999, 1)));
  EXPECT_EQ(sub.pending_count(), horus::shm::kMaxPublishers);
  pubs.pop_back();  // frees a lane
  extra.send(Stamp::make(999, 2));
  EXPECT_EQ(extra.metrics().messages_sent(), 1u);
}

TEST(Topic, AMovedHandleKeepsItsSubscriptionAndLane) {
  const auto name = unique_name("move");
  Topic<Stamp> sub(name);
  Topic<Stamp> pub(name);
  pub.send(Stamp::make(0, 0));
  Topic<Stamp> moved_pub(std::move(pub));
  moved_pub.send(Stamp::make(0, 1));
  Topic<Stamp> moved_sub(name);
  EXPECT_EQ(moved_sub.sub_count(), 2u);
  moved_sub = std::move(sub);  // releases moved_sub's own subscription, takes sub's
  EXPECT_EQ(moved_sub.sub_count(), 1u);
  EXPECT_EQ(moved_sub.pub_count(), 1u);
  EXPECT_EQ(drain(moved_sub), range(0, 2));
  // Assigning over a handle that holds a lane releases that lane.
  Topic<Stamp> other_pub(name);
  other_pub.send(Stamp::make(1, 0));
  EXPECT_EQ(moved_sub.pub_count(), 2u);
  other_pub = std::move(moved_pub);
  EXPECT_EQ(moved_sub.pub_count(), 1u);
  other_pub.send(Stamp::make(0, 2));
  // Publisher 0's 2, then publisher 1's 0: the turn over lanes starts at lane 0 when a second
  // lane appears (ring_reader.hpp: a reader of one lane keeps no turn); FIFO within each.
  EXPECT_EQ(drain(moved_sub), (std::vector<std::uint64_t>{2, 0}));
}

TEST(Topic, SelfMoveAssignmentLeavesTheHandleWorking) {
  const auto name = unique_name("selfmove");
  Topic<Stamp> sub(name), pub(name);
  pub.send(Stamp::make(0, 0));
  auto& alias = pub;
  pub = std::move(alias);
  pub.send(Stamp::make(0, 1));
  EXPECT_EQ(sub.pub_count(), 1u);
  EXPECT_EQ(drain(sub), range(0, 2));
}

TEST(Topic, AHandleThatAlsoReceivesNeverWaitsForItsOwnSubscription) {
  const auto name = unique_name("self_wait");
  auto node = must(Topic<Stamp>::with_capacity(name, 2));
  EXPECT_FALSE(node.recv());  // a receiver: stays subscribed when it sends
  for (std::uint64_t i = 0; i < 5; ++i)
    EXPECT_TRUE(node.send_blocking(Stamp::make(0, i), std::chrono::milliseconds(100))) << i;
  EXPECT_EQ(node.sub_count(), 1u);
  EXPECT_EQ(drain(node), range(3, 5));
  EXPECT_EQ(node.dropped_count(), 3u);
}

TEST(Topic, AnIdleSubscriberMakesTrySendRefuseUntilItReads) {
  const auto name = unique_name("idle_sub");
  auto idle = must(Topic<Stamp>::with_capacity(name, 2));
  Topic<Stamp> pub(name);
  EXPECT_TRUE(pub.try_send(Stamp::make(0, 0)));
  EXPECT_TRUE(pub.try_send(Stamp::make(0, 1)));
  EXPECT_FALSE(pub.try_send(Stamp::make(0, 2)));
  EXPECT_TRUE(idle.read_latest());  // marks everything read
  EXPECT_TRUE(pub.try_send(Stamp::make(0, 2)));
}

TEST(Topic, AHandleDeclaredPublishOnlyNeverHoldsSendersBackUntilItReceives) {
  const auto name = unique_name("publish_only");
  auto waiting = must(Topic<Stamp>::with_capacity(name, 2));  // will publish, some day
  waiting.publish_only();
  Topic<Stamp> pub(name);
  EXPECT_EQ(pub.sub_count(), 1u);  // pub itself; not `waiting`
  for (std::uint64_t i = 0; i < 5; ++i) EXPECT_TRUE(pub.try_send(Stamp::make(0, i))) << i;
  EXPECT_EQ(pub.dropped_count(), 0u);
  // A receive subscribes it again, from then on: it holds senders back like any subscriber.
  EXPECT_EQ(pub.sub_count(), 0u);  // pub is a pure publisher too, since its first send
  EXPECT_FALSE(waiting.recv());
  EXPECT_EQ(pub.sub_count(), 1u);
  EXPECT_TRUE(pub.try_send(Stamp::make(0, 5)));
  EXPECT_TRUE(pub.try_send(Stamp::make(0, 6)));
  EXPECT_FALSE(pub.try_send(Stamp::make(0, 7)));
  auto m = waiting.recv();
  ASSERT_TRUE(m);
  EXPECT_EQ(m->seq, 5u);
}

TEST(Topic, SendBlockingWithoutAFreeLaneFailsAtOnceWithLimitReached) {
  const auto name = unique_name("blocking_nolane");
  auto pubs = take_every_lane(name);
  Topic<Stamp> extra(name);
  const auto start = std::chrono::steady_clock::now();
  auto r = extra.send_blocking(Stamp::make(99, 0), std::chrono::seconds(30));
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code(), Errc::LimitReached);
  EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(5));
}

TEST(Topic, HasMessageOnAPurePublisherSubscribesItAgain) {
  const auto name = unique_name("pub_then_sub");
  Topic<Stamp> node(name), other(name);
  node.send(Stamp::make(0, 0));  // pure publisher: not subscribed
  EXPECT_EQ(node.sub_count(), 1u);
  EXPECT_FALSE(node.has_message());  // subscribes from now on
  EXPECT_EQ(node.sub_count(), 2u);
  other.send(Stamp::make(1, 1));
  EXPECT_TRUE(node.has_message());
  auto m = node.recv();
  ASSERT_TRUE(m);
  EXPECT_EQ(m->seq, 1u);
  EXPECT_EQ(node.metrics().messages_received(), 1u);
  EXPECT_EQ(node.metrics().messages_sent(), 1u);
}

TEST(Topic, DroppedCountNeverGoesDownWhenReadLatestSkipsOverLostMessages) {
  const auto name = unique_name("drops_monotonic");
  auto sub = must(Topic<Stamp>::with_capacity(name, 4));
  Topic<Stamp> pub(name);
  for (std::uint64_t i = 0; i < 10; ++i) pub.send(Stamp::make(0, i));
  EXPECT_EQ(sub.dropped_count(), 6u);
  EXPECT_EQ(pub.dropped_count(), 6u);
  auto latest = sub.read_latest();
  ASSERT_TRUE(latest);
  EXPECT_EQ(latest->seq, 9u);
  EXPECT_EQ(sub.dropped_count(), 6u);
  EXPECT_EQ(pub.dropped_count(), 6u);
  EXPECT_FALSE(sub.recv());
  EXPECT_EQ(sub.metrics().messages_received(), 0u);
}

TEST(Topic, APublisherKeepsCountingTheLossesOfASubscriberThatClosed) {
  const auto name = unique_name("drops_after_close");
  auto pub = must(Topic<Stamp>::with_capacity(name, 4));
  pub.send(Stamp::make(0, 0));  // pure publisher from here on
  {
    Topic<Stamp> lagging(name);
    for (std::uint64_t i = 1; i <= 10; ++i) pub.send(Stamp::make(0, i));
    EXPECT_EQ(pub.dropped_count(), 6u);
  }
  EXPECT_EQ(pub.dropped_count(), 6u);
}

namespace {
// 12 bytes: exercises the partial last word of a slot.
struct Odd {
  std::uint8_t a{};
  std::uint16_t b{};
  float c{};
  std::uint32_t d{};
};
HORUS_REFLECT(Odd, a, b, c, d)
static_assert(sizeof(Odd) == 12);
}  // namespace

TEST(Topic, MessagesWhoseSizeIsNotAMultipleOfEightBytesArriveIntact) {
  const auto name = unique_name("odd_size");
  auto sub = must(Topic<Odd>::with_capacity(name, 4));
  Topic<Odd> pub(name);
  for (std::uint32_t i = 0; i < 10; ++i)
    pub.send(Odd{static_cast<std::uint8_t>(i), static_cast<std::uint16_t>(1000 + i), 0.5f * static_cast<float>(i),
                 0xdead0000u + i});
  for (std::uint32_t i = 6; i < 10; ++i) {
    auto m = sub.recv();
    ASSERT_TRUE(m);
    EXPECT_EQ(m->a, i);
    EXPECT_EQ(m->b, 1000 + i);
    EXPECT_EQ(m->c, 0.5f * static_cast<float>(i));
    EXPECT_EQ(m->d, 0xdead0000u + i);
  }
  EXPECT_FALSE(sub.recv());
}
