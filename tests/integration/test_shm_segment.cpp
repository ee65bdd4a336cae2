// The shared-memory segment of a topic (backend_shm/shm_segment.hpp), with real processes:
// children made with fork() open the same segment, publish, subscribe, and get killed.
#include <gtest/gtest.h>

#include <fcntl.h>
#include <signal.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdint>
#include <cstdlib>
#include <cstddef>
#include <cstring>
#include <string>
#include <thread>

#include "horus/shm/shm_segment.hpp"
#include "process_support.hpp"
#include "test_support.hpp"

namespace {

using horus::shm::Ring;
using horus::shm::RingReader;
using horus::shm::RingWriter;
using horus::shm::SegmentError;
using horus::shm::SegmentSpec;
using horus::shm::ShmSegment;
using horus_test::Pipe;
using horus_test::spawn;
using horus_test::Stamp;
using horus_test::wait_for;

// Every test process has its own namespace (checked for leaks after each test).
const std::string& test_ns() {
  static const std::string ns = "test" + std::to_string(::getpid());
  return ns;
}

SegmentSpec stamp_spec(std::uint32_t capacity = 16) {
  SegmentSpec s;
  s.type_name = "horus_test::Stamp";
  s.type_hash = horus::type_hash<Stamp>;
  s.payload_size = sizeof(Stamp);
  s.capacity = capacity;
  return s;
}

std::uint64_t token(std::uint32_t k) { return (static_cast<std::uint64_t>(::getpid()) << 32) | k; }

std::string topic_name(const std::string& base) {
  static int n = 0;
  return base + "." + std::to_string(n++);
}

bool shm_file_exists(const std::string& topic) {
  struct stat st{};
  return ::stat(("/dev/shm" + horus::shm::segment_name(test_ns(), topic)).c_str(), &st) == 0;
}

// CTest runs every test in its own process, so each test has its own namespace: after it,
// nothing of that namespace may remain in /dev/shm.
class ShmSegmentTest : public ::testing::Test {
 protected:
  void SetUp() override { (void)test_ns(); }  // fixed before any fork: children share it
  void TearDown() override {
    for (const auto& s : horus::shm::list_segments(test_ns())) {
      ADD_FAILURE() << "left in /dev/shm: " << s.name;
      ::shm_unlink(("/" + s.name).c_str());
    }
  }
};

TEST_F(ShmSegmentTest, IsCreatedOwnerOnlyAndRemovedWhenTheLastProcessDetaches) {
  const auto topic = topic_name("perm");
  {
    auto seg = ShmSegment::open(test_ns(), topic, stamp_spec());
    ASSERT_TRUE(seg) << seg.error().message;
    struct stat st{};
    ASSERT_EQ(::stat(("/dev/shm" + seg->name()).c_str(), &st), 0);
    EXPECT_EQ(st.st_mode & 0777, 0600u);
    EXPECT_EQ(seg->live_participants(), 1u);
  }
  EXPECT_FALSE(shm_file_exists(topic));
}

TEST_F(ShmSegmentTest, AWiderModeIsAppliedWhateverTheUmask) {
  const auto topic = topic_name("mode");
  auto spec = stamp_spec();
  spec.mode = 0660;
  const mode_t old = ::umask(077);
  auto seg = ShmSegment::open(test_ns(), topic, spec);
  ::umask(old);
  ASSERT_TRUE(seg) << seg.error().message;
  struct stat st{};
  ASSERT_EQ(::stat(("/dev/shm" + seg->name()).c_str(), &st), 0);
  EXPECT_EQ(st.st_mode & 0777, 0660u);
}

TEST_F(ShmSegmentTest, TwoAttachmentsShareOneRing) {
  const auto topic = topic_name("share");
  auto a = ShmSegment::open(test_ns(), topic, stamp_spec());
  auto b = ShmSegment::open(test_ns(), topic, stamp_spec());
  ASSERT_TRUE(a && b);
  EXPECT_EQ(a->live_participants(), 2u);
  RingReader<Stamp> reader(b->ring(), token(1));
  ASSERT_TRUE(reader.subscribe());
  RingWriter<Stamp> writer(a->ring(), token(2));
  ASSERT_TRUE(writer.ensure_lane());
  writer.write(Stamp::make(1, 42));
  Stamp out{};
  ASSERT_TRUE(reader.read(out));
  EXPECT_EQ(out.seq, 42u);
  EXPECT_TRUE(out.intact());
}

TEST_F(ShmSegmentTest, OpeningWithAnotherTypeNamesBothTypes) {
  const auto topic = topic_name("type");
  auto a = ShmSegment::open(test_ns(), topic, stamp_spec());
  ASSERT_TRUE(a);
  auto other = stamp_spec();
  other.type_name = "horus_test::Other";
  other.type_hash = horus::type_hash<horus_test::Other>;
  other.payload_size = sizeof(horus_test::Other);
  auto b = ShmSegment::open(test_ns(), topic, other);
  ASSERT_FALSE(b);
  EXPECT_EQ(b.error().kind, SegmentError::Kind::TypeMismatch);
  EXPECT_NE(b.error().message.find("carries horus_test::Stamp"), std::string::npos) << b.error().message;
  EXPECT_NE(b.error().message.find("as horus_test::Other"), std::string::npos) << b.error().message;
}

TEST_F(ShmSegmentTest, ARequiredCapacityMustMatchTheExistingSegment) {
  const auto topic = topic_name("cap");
  auto a = ShmSegment::open(test_ns(), topic, stamp_spec(16));
  ASSERT_TRUE(a);
  auto spec = stamp_spec(32);
  EXPECT_TRUE(ShmSegment::open(test_ns(), topic, spec));  // not required: accepts 16
  spec.capacity_required = true;
  auto b = ShmSegment::open(test_ns(), topic, spec);
  ASSERT_FALSE(b);
  EXPECT_EQ(b.error().kind, SegmentError::Kind::ConfigMismatch);
  EXPECT_NE(b.error().message.find("capacity 16"), std::string::npos) << b.error().message;
}

TEST_F(ShmSegmentTest, AnotherProcessReceivesEveryMessageOnceInOrder) {
  const auto topic = topic_name("order");
  auto seg = ShmSegment::open(test_ns(), topic, stamp_spec(1024));
  ASSERT_TRUE(seg);
  constexpr std::uint64_t kCount = 1000;
  Pipe ready;
  const pid_t child = spawn([&] {
    auto s = ShmSegment::open(test_ns(), topic, stamp_spec(1024));
    if (!s) return 10;
    RingReader<Stamp> reader(s->ring(), token(1));
    if (!reader.subscribe()) return 11;
    ready.signal();
    const horus_test::Deadline deadline(std::chrono::seconds(20));
    std::uint64_t next = 0;
    while (next < kCount && !deadline.expired()) {
      Stamp m{};
      if (!reader.read(m)) continue;
      if (m.seq != next || !m.intact()) return 12;
      ++next;
    }
    return next == kCount && reader.lost() == 0 ? 0 : 13;
  });
  ASSERT_TRUE(ready.wait());
  RingWriter<Stamp> writer(seg->ring(), token(2));
  ASSERT_TRUE(writer.ensure_lane());
  for (std::uint64_t i = 0; i < kCount; ++i) writer.write(Stamp::make(7, i));
  EXPECT_EQ(wait_for(child), 0);
}

TEST_F(ShmSegmentTest, ASegmentLeftByAKilledProcessIsReclaimedByTheNextOpen) {
  const auto topic = topic_name("reclaim");
  Pipe ready;
  const pid_t child = spawn([&] {
    auto s = ShmSegment::open(test_ns(), topic, stamp_spec());
    if (!s) return 10;
    RingWriter<Stamp> writer(s->ring(), token(1));
    writer.ensure_lane();
    writer.write(Stamp::make(1, 1));
    ready.signal();
    for (;;) ::pause();
  });
  ASSERT_TRUE(ready.wait());
  ::kill(child, SIGKILL);
  EXPECT_EQ(wait_for(child), 128 + SIGKILL);
  ASSERT_TRUE(shm_file_exists(topic));
  const auto listed = horus::shm::list_segments(test_ns());
  bool found_dead = false;
  for (const auto& info : listed)
    if (info.topic == topic && info.participants.size() == 1 && !info.participants[0].second) found_dead = true;
  EXPECT_TRUE(found_dead);
  // Another type can now take the name: nobody alive uses the old one.
  auto other = stamp_spec();
  other.type_name = "horus_test::Other";
  other.type_hash = horus::type_hash<horus_test::Other>;
  other.payload_size = sizeof(horus_test::Other);
  auto seg = ShmSegment::open(test_ns(), topic, other);
  ASSERT_TRUE(seg) << seg.error().message;
  EXPECT_EQ(seg->live_participants(), 1u);
  EXPECT_EQ(seg->ring().publisher_count(), 0u);
}

TEST_F(ShmSegmentTest, AKilledSubscriberNoLongerHoldsThePublisherBack) {
  const auto topic = topic_name("deadsub");
  auto seg = ShmSegment::open(test_ns(), topic, stamp_spec(4));
  ASSERT_TRUE(seg);
  Pipe ready;
  const pid_t child = spawn([&] {
    auto s = ShmSegment::open(test_ns(), topic, stamp_spec(4));
    if (!s) return 10;
    RingReader<Stamp> reader(s->ring(), token(1));
    if (!reader.subscribe()) return 11;
    ready.signal();
    for (;;) ::pause();
  });
  ASSERT_TRUE(ready.wait());
  RingWriter<Stamp> writer(seg->ring(), token(2));
  ASSERT_TRUE(writer.ensure_lane());
  for (int i = 0; i < 4; ++i) {
    ASSERT_TRUE(writer.has_space(0));
    writer.write(Stamp::make(1, static_cast<std::uint64_t>(i)));
  }
  EXPECT_FALSE(writer.has_space(0));  // the idle subscriber has 4 unread messages
  ::kill(child, SIGKILL);
  EXPECT_EQ(wait_for(child), 128 + SIGKILL);
  EXPECT_EQ(seg->reap_dead(), 1u);
  EXPECT_EQ(seg->ring().subscriber_count(), 0u);
  EXPECT_TRUE(writer.has_space(0));
}

TEST_F(ShmSegmentTest, AnUnfinishedHeaderLeftByACrashedCreatorIsFormattedAgain) {
  const auto topic = topic_name("unfinished");
  const std::string name = horus::shm::segment_name(test_ns(), topic);
  const int fd = ::shm_open(name.c_str(), O_RDWR | O_CREAT | O_EXCL, 0600);
  ASSERT_GE(fd, 0);
  ASSERT_EQ(::ftruncate(fd, 8192), 0);
  const std::uint64_t magic = horus::shm::kSegmentMagic;  // magic written, never marked ready
  ASSERT_EQ(::pwrite(fd, &magic, sizeof(magic), 0), static_cast<ssize_t>(sizeof(magic)));
  ::close(fd);
  auto seg = ShmSegment::open(test_ns(), topic, stamp_spec());
  ASSERT_TRUE(seg) << seg.error().message;
  EXPECT_EQ(seg->header().ready.load(), 1u);
  EXPECT_EQ(std::string(seg->header().type_name), "horus_test::Stamp");
}

TEST_F(ShmSegmentTest, AHeaderWhoseRingDoesNotMatchIsAnErrorWhileUsedAndReclaimedOnceAbandoned) {
  const auto topic = topic_name("corrupt");
  const std::string name = horus::shm::segment_name(test_ns(), topic);
  {
    auto a = ShmSegment::open(test_ns(), topic, stamp_spec());
    ASSERT_TRUE(a);
    const int fd = ::shm_open(name.c_str(), O_RDWR, 0);
    ASSERT_GE(fd, 0);
    const std::uint64_t bad_offset = 1u << 30;  // past the end of the file
    ASSERT_EQ(::pwrite(fd, &bad_offset, sizeof(bad_offset), offsetof(horus::shm::SegmentHeader, ring_offset)),
              static_cast<ssize_t>(sizeof(bad_offset)));
    ::close(fd);
    auto b = ShmSegment::open(test_ns(), topic, stamp_spec());
    ASSERT_FALSE(b);
    EXPECT_EQ(b.error().kind, SegmentError::Kind::Io);
    EXPECT_NE(b.error().message.find("corrupt header"), std::string::npos) << b.error().message;
    EXPECT_EQ(a->live_participants(), 1u);  // the failed open left the table alone
  }
  // Abandoned now (a detached; had it crashed, the same): the next open formats it afresh.
  const int fd = ::shm_open(name.c_str(), O_RDWR | O_CREAT, 0600);
  ASSERT_GE(fd, 0);
  ASSERT_EQ(::ftruncate(fd, 2 * 4096 + 65536), 0);
  horus::shm::SegmentHeader h{};
  h.magic = horus::shm::kSegmentMagic;
  h.layout_version = horus::shm::kSegmentVersion;
  h.ready.store(1);
  h.ring_offset = 1u << 30;
  ASSERT_EQ(::pwrite(fd, &h, sizeof(h), 0), static_cast<ssize_t>(sizeof(h)));
  ::close(fd);
  auto c = ShmSegment::open(test_ns(), topic, stamp_spec());
  ASSERT_TRUE(c) << c.error().message;
  EXPECT_EQ(c->live_participants(), 1u);
}

TEST_F(ShmSegmentTest, CleanRemovesOnlySegmentsWhoseProcessesAreAllGone) {
  const auto live_topic = topic_name("clean_live");
  const auto dead_topic = topic_name("clean_dead");
  auto live = ShmSegment::open(test_ns(), live_topic, stamp_spec());
  ASSERT_TRUE(live);
  const pid_t child = spawn([&] {
    auto s = ShmSegment::open(test_ns(), dead_topic, stamp_spec());
    if (!s) return 10;
    ::raise(SIGKILL);
    return 0;
  });
  EXPECT_EQ(wait_for(child), 128 + SIGKILL);
  ASSERT_TRUE(shm_file_exists(dead_topic));
  const auto removed = horus::shm::clean_stale_segments(test_ns());
  ASSERT_EQ(removed.size(), 1u);
  EXPECT_EQ(removed[0], "horus." + test_ns() + "." + dead_topic);
  EXPECT_FALSE(shm_file_exists(dead_topic));
  EXPECT_TRUE(shm_file_exists(live_topic));
}

TEST_F(ShmSegmentTest, TheNamespaceComesFromTheEnvironmentAndIsChecked) {
  ::unsetenv("HORUS_NAMESPACE");
  auto def = horus::shm::shm_namespace();
  ASSERT_TRUE(def);
  EXPECT_EQ(*def, "u" + std::to_string(::getuid()));
  ::setenv("HORUS_NAMESPACE", "fleet_a", 1);
  EXPECT_EQ(horus::shm::shm_namespace().value_or(""), "fleet_a");
  ::setenv("HORUS_NAMESPACE", "bad/name", 1);
  auto bad = horus::shm::shm_namespace();
  ASSERT_FALSE(bad);
  EXPECT_NE(bad.error().message.find("contains '/'"), std::string::npos) << bad.error().message;
  ::unsetenv("HORUS_NAMESPACE");
  EXPECT_NE(horus::shm::segment_name("fleet_a", "robot.pose"), horus::shm::segment_name("fleet_b", "robot.pose"));
}

TEST_F(ShmSegmentTest, ProcessLivenessSeesThroughPidReuse) {
  const auto start = horus::shm::process_start_time(::getpid());
  EXPECT_NE(start, 0u);
  EXPECT_TRUE(horus::shm::process_alive(::getpid(), start));
  EXPECT_FALSE(horus::shm::process_alive(::getpid(), start + 1));  // same pid, another start: reused
  const pid_t child = spawn([] { return 0; });
  // Exited but not yet reaped (a zombie): dead already.
  const horus_test::Deadline deadline(std::chrono::seconds(10));
  while (horus::shm::process_alive(child, 0) && !deadline.expired()) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  EXPECT_FALSE(horus::shm::process_alive(child, 0));
  EXPECT_EQ(::kill(child, 0), 0);  // the pid still exists: it is the zombie
  EXPECT_EQ(wait_for(child), 0);
  EXPECT_FALSE(horus::shm::process_alive(child, 0));
}

}  // namespace

