// The ring region itself: layout, formatting and validation of a region's header.
#include <gtest/gtest.h>

#include <array>
#include <cstring>
#include <string>

#include "horus/shm/heap_region.hpp"
#include "horus/shm/ring.hpp"

using namespace horus::shm;

namespace {
const RingConfig kCfg{8, 24, 0x1234};

HeapRegion formatted() {
  HeapRegion region(Ring::required_size(kCfg));
  Ring::format(region.data(), kCfg);
  return region;
}

std::string validate(const HeapRegion& r, std::size_t size) { return Ring::validate(r.data(), size).value_or(""); }
}  // namespace

TEST(RingLayout, SmallSlotsNeverStraddleACacheLine) {
  for (std::uint32_t payload = 1; payload <= 56; ++payload) {
    const auto stride = slot_stride_for(payload);
    EXPECT_GE(stride, 8 + payload);
    EXPECT_EQ(64 % stride, 0u) << payload;
  }
  EXPECT_EQ(slot_stride_for(100) % 64, 0u);
}

TEST(RingLayout, AFormattedRegionValidatesAndKeepsItsConfiguration) {
  auto region = formatted();
  EXPECT_EQ(validate(region, region.size()), "");
  const Ring ring = Ring::attach(region.data());
  EXPECT_EQ(ring.capacity(), 8u);
  EXPECT_EQ(ring.stride(), slot_stride_for(24));
  EXPECT_EQ(ring.header().type_hash, 0x1234u);
  EXPECT_EQ(ring.publisher_count(), 0u);
  EXPECT_EQ(ring.subscriber_count(), 0u);
}

// The high-water marks of lanes and subscriber entries live in shared memory: a hostile writer
// that raises them after attach must not make a reader or the control plane index past the
// tables (ASan checks this in the asan pass).
TEST(RingLayout, HighWaterMarksRaisedByAnotherWriterStayWithinTheTables) {
  auto region = formatted();
  const Ring ring = Ring::attach(region.data());
  RingReader<std::array<std::byte, 24>> reader(ring, 1);
  ASSERT_TRUE(reader.subscribe());
  ring.header().lane_hwm.store(1u << 30);
  ring.header().sub_hwm.store(1u << 30);
  std::array<std::byte, 24> out{};
  EXPECT_FALSE(reader.read(out));
  EXPECT_FALSE(reader.has_message());
  EXPECT_EQ(reader.pending(), 0u);
  EXPECT_FALSE(reader.read_latest(out));
  EXPECT_EQ(ring.subscriber_count(), 1u);
  EXPECT_EQ(ring.publisher_count(), 0u);
  EXPECT_EQ(ring.undetected_losses(), 0u);
  EXPECT_EQ(ring.total_sent(), 0u);
}

TEST(RingLayout, ACorruptHeaderIsRejectedWithAReason) {
  {
    auto region = formatted();
    static_cast<RingHeader*>(region.data())->magic = 42;
    EXPECT_NE(validate(region, region.size()).find("bad magic"), std::string::npos);
  }
  {
    auto region = formatted();
    static_cast<RingHeader*>(region.data())->layout_version = 99;
    EXPECT_NE(validate(region, region.size()).find("layout version 99"), std::string::npos);
  }
  {
    auto region = formatted();
    static_cast<RingHeader*>(region.data())->capacity = 6;
    EXPECT_NE(validate(region, region.size()).find("not a power of two"), std::string::npos);
  }
  {
    auto region = formatted();
    static_cast<RingHeader*>(region.data())->slots_offset += 64;
    EXPECT_NE(validate(region, region.size()).find("corrupt ring header"), std::string::npos);
  }
  {
    auto region = formatted();
    EXPECT_NE(validate(region, region.size() - 1).find("the region has"), std::string::npos);
    EXPECT_NE(validate(region, 16).find("too small"), std::string::npos);
  }
}

TEST(RingLayout, LanesAndSubscriberEntriesAreClaimedOnceAndReleasedByTheirOwner) {
  auto region = formatted();
  const Ring ring = Ring::attach(region.data());
  auto a = ring.claim_lane(1);
  auto b = ring.claim_lane(2);
  ASSERT_TRUE(a && b);
  EXPECT_NE(*a, *b);
  ring.release_lane(*a, 2);  // not the owner: ignored
  EXPECT_EQ(ring.publisher_count(), 2u);
  ring.release_lane(*a, 1);
  EXPECT_EQ(ring.publisher_count(), 1u);
  for (std::uint32_t i = 0; i < kMaxSubscribers; ++i) ASSERT_TRUE(ring.add_subscriber(100 + i));
  EXPECT_FALSE(ring.add_subscriber(999));
  EXPECT_EQ(ring.subscriber_count(), kMaxSubscribers);
}
