// The large-data pool (backend_shm/pool.hpp) and what Topic<T> builds on it for Image,
// PointCloud, DepthImage and Tensor: zero-copy receive, copy on write, loans, pins that keep a
// slot from being rewritten, exhaustion, and reuse counted as drops.
#include <gtest/gtest.h>

#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <cstring>
#include <deque>
#include <thread>
#include <vector>

#include "horus/messages.hpp"
#include "horus/shm/heap_region.hpp"
#include "horus/shm/pool.hpp"
#include "horus/shm/shm_segment.hpp"
#include "horus/topic.hpp"
#include "test_support.hpp"

namespace {

using horus::Topic;
using horus::TopicOptions;
using horus::msg::Image;
using horus::msg::ImageEncoding;
using horus::shm::Pool;
using horus::shm::PoolConfig;

Pool::Claimer me() {
  return {static_cast<std::uint32_t>(::getpid()), horus::shm::process_start_time(::getpid())};
}

struct PoolFixture {
  explicit PoolFixture(PoolConfig cfg) : region(Pool::required_size(cfg)), pool(Pool::format(region.data(), cfg)) {}
  horus::shm::HeapRegion region;
  Pool pool;
};

TEST(Pool, ConfigIsCheckedAndTheHeaderValidated) {
  EXPECT_TRUE(Pool::check_config({0, 8}));
  EXPECT_TRUE(Pool::check_config({4096, 1}));
  EXPECT_TRUE(Pool::check_config({4096, horus::shm::kMaxPoolSlotsPerLane + 1}));
  EXPECT_FALSE(Pool::check_config({4096, 8}));
  PoolFixture f({1000, 4});
  EXPECT_FALSE(Pool::validate(f.region.data(), Pool::required_size({1000, 4})));
  EXPECT_TRUE(Pool::validate(f.region.data(), 100));  // cut off
  f.pool.header().slot_stride = 123;                   // corrupt
  const auto err = Pool::validate(f.region.data(), Pool::required_size({1000, 4}));
  ASSERT_TRUE(err);
  EXPECT_NE(err->find("layout"), std::string::npos) << *err;
}

// Another process that rewrites the shared header after this one attached (a hostile writer
// of a shared segment) cannot move the bounds this process checks: the geometry was copied at
// attach. Without the copy, slot 3's data would move 1 GiB past the region.
TEST(Pool, TheGeometryIsCopiedAtAttachAndALaterHeaderChangeMovesNoBound) {
  PoolFixture f({1000, 4});
  const Pool attached = Pool::attach(f.region.data());
  const auto bytes = attached.slot_bytes();
  const auto count = attached.slot_count();
  const auto offset = attached.offset_of(3);
  const auto* data = attached.data(3);
  f.pool.header().slot_bytes = std::uint64_t{1} << 40;
  f.pool.header().slot_stride = std::uint64_t{1} << 30;
  f.pool.header().slots_per_lane = 1u << 30;
  f.pool.header().lanes = 1u << 20;
  f.pool.header().data_offset = std::uint64_t{1} << 35;
  EXPECT_EQ(attached.slot_bytes(), bytes);
  EXPECT_EQ(attached.slot_count(), count);
  EXPECT_EQ(attached.offset_of(3), offset);
  EXPECT_EQ(attached.data(3), data);
  EXPECT_FALSE(attached.pin(count, 0, 0)) << "a slot past the attached geometry";
}

TEST(Pool, AClaimIsOddUntilPublishedAndPinsOnlyTheGenerationPublished) {
  PoolFixture f({4096, 4});
  auto c = f.pool.claim(3, me());
  ASSERT_TRUE(c);
  EXPECT_EQ(c->slot / 4, 3u) << "a lane claims its own slots";
  EXPECT_EQ(c->gen % 2, 1u);
  EXPECT_FALSE(f.pool.pin(c->slot, c->gen, 0)) << "an odd generation is never pinned";
  EXPECT_FALSE(f.pool.pin(c->slot, c->gen + 1, 0)) << "not published yet";
  const auto gen = f.pool.publish(*c, 1);
  EXPECT_EQ(gen, c->gen + 1);
  EXPECT_TRUE(f.pool.pin(c->slot, gen, 5));
  EXPECT_FALSE(f.pool.pin(c->slot, gen - 2, 5)) << "an older generation";
  EXPECT_FALSE(f.pool.pin(f.pool.slot_count(), gen, 5)) << "a slot out of range";
  EXPECT_EQ(f.pool.pinned_slots(), 1u);
  f.pool.unpin(c->slot, 5);
  EXPECT_EQ(f.pool.pinned_slots(), 0u);
}

TEST(Pool, APinnedSlotIsNeverClaimedAndTheOldestFreeOneIsTaken) {
  PoolFixture f({4096, 4});
  std::vector<Pool::Claim> published;
  for (std::uint64_t i = 0; i < 4; ++i) {
    auto c = f.pool.claim(0, me());
    ASSERT_TRUE(c);
    f.pool.publish(*c, i + 1);
    published.push_back(Pool::Claim{c->slot, c->gen + 1});
  }
  // Every slot used once, in order; pin the oldest: the next claim takes the second oldest.
  ASSERT_TRUE(f.pool.pin(published[0].slot, published[0].gen, 0));
  auto c = f.pool.claim(0, me());
  ASSERT_TRUE(c);
  EXPECT_EQ(c->slot, published[1].slot);
  f.pool.publish(*c, 5);
  // Pin the rest: nothing left, and the refusal is counted.
  for (std::size_t i = 2; i < 4; ++i) ASSERT_TRUE(f.pool.pin(published[i].slot, published[i].gen, 1));
  ASSERT_TRUE(f.pool.pin(c->slot, c->gen + 1, 1));
  EXPECT_FALSE(f.pool.claim(0, me()));  // (the caller counts the refusal, once per message)
  // A participant that dies releases everything it pinned.
  f.pool.release_participant(1);
  EXPECT_EQ(f.pool.pinned_slots(), 1u);
  EXPECT_TRUE(f.pool.claim(0, me()));
}

TEST(Pool, AnAbandonedClaimComesBackFirstAndOnlyADeadWritersSlotIsTakenOver) {
  PoolFixture f({4096, 2});
  auto a = f.pool.claim(0, me());
  ASSERT_TRUE(a);
  f.pool.publish(*a, 1);
  auto b = f.pool.claim(0, me());
  ASSERT_TRUE(b);
  EXPECT_NE(a->slot, b->slot);
  EXPECT_TRUE(f.pool.claimed(*b));
  EXPECT_TRUE(f.pool.abandon(*b));
  EXPECT_FALSE(f.pool.abandon(*b)) << "only once";
  EXPECT_FALSE(f.pool.claimed(*b));
  auto c = f.pool.claim(0, me());
  ASSERT_TRUE(c);
  EXPECT_EQ(c->slot, b->slot) << "an abandoned slot is reused first";
  // c stays claimed by this (live) process: never taken over, even by another claimer.
  const Pool::Claimer other{static_cast<std::uint32_t>(::getpid()), me().start_time + 1};
  auto d = f.pool.claim(0, other);
  ASSERT_TRUE(d);
  EXPECT_EQ(d->slot, a->slot);
  EXPECT_FALSE(f.pool.claim(0, other)) << "both slots are being written by live claimers";
  // A claimer that died mid-write: its slot is taken over with a new odd generation.
  const pid_t dead = ::fork();
  if (dead == 0) ::_exit(0);
  ::waitpid(dead, nullptr, 0);
  PoolFixture g({4096, 2});
  auto x = g.pool.claim(0, {static_cast<std::uint32_t>(dead), 12345});
  auto y = g.pool.claim(0, {static_cast<std::uint32_t>(dead), 12345});
  ASSERT_TRUE(x && y);
  auto z = g.pool.claim(0, me());
  ASSERT_TRUE(z) << "the dead writer's slots are free";
  EXPECT_EQ(z->gen % 2, 1u);
  EXPECT_GT(z->gen, std::max(x->gen, y->gen) - 1);
}

TEST(Pool, PinAndClaimRacingNeverBothWin) {
  // Thread A claims and publishes slot generations over and over; thread B pins whatever was
  // published last and checks the bytes are not rewritten while it holds the pin.
  PoolFixture f({64, 2});
  std::atomic<std::uint64_t> last{0};  // (slot << 32) | gen
  std::atomic<bool> stop{false};
  std::atomic<std::uint64_t> torn{0}, pinned{0};
  std::thread writer([&] {
    for (std::uint32_t i = 1; !stop.load(std::memory_order_relaxed); ++i) {
      auto c = f.pool.claim(0, me());
      if (!c) continue;
      std::memset(f.pool.data(c->slot), static_cast<int>(i & 0xff), 64);
      const auto gen = f.pool.publish(*c, i);
      last.store((std::uint64_t{c->slot} << 32) | gen, std::memory_order_release);
    }
  });
  const horus_test::Deadline deadline(std::chrono::milliseconds(300));
  while (!deadline.expired()) {
    const auto v = last.load(std::memory_order_acquire);
    const auto slot = static_cast<std::uint32_t>(v >> 32);
    const auto gen = v & 0xffffffffu;
    if (gen == 0 || !f.pool.pin(slot, gen, 0)) continue;
    ++pinned;
    const std::uint8_t* p = f.pool.data(slot);
    std::uint8_t first = std::atomic_ref<const std::uint8_t>(p[0]).load(std::memory_order_relaxed);
    for (int k = 0; k < 50; ++k)
      for (int j = 0; j < 64; ++j)
        if (std::atomic_ref<const std::uint8_t>(p[j]).load(std::memory_order_relaxed) != first) ++torn;
    f.pool.unpin(slot, 0);
  }
  stop = true;
  writer.join();
  EXPECT_GT(pinned.load(), 0u);
  EXPECT_EQ(torn.load(), 0u) << "a pinned slot was rewritten";
}

// -- Topic<T> on the pool, in one process --------------------------------------

Image gradient(std::uint32_t h, std::uint32_t w, std::uint8_t seed) {
  Image img(h, w, ImageEncoding::Rgb8);
  auto d = img.data_mut();
  for (std::size_t i = 0; i < d.size(); ++i) d[i] = static_cast<std::uint8_t>(i * 13 + seed);
  return img;
}

class PoolTopic : public ::testing::TestWithParam<horus::Backend> {
 protected:
  TopicOptions opts(std::uint32_t capacity = 4) const { return TopicOptions{GetParam(), capacity, std::nullopt}; }
};

TEST_P(PoolTopic, AReceivedImageBorrowsThePoolSlotAndWritesCopyFirst) {
  const auto name = horus_test::unique_name("pool.borrow");
  auto pub = Topic<Image>::open(name, opts());
  ASSERT_TRUE(pub) << pub.error().message();
  auto sub1 = Topic<Image>::open(name, opts());
  auto sub2 = Topic<Image>::open(name, opts());
  ASSERT_TRUE(sub1 && sub2);
  static_assert(Topic<Image>::kPooled && !Topic<Image>::kSerialized);
  const Image sent = gradient(48, 64, 1);
  pub->send(sent);
  auto a = sub1->recv();
  auto b = sub2->recv();
  ASSERT_TRUE(a && b);
  EXPECT_EQ(*a, sent);
  EXPECT_TRUE(a->buffer().borrowed());
  EXPECT_EQ(a->data().data(), b->data().data()) << "both subscribers read the same pool slot";
  // A write copies first: the other subscriber's image is unchanged.
  a->set_pixel(0, 0, {9, 9, 9});
  EXPECT_FALSE(a->buffer().borrowed());
  EXPECT_EQ(*b, sent);
  const Image copy = *b;  // a copy owns its bytes
  EXPECT_FALSE(copy.buffer().borrowed());
  EXPECT_EQ(copy, sent);
  EXPECT_EQ(pub->max_message_size(), Image::kDefaultSlotBytes);
}

TEST_P(PoolTopic, EveryLargeDataTypeTravels) {
  using namespace horus::msg;
  const auto base = horus_test::unique_name("pool.types");
  Topic<PointCloud> pc_pub(base + ".pc"), pc_sub(base + ".pc");
  auto cloud = PointCloud::from_xyz(std::vector<std::array<float, 3>>{{1, 2, 3}, {4, 5, 6}});
  pc_pub.send(cloud);
  auto pc = pc_sub.recv();
  ASSERT_TRUE(pc);
  EXPECT_EQ(*pc, cloud);
  Topic<DepthImage> d_pub(base + ".depth"), d_sub(base + ".depth");
  auto depth = DepthImage::meters(3, 4);
  depth.set_depth(1, 2, 1.5f);
  d_pub.send(depth);
  auto d = d_sub.recv();
  ASSERT_TRUE(d);
  EXPECT_EQ(*d, depth);
  EXPECT_FLOAT_EQ(*d->get_depth(1, 2), 1.5f);
  Topic<Tensor> t_pub(base + ".tensor"), t_sub(base + ".tensor");
  Tensor t({2, 3}, TensorDtype::F32);
  t.data_mut()[5] = 7;
  t_pub.send(t);
  auto tt = t_sub.recv();
  ASSERT_TRUE(tt);
  EXPECT_EQ(*tt, t);
}

TEST_P(PoolTopic, ALoanIsFilledInPlaceAndSentWithoutACopy) {
  const auto name = horus_test::unique_name("pool.loan");
  auto pub = Topic<Image>::open(name, opts());
  auto sub = Topic<Image>::open(name, opts());
  ASSERT_TRUE(pub && sub);
  auto desc = Image::describe(1080, 1920, ImageEncoding::Rgb8);
  ASSERT_TRUE(desc);
  auto loan = pub->loan(*desc);
  ASSERT_TRUE(loan) << loan.error().message();
  EXPECT_EQ((*loan)->width(), 1920u);
  EXPECT_EQ((*loan)->data().size(), 1920u * 1080u * 3u);
  const std::uint8_t* where = (*loan)->data().data();
  auto bytes = (*loan)->data_mut();
  EXPECT_EQ(bytes.data(), where) << "a loan is written in place";
  for (std::size_t i = 0; i < bytes.size(); i += 4096) bytes[i] = static_cast<std::uint8_t>(i >> 12);
  (*loan)->set_timestamp_ns(77);
  pub->send(std::move(*loan));
  auto got = sub->recv();
  ASSERT_TRUE(got);
  EXPECT_EQ(got->data().data(), where) << "the subscriber reads the very bytes the publisher wrote";
  EXPECT_EQ(got->timestamp_ns(), 77u);
  for (std::size_t i = 0; i < got->data().size(); i += 4096) ASSERT_EQ(got->data()[i], static_cast<std::uint8_t>(i >> 12));
  EXPECT_EQ(pub->metrics().messages_sent(), 1u);
}

TEST_P(PoolTopic, LoansDroppedUnsentComeBackAndLimitsAreClearErrors) {
  const auto name = horus_test::unique_name("pool.loanlimits");
  auto pub = Topic<Image>::open(name, TopicOptions{GetParam(), 2, std::size_t{1} << 20});
  ASSERT_TRUE(pub) << pub.error().message();
  auto sub = Topic<Image>::open(name, TopicOptions{GetParam(), std::nullopt, std::nullopt});
  ASSERT_TRUE(sub) << sub.error().message();
  // 2 ring slots per lane: 4 pool slots. Four loans at once, then the fifth is refused.
  const auto desc = *Image::describe(100, 100, ImageEncoding::Mono8);
  std::vector<horus::Loan<Image>> loans;
  for (int i = 0; i < 4; ++i) {
    auto l = pub->loan(desc);
    ASSERT_TRUE(l) << i << ": " << l.error().message();
    loans.push_back(std::move(*l));
  }
  auto fifth = pub->loan(desc);
  ASSERT_FALSE(fifth);
  EXPECT_EQ(fifth.error().code(), horus::Errc::LimitReached);
  EXPECT_NE(fifth.error().message().find("pool slot"), std::string::npos) << fifth.error().message();
  loans.clear();  // dropped unsent: the slots come back
  for (int i = 0; i < 8; ++i) {
    auto l = pub->loan(desc);
    ASSERT_TRUE(l) << "round " << i << ": " << l.error().message();
    pub->send(std::move(*l));
  }
  // Too large for the 1 MiB slots, by loan and by send.
  auto big = pub->loan(*Image::describe(1080, 1920, ImageEncoding::Rgb8));
  ASSERT_FALSE(big);
  EXPECT_EQ(big.error().code(), horus::Errc::MessageTooLarge);
  EXPECT_NE(big.error().message().find("6220800"), std::string::npos) << big.error().message();
  auto r = pub->send_blocking(gradient(1080, 1920, 0), std::chrono::milliseconds(10));
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code(), horus::Errc::MessageTooLarge);
  // Another slot size is a configuration mismatch.
  auto other = Topic<Image>::open(name, TopicOptions{GetParam(), std::nullopt, std::size_t{2} << 20});
  ASSERT_FALSE(other);
  EXPECT_EQ(other.error().code(), horus::Errc::ConfigMismatch);
}