namespace {

TEST_F(ShmSegmentTest, OneProcessHoldsTheBridgeAndAnotherTakesItOverWhenItIsKilled) {
  using Claim = ShmSegment::BridgeClaim;
  const auto topic = topic_name("bridge");
  auto seg = ShmSegment::open(test_ns(), topic, stamp_spec());
  ASSERT_TRUE(seg) << seg.error().message;
  EXPECT_EQ(seg->bridge_holder(), 0);
  Pipe ready;
  const pid_t child = spawn([&] {
    auto s = ShmSegment::open(test_ns(), topic, stamp_spec());
    if (!s) return 10;
    if (s->claim_bridge() != Claim::Claimed) return 11;
    ready.signal();
    for (;;) ::pause();
  });
  ASSERT_TRUE(ready.wait());
  EXPECT_EQ(seg->bridge_holder(), child);
  EXPECT_EQ(seg->claim_bridge(), Claim::Held);
  ::kill(child, SIGKILL);
  EXPECT_EQ(wait_for(child), 128 + SIGKILL);
  EXPECT_EQ(seg->bridge_holder(), 0);  // a dead holder holds nothing
  EXPECT_EQ(seg->claim_bridge(), Claim::TookOver);
  EXPECT_EQ(seg->claim_bridge(), Claim::Ours);
  EXPECT_EQ(seg->bridge_holder(), ::getpid());
  EXPECT_EQ(seg->header().bridge.claims.load(), 2u);

  // A live holder keeps it; one that detaches gives it up (a claim, not a takeover).
  const pid_t other = spawn([&] {
    auto s = ShmSegment::open(test_ns(), topic, stamp_spec());
    return !s ? 10 : s->claim_bridge() == Claim::Held ? 0 : 11;
  });
  EXPECT_EQ(wait_for(other), 0);
  seg->release_bridge();
  EXPECT_EQ(seg->bridge_holder(), 0);
  const pid_t closer = spawn([&] {
    auto s = ShmSegment::open(test_ns(), topic, stamp_spec());
    if (!s || s->claim_bridge() != Claim::Claimed) return 10;
    *s = ShmSegment();  // detaches: releases the bridge
    return 0;
  });
  EXPECT_EQ(wait_for(closer), 0);
  EXPECT_EQ(seg->claim_bridge(), Claim::Claimed);
  EXPECT_EQ(seg->header().bridge.claims.load(), 4u);
}

}  // namespace
