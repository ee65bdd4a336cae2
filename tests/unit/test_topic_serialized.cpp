// Topic<T> for variable-size messages (vectors, strings): serialized into slots.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <cstring>
#include <cstdint>
#include <ostream>
#include <string>
#include <thread>
#include <vector>

#include "horus/msg/image.hpp"
#include "horus/topic.hpp"
#include "test_support.hpp"

namespace serial_test {

struct Blob {
  std::string label;
  std::vector<std::int32_t> values;
  std::uint64_t seq{};
  friend bool operator==(const Blob&, const Blob&) = default;
};
HORUS_REFLECT(Blob, label, values, seq)
inline void PrintTo(const Blob& b, std::ostream* os) {
  *os << "Blob{" << b.label << ", " << b.values.size() << " values, seq " << b.seq << "}";
}

/// A type that declares its own default slot size.
struct Small {
  static constexpr std::size_t kDefaultSlotBytes = 64;
  std::vector<std::uint8_t> bytes;
};
HORUS_REFLECT(Small, bytes)

Blob make_blob(std::uint64_t seq, std::size_t n) {
  Blob b;
  b.seq = seq;
  b.label = "blob-" + std::to_string(seq);
  for (std::size_t i = 0; i < n; ++i) b.values.push_back(static_cast<std::int32_t>(seq * 1000 + i));
  return b;
}

}  // namespace serial_test

namespace {
using horus::Errc;
using horus::Topic;
using horus_test::unique_name;
using serial_test::Blob;
using serial_test::make_blob;

static_assert(Topic<Blob>::kSerialized);
static_assert(!Topic<horus_test::Stamp>::kSerialized);

TEST(SerializedTopic, MessagesOfDifferentSizesArriveIntactAndInOrder) {
  const auto name = unique_name("serial");
  Topic<Blob> pub(name), sub(name);
  ASSERT_EQ(pub.capacity(), 16u);
  for (std::uint64_t i = 0; i < 16; ++i) pub.send(make_blob(i, i * 37));  // 0 to 555 values
  for (std::uint64_t i = 0; i < 16; ++i) {
    auto m = sub.recv();
    ASSERT_TRUE(m) << "message " << i;
    EXPECT_EQ(*m, make_blob(i, i * 37));
  }
  EXPECT_FALSE(sub.recv());
  EXPECT_EQ(sub.metrics().messages_received(), 16u);
  EXPECT_EQ(sub.metrics().decode_failures(), 0u);
}

TEST(SerializedTopic, DefaultSlotSizeIs64KiBOrTheTypesOwn) {
  Topic<Blob> blob(unique_name("serial"));
  EXPECT_EQ(blob.max_message_size(), 64u * 1024u);
  Topic<serial_test::Small> small(unique_name("serial"));
  EXPECT_EQ(small.max_message_size(), 64u);
  Topic<horus_test::Stamp> fixed(unique_name("serial"));
  EXPECT_EQ(fixed.max_message_size(), sizeof(horus_test::Stamp));
}

TEST(SerializedTopic, AMessageOverTheSlotSizeIsRefusedCountedAndNamedBySendBlocking) {
  const auto name = unique_name("serial");
  auto pub = Topic<Blob>::with_capacity(name, 8, 256);
  ASSERT_TRUE(pub) << pub.error().message();
  Topic<Blob> sub(name);
  EXPECT_EQ(pub->max_message_size(), 256u);
  // label "blob-1" (4 + 6) + values (4 + 4n) + seq 8 = 22 + 4n bytes: n = 58 fits (254), 59 does not (258).
  pub->send(make_blob(1, 58));
  pub->send(make_blob(2, 59));
  EXPECT_EQ(pub->metrics().send_failures(), 1u);
  EXPECT_EQ(pub->metrics().messages_sent(), 1u);
  auto r = pub->send_blocking(make_blob(3, 59), std::chrono::milliseconds(1));
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code(), Errc::MessageTooLarge);
  EXPECT_NE(r.error().message().find("258 bytes"), std::string::npos) << r.error().message();
  EXPECT_NE(r.error().message().find("256 bytes"), std::string::npos) << r.error().message();
  auto t = pub->try_send(make_blob(4, 1000));
  ASSERT_FALSE(t);
  EXPECT_EQ(t.error().seq, 4u);  // the message comes back
  EXPECT_EQ(pub->metrics().send_failures(), 3u);
  auto m = sub.recv();
  ASSERT_TRUE(m);
  EXPECT_EQ(m->seq, 1u);
  EXPECT_FALSE(sub.recv());
}