TEST_P(PoolTopic, AHeldImageIsNeverRewrittenAndHoldingEverySlotRefusesSends) {
  const auto name = horus_test::unique_name("pool.hold");
  auto pub = Topic<Image>::open(name, opts(2));  // 4 pool slots for the publisher
  auto sub = Topic<Image>::open(name, opts(2));
  ASSERT_TRUE(pub && sub);
  std::deque<Image> held;
  std::vector<Image> sent;
  for (std::uint8_t i = 0; i < 4; ++i) {
    sent.push_back(gradient(8, 8, i));
    pub->send(sent.back());
    auto m = sub->recv();
    ASSERT_TRUE(m);
    held.push_back(std::move(*m));
  }
  // All four slots pinned: the next send is refused and counted, nothing is overwritten.
  pub->send(gradient(8, 8, 99));
  EXPECT_EQ(pub->metrics().send_failures(), 1u);
  auto r = pub->send_blocking(gradient(8, 8, 99), std::chrono::milliseconds(5));
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code(), horus::Errc::LimitReached);
  for (std::size_t i = 0; i < held.size(); ++i) EXPECT_EQ(held[i], sent[i]) << i;
  held.pop_front();  // one slot free again
  pub->send(gradient(8, 8, 50));
  auto m = sub->recv();
  ASSERT_TRUE(m);
  EXPECT_EQ(*m, gradient(8, 8, 50));
  for (std::size_t i = 0; i < held.size(); ++i) EXPECT_EQ(held[i], sent[i + 1]) << i;
}