TEST(SerializedTopic, SlotSizeMustMatchAnExistingTopicUnlessLeftOut) {
  const auto name = unique_name("serial");
  auto a = Topic<Blob>::with_capacity(name, 8, 1000);
  ASSERT_TRUE(a);
  auto b = Topic<Blob>::with_capacity(name, 8, 2000);
  ASSERT_FALSE(b);
  EXPECT_EQ(b.error().code(), Errc::ConfigMismatch);
  EXPECT_NE(b.error().message().find("slot_size 1000"), std::string::npos) << b.error().message();
  auto c = Topic<Blob>::open(name);
  ASSERT_TRUE(c);
  EXPECT_EQ(c->max_message_size(), 1000u);
}

TEST(SerializedTopic, SlotSizeZeroIsRejected) {
  auto r = Topic<Blob>::with_capacity(unique_name("serial"), 8, 0);
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code(), Errc::InvalidArgument);
}

TEST(SerializedTopic, ASerializedAndAFixedTypeCannotShareAName) {
  const auto name = unique_name("serial");
  Topic<Blob> a(name);
  auto b = Topic<horus_test::Stamp>::open(name);
  ASSERT_FALSE(b);
  EXPECT_EQ(b.error().code(), Errc::TypeMismatch);
}

TEST(SerializedTopic, ReadLatestReturnsTheNewestMessage) {
  const auto name = unique_name("serial");
  Topic<Blob> pub(name), sub(name);
  for (std::uint64_t i = 0; i < 5; ++i) pub.send(make_blob(i, i));
  auto m = sub.read_latest();
  ASSERT_TRUE(m);
  EXPECT_EQ(*m, make_blob(4, 4));
  EXPECT_FALSE(sub.recv());
}

TEST(SerializedTopic, AFullRingDropsTheOldestAndCountsIt) {
  const auto name = unique_name("serial");
  auto pub = Topic<Blob>::with_capacity(name, 4, 4096);
  ASSERT_TRUE(pub);
  Topic<Blob> sub(name);
  for (std::uint64_t i = 0; i < 10; ++i) pub->send(make_blob(i, 10));
  std::vector<std::uint64_t> got;
  while (auto m = sub.recv()) got.push_back(m->seq);
  EXPECT_EQ(got, (std::vector<std::uint64_t>{6, 7, 8, 9}));
  EXPECT_EQ(sub.dropped_count(), 6u);
}

TEST(SerializedTopic, ConcurrentPublishersDeliverIntactMessages) {
  const auto name = unique_name("serial");
  auto sub = Topic<Blob>::with_capacity(name, 64, 8192);
  ASSERT_TRUE(sub);
  constexpr std::uint64_t kPerPublisher = 2000;
  auto publish = [&](std::uint64_t base) {
    Topic<Blob> pub(name);
    for (std::uint64_t i = 0; i < kPerPublisher; ++i) {
      const Blob b = make_blob(base + i, (i * 7) % 300);
      while (!pub.try_send(b)) std::this_thread::yield();
    }
  };
  std::thread t1(publish, 0), t2(publish, 1'000'000);
  std::uint64_t received = 0;
  const horus_test::Deadline deadline(std::chrono::seconds(60));
  while (received < 2 * kPerPublisher && !deadline.expired()) {
    if (auto m = sub->recv()) {
      const std::uint64_t i = m->seq >= 1'000'000 ? m->seq - 1'000'000 : m->seq;
      ASSERT_EQ(*m, make_blob(m->seq, (i * 7) % 300));
      ++received;
    } else {
      std::this_thread::yield();
    }
  }
  t1.join();
  t2.join();
  EXPECT_EQ(received, 2 * kPerPublisher);
  EXPECT_EQ(sub->dropped_count(), 0u);
}

TEST(SerializedTopic, MessagesUpToExactlyTheSlotSizeArriveIntactWhateverTheirLengthModuloEight) {
  const auto name = unique_name("serial");
  auto pub = Topic<Blob>::with_capacity(name, 16, 256);
  ASSERT_TRUE(pub);
  Topic<Blob> sub(name);
  // Encoded size = (4 + label) + (4 + 4n) + 8: with n = 58 and labels of 0 to 8 characters,
  // 248 to 256 bytes, every remainder modulo 8.
  std::vector<Blob> sent;
  for (std::size_t len = 0; len <= 8; ++len) {
    Blob b = make_blob(len, 58);
    b.label = std::string(len, 'x');
    ASSERT_EQ(horus::codec::encoded_size(b), 248 + len);
    pub->send(b);
    sent.push_back(b);
  }
  Blob over = make_blob(99, 58);
  over.label = std::string(9, 'x');  // 257 bytes
  pub->send(over);
  EXPECT_EQ(pub->metrics().send_failures(), 1u);
  for (const auto& b : sent) {
    auto m = sub.recv();
    ASSERT_TRUE(m);
    EXPECT_EQ(*m, b);
  }
  EXPECT_FALSE(sub.recv());
}

// A slot written with bytes that do not decode as the topic's type (what a damaged shared
// segment could hold): skipped, counted, and later messages still arrive.
TEST(SerializedTopic, AMessageThatDoesNotDecodeIsSkippedCountedAndLaterOnesArrive) {
  const auto name = unique_name("serial");
  Topic<Blob> sub(name);
  const horus::detail::TypeInfo type{horus::type_name<Blob>(), horus::type_hash<Blob>, 64 * 1024, true};
  auto core = horus::detail::open_core(name, type, {}, *horus::Settings::current());
  ASSERT_TRUE(core) << core.error().message();
  horus::shm::RingWriter<horus::shm::ByteMessage> raw((*core)->ring, horus::detail::next_token());
  ASSERT_TRUE(raw.ensure_lane());
  const std::byte garbage[5] = {std::byte{0xff}, std::byte{0xff}, std::byte{0xff}, std::byte{0xff}, std::byte{1}};
  raw.write_bytes(garbage);
  Topic<Blob> pub(name);
  pub.send(make_blob(7, 3));
  auto m = sub.recv();
  ASSERT_TRUE(m);
  EXPECT_EQ(*m, make_blob(7, 3));
  EXPECT_EQ(sub.metrics().decode_failures(), 1u);
  EXPECT_EQ(sub.metrics().messages_received(), 1u);
  EXPECT_FALSE(sub.recv());
}

TEST(SerializedTopic, ASlotWhoseLengthExceedsTheLimitIsSkippedAsCorruptNotReturned) {
  const auto name = unique_name("serial");
  auto pub = Topic<Blob>::with_capacity(name, 4, 1024);
  ASSERT_TRUE(pub);
  Topic<Blob> sub(name);
  pub->send(make_blob(1, 2));
  // The first publisher writes lane 0, slot 0: [seq][length][bytes]. Damage the length.
  auto core = horus::detail::open_core(name, {horus::type_name<Blob>(), horus::type_hash<Blob>, 1024, true}, {},
                                       *horus::Settings::current());
  ASSERT_TRUE(core);
  const std::uint64_t bad = 1024 + 64;
  std::memcpy((*core)->ring.lane_slots(0) + 8, &bad, 8);
  EXPECT_FALSE(sub.read_latest());
  pub->send(make_blob(2, 2));
  auto m = sub.recv();
  ASSERT_TRUE(m);
  EXPECT_EQ(m->seq, 2u);
  EXPECT_EQ(sub.metrics().decode_failures(), 1u);
  EXPECT_EQ(sub.metrics().messages_received(), 1u);
  EXPECT_EQ(sub.dropped_count(), 0u);
}