TEST_P(PoolTopic, AMessageWhoseSlotWasReusedCountsAsDropped) {
  const auto name = horus_test::unique_name("pool.reuse");
  auto pub = Topic<Image>::open(name, opts(2));  // ring: 2 per lane; pool: 4 per lane
  auto holder = Topic<Image>::open(name, opts(2));
  auto slow = Topic<Image>::open(name, opts(2));
  ASSERT_TRUE(pub && holder && slow);
  // The holder keeps three slots pinned: one free slot is left for the two ring messages.
  std::vector<Image> held;
  for (std::uint8_t i = 0; i < 3; ++i) {
    pub->send(gradient(4, 4, i));
    auto m = holder->recv();
    ASSERT_TRUE(m);
    held.push_back(std::move(*m));
  }
  while (slow->recv()) {
  }
  const auto before = slow->dropped_count();
  pub->send(gradient(4, 4, 10));
  pub->send(gradient(4, 4, 11));  // reuses the slot of message 10, still unread by `slow`
  auto got = slow->recv();
  ASSERT_TRUE(got);
  EXPECT_EQ(*got, gradient(4, 4, 11));
  EXPECT_FALSE(slow->recv());
  EXPECT_EQ(slow->dropped_count(), before + 1) << "the lost message is counted";
  EXPECT_GE(pub->dropped_count(), 1u);
}