TEST(SerializedTopic, OverwritingSendsUnderLoadDeliverIntactMessagesAndCountEveryLoss) {
  const auto name = unique_name("serial");
  auto sub = Topic<Blob>::with_capacity(name, 2, 4096);
  ASSERT_TRUE(sub);
  constexpr std::uint64_t kSent = 20000;
  std::atomic<bool> done{false};
  std::thread publisher([&] {
    Topic<Blob> pub(name);
    for (std::uint64_t i = 0; i < kSent; ++i) pub.send(make_blob(i, i % 200));
    done.store(true);
  });
  std::uint64_t received = 0, last = 0;
  bool first = true;
  const horus_test::Deadline deadline(std::chrono::seconds(60));
  for (;;) {
    const bool finished = done.load();
    while (auto m = sub->recv()) {
      ASSERT_EQ(*m, make_blob(m->seq, m->seq % 200));
      if (!first) {
        ASSERT_GT(m->seq, last);
      }
      first = false;
      last = m->seq;
      ++received;
    }
    if (finished || deadline.expired()) break;
    std::this_thread::yield();
  }
  publisher.join();
  EXPECT_GT(received, 0u);
  EXPECT_EQ(received + sub->dropped_count(), kSent);
  EXPECT_EQ(sub->metrics().messages_received(), received);
}

TEST(SerializedTopic, AMovedHandleKeepsItsSubscriptionLaneAndCounters) {
  const auto name = unique_name("serial");
  Topic<Blob> a(name);
  Topic<Blob> pub(name);
  pub.send(make_blob(1, 1));
  ASSERT_TRUE(a.recv());
  Topic<Blob> b(unique_name("serial"));
  b = std::move(a);
  pub.send(make_blob(2, 1));
  auto m = b.recv();
  ASSERT_TRUE(m);
  EXPECT_EQ(m->seq, 2u);
  EXPECT_EQ(b.metrics().messages_received(), 2u);
  Topic<Blob> c(std::move(pub));
  c.send(make_blob(3, 1));
  ASSERT_TRUE(b.recv());
  EXPECT_EQ(c.metrics().messages_sent(), 3u);  // two before the move, one after
}

TEST(SerializedTopic, AFullHdRgbaImageTravelsThroughADefaultImageTopic) {
  const auto name = unique_name("serial");
  horus::Topic<horus::msg::Image> pub(name), sub(name);
  horus::msg::Image img(1080, 1920, horus::msg::ImageEncoding::Rgba8);
  auto px = img.data_mut();
  for (std::size_t i = 0; i < px.size(); ++i) px[i] = static_cast<std::uint8_t>(i * 7);
  ASSERT_TRUE(img.set_frame_id("camera_front"));
  pub.send(img);
  auto m = sub.recv();
  ASSERT_TRUE(m);
  EXPECT_EQ(*m, img);
  EXPECT_EQ(pub.metrics().send_failures(), 0u);
}

TEST(SerializedTopic, CapacityMismatchAndOversizedSlotsAreRejected) {
  const auto name = unique_name("serial");
  auto a = Topic<Blob>::with_capacity(name, 8, 1000);
  ASSERT_TRUE(a);
  auto b = Topic<Blob>::with_capacity(name, 16, 1000);
  ASSERT_FALSE(b);
  EXPECT_EQ(b.error().code(), Errc::ConfigMismatch);
  auto big = Topic<Blob>::with_capacity(unique_name("serial"), 4, (std::size_t{1} << 30));
  ASSERT_FALSE(big);
  EXPECT_EQ(big.error().code(), Errc::InvalidArgument);
  EXPECT_NE(big.error().message().find("out of range"), std::string::npos) << big.error().message();
}

}  // namespace