TEST_P(PoolTopic, ALoanOutlivingItsTopicIsNeverRewritten) {
  const auto name = horus_test::unique_name("pool.orphan");
  auto sub = Topic<Image>::open(name, opts(2));
  ASSERT_TRUE(sub);
  std::optional<horus::Loan<Image>> orphan;
  {
    auto pub = Topic<Image>::open(name, opts(2));
    ASSERT_TRUE(pub);
    auto l = pub->loan(*Image::describe(8, 8, ImageEncoding::Mono8));
    ASSERT_TRUE(l);
    (*l)->fill({0xAA});
    orphan.emplace(std::move(*l));
  }  // the handle is gone, its lane free, the loan still lent
  auto next = Topic<Image>::open(name, opts(2));
  ASSERT_TRUE(next);
  for (std::uint8_t i = 0; i < 12; ++i) {
    Image img(8, 8, ImageEncoding::Mono8);
    img.fill({i});
    next->send(img);
    while (sub->recv()) {
    }
  }
  for (std::uint8_t b : (*orphan)->data()) ASSERT_EQ(b, 0xAA) << "the lent slot was reused";
  next->send(std::move(*orphan));  // not this handle's: sent by copy
  orphan.reset();
  auto got = sub->recv();
  ASSERT_TRUE(got);
  EXPECT_EQ(got->data()[0], 0xAA);
}

TEST_P(PoolTopic, TrySendNeverTakesTheSlotOfAnUnreadMessage) {
  const auto name = horus_test::unique_name("pool.trysend");
  auto pub = Topic<Image>::open(name, opts(2));  // ring 2 per lane, pool 4 per lane
  auto holder = Topic<Image>::open(name, opts(2));
  auto slow = Topic<Image>::open(name, opts(2));
  ASSERT_TRUE(pub && holder && slow);
  std::vector<Image> held;
  for (std::uint8_t i = 0; i < 3; ++i) {
    ASSERT_TRUE(pub->try_send(gradient(4, 4, i)));
    auto m = holder->recv();
    ASSERT_TRUE(m);
    held.push_back(std::move(*m));
    while (slow->recv()) {
    }
  }
  ASSERT_TRUE(pub->try_send(gradient(4, 4, 4)));  // the last free slot
  ASSERT_TRUE(holder->recv());                    // read (and dropped) by the holder, not by `slow`
  EXPECT_FALSE(pub->try_send(gradient(4, 4, 5)))  // would take message 4's slot: refused
      << "the ring had room, the pool did not";
  auto m = slow->recv();
  ASSERT_TRUE(m);
  EXPECT_EQ(*m, gradient(4, 4, 4));
  EXPECT_EQ(slow->dropped_count(), 0u);
  m.reset();
  EXPECT_TRUE(pub->try_send(gradient(4, 4, 5)));  // read by all now: its slot may go
  EXPECT_EQ(*slow->recv(), gradient(4, 4, 5));
  // Message 5 unread by the holder, three slots pinned: send_blocking waits, then refuses once.
  const auto before = pub->metrics().send_failures();
  auto r = pub->send_blocking(gradient(4, 4, 6), std::chrono::milliseconds(2));
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code(), horus::Errc::LimitReached) << r.error().message();
  EXPECT_EQ(pub->metrics().send_failures(), before + 1);
  EXPECT_EQ(pub->dropped_count(), 0u) << "nothing unread was lost";
}

TEST_P(PoolTopic, AForkedChildDroppingAnInheritedImageLeavesTheParentsPinAlone) {
  const auto name = horus_test::unique_name("pool.fork");
  auto pub = Topic<Image>::open(name, opts(2));
  auto sub = Topic<Image>::open(name, opts(2));
  ASSERT_TRUE(pub && sub);
  pub->send(gradient(4, 4, 1));
  auto held = sub->recv();
  ASSERT_TRUE(held);
  const auto pinned = [&] { return pub->loan(*Image::describe(4, 4, ImageEncoding::Rgb8)); };
  const pid_t child = ::fork();
  if (child == 0) {
    held.reset();  // must not unpin the parent's slot
    ::_exit(0);
  }
  int status = 0;
  ASSERT_EQ(::waitpid(child, &status, 0), child);
  // The parent's image still pins its slot: four loans are possible only if it did not.
  std::vector<horus::Loan<Image>> loans;
  for (int i = 0; i < 4; ++i)
    if (auto l = pinned()) loans.push_back(std::move(*l));
  EXPECT_EQ(loans.size(), 3u) << "the parent's pin survived its child";
  EXPECT_EQ(*held, gradient(4, 4, 1));
}

INSTANTIATE_TEST_SUITE_P(Backends, PoolTopic,
                         ::testing::Values(horus::Backend::InProcess, horus::Backend::SharedMemory),
                         [](const auto& p) { return std::string(horus::to_string(p.param)); });

}  // namespace
