// The ring's writer/reader protocol, driven directly (RingWriter / RingReader over a formatted
// HeapRegion), without horus::Topic: ordering, losses, read_latest, a writer that died
// mid-write, serialized slots, and a concurrent stress that checks every message for tearing.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <latch>
#include <span>
#include <thread>
#include <utility>
#include <vector>

#include "horus/shm/heap_region.hpp"
#include "horus/shm/ring.hpp"

using namespace horus::shm;

namespace {

// A formatted ring in its own memory (the region owns the bytes, the Ring views them).
struct TestRing {
  HeapRegion region;
  Ring ring;
};

TestRing make_ring(std::uint32_t capacity, std::uint32_t payload_size) {
  const RingConfig cfg{capacity, payload_size, 0x5EED};
  TestRing t{HeapRegion(Ring::required_size(cfg)), Ring{}};
  t.ring = Ring::format(t.region.data(), cfg);
  return t;
}

// n readers (tokens 100, 101, ...) that have subscribed, and n writers (tokens 1, 2, ...) that
// hold a lane; a subscription or lane refused is a test failure.
template <class T>
std::vector<RingReader<T>> subscribed_readers(const Ring& ring, int n) {
  std::vector<RingReader<T>> readers;
  readers.reserve(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) {
    readers.emplace_back(ring, static_cast<std::uint64_t>(100 + i));
    EXPECT_TRUE(readers.back().subscribe()) << "reader " << i;
  }
  return readers;
}

template <class T>
std::vector<RingWriter<T>> writers_with_lanes(const Ring& ring, int n) {
  std::vector<RingWriter<T>> writers;
  writers.reserve(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) {
    writers.emplace_back(ring, static_cast<std::uint64_t>(1 + i));
    EXPECT_TRUE(writers.back().ensure_lane()) << "writer " << i;
  }
  return writers;
}

struct Msg {
  std::uint64_t seq;
  std::uint64_t writer;
};

// A message whose words must all be equal: a torn copy mixes two messages and shows.
template <std::size_t Words>
struct Uniform {
  std::array<std::uint64_t, Words> w;
  static Uniform of(std::uint64_t v) {
    Uniform u;
    u.w.fill(v);
    return u;
  }
  bool intact() const { return std::all_of(w.begin(), w.end(), [&](std::uint64_t x) { return x == w[0]; }); }
};
using SmallUniform = Uniform<8>;  // 64 B: copied word by word
using LargeUniform = Uniform<40>;  // 320 B: above kBulkCopyBytes, copied with copy_to_slot / copy_from_slot
static_assert(sizeof(LargeUniform) > kBulkCopyBytes);

// Iterations a thread waits for another one before the test gives up (a failure, not a hang).
constexpr long kSpinBudget = 20'000'000;

// Waits until the writer may write without overwriting an unread message; false if it never may.
template <class T>
bool wait_for_space(RingWriter<T>& w) {
  for (long i = 0; i < kSpinBudget; ++i) {
    if (w.has_space(0)) return true;
    std::this_thread::yield();
  }
  return false;
}

std::byte* slot_at(const Ring& ring, std::uint32_t lane, std::uint64_t seq) {
  return ring.lane_slots(lane) + (seq & (ring.capacity() - 1)) * ring.stride();
}

// Stores a slot's sequence word by hand, as a writer does before and after the payload.
void store_seq(std::byte* slot, std::uint64_t value) {
  std::atomic_ref<std::uint64_t>(*reinterpret_cast<std::uint64_t*>(slot)).store(value, std::memory_order_release);
}

// What one reader thread saw of several writers' messages (Msg.writer is the writer's index).
struct Received {
  std::vector<std::uint64_t> next;  // next seq expected from each writer
  std::uint64_t total = 0;
  std::uint64_t out_of_order = 0;
};

// Reads until every writer is done and nothing is left.
Received drain_in_order(RingReader<Msg>& r, const std::atomic<int>& writers_done, int writers) {
  Received got;
  got.next.assign(static_cast<std::size_t>(writers), 0);
  Msg m{};
  bool finished = false;
  for (;;) {
    if (r.read(m)) {
      ++got.total;
      if (m.writer >= got.next.size() || m.seq != got.next[m.writer]) ++got.out_of_order;
      else ++got.next[m.writer];
      continue;
    }
    if (finished) break;  // read() found nothing after every writer had finished
    finished = writers_done.load(std::memory_order_acquire) == writers;
    if (!finished) std::this_thread::yield();
  }
  return got;
}

}  // namespace

TEST(RingProtocol, ReaderSeesEveryMessageOfOneWriterInOrder) {
  auto t = make_ring(16, sizeof(Msg));
  RingReader<Msg> reader(t.ring, 1);
  ASSERT_TRUE(reader.subscribe());
  constexpr std::uint64_t kCount = 20'000;
  RingWriter<Msg> w(t.ring, 2);
  ASSERT_TRUE(w.ensure_lane());
  std::atomic<int> done{0};
  bool writer_waited_too_long = false;

  std::thread writer([&] {
    for (std::uint64_t i = 0; i < kCount; ++i) {
      if (!wait_for_space(w)) {
        writer_waited_too_long = true;
        break;
      }
      w.write({i, 0});
    }
    done.fetch_add(1, std::memory_order_release);
  });
  Received got;
  std::thread consumer([&] { got = drain_in_order(reader, done, 1); });
  writer.join();
  consumer.join();

  EXPECT_FALSE(writer_waited_too_long);
  EXPECT_EQ(got.out_of_order, 0u);
  EXPECT_EQ(got.total, kCount);
  EXPECT_EQ(got.next[0], kCount);
  EXPECT_EQ(reader.lost(), 0u);
  EXPECT_EQ(reader.delivered(), kCount);
  EXPECT_EQ(t.ring.total_sent(), kCount);
}

TEST(RingProtocol, SeveralWritersAndReadersEachGetEveryMessageOnceInEachWritersOrder) {
  constexpr int kWriters = 3;
  constexpr int kReaders = 3;
  constexpr std::uint64_t kCount = 4'000;
  auto t = make_ring(32, sizeof(Msg));
  auto readers = subscribed_readers<Msg>(t.ring, kReaders);
  auto writers = writers_with_lanes<Msg>(t.ring, kWriters);
  if (::testing::Test::HasFailure()) return;
  std::vector<std::uint32_t> lanes;
  for (const auto& w : writers) lanes.push_back(w.lane());
  std::atomic<int> done{0};
  std::atomic<int> writers_stuck{0};
  std::vector<Received> got(kReaders);

  std::vector<std::thread> threads;
  for (int wi = 0; wi < kWriters; ++wi)
    threads.emplace_back([&, wi] {
      auto& w = writers[static_cast<std::size_t>(wi)];
      for (std::uint64_t i = 0; i < kCount; ++i) {
        if (!wait_for_space(w)) {
          writers_stuck.fetch_add(1);
          break;
        }
        w.write({i, static_cast<std::uint64_t>(wi)});
      }
      done.fetch_add(1, std::memory_order_release);
    });
  for (int ri = 0; ri < kReaders; ++ri)
    threads.emplace_back([&, ri] { got[static_cast<std::size_t>(ri)] = drain_in_order(readers[static_cast<std::size_t>(ri)], done, kWriters); });
  for (auto& th : threads) th.join();

  EXPECT_EQ(writers_stuck.load(), 0);
  std::sort(lanes.begin(), lanes.end());
  EXPECT_TRUE(std::adjacent_find(lanes.begin(), lanes.end()) == lanes.end()) << "two writers shared a lane";
  for (int ri = 0; ri < kReaders; ++ri) {
    const auto& g = got[static_cast<std::size_t>(ri)];
    EXPECT_EQ(g.out_of_order, 0u) << "reader " << ri;
    EXPECT_EQ(g.total, kWriters * kCount) << "reader " << ri;
    for (int wi = 0; wi < kWriters; ++wi) EXPECT_EQ(g.next[static_cast<std::size_t>(wi)], kCount) << "reader " << ri << " writer " << wi;
    EXPECT_EQ(readers[static_cast<std::size_t>(ri)].lost(), 0u) << "reader " << ri;
  }
  EXPECT_EQ(t.ring.header().dropped_total.load(), 0u);
}

TEST(RingProtocol, AFullLaneOverwritesTheOldestAndTheReaderCountsExactlyTheLostOnes) {
  auto t = make_ring(8, sizeof(Msg));
  RingReader<Msg> reader(t.ring, 1);
  ASSERT_TRUE(reader.subscribe());
  RingWriter<Msg> w(t.ring, 2);
  ASSERT_TRUE(w.ensure_lane());
  for (std::uint64_t i = 0; i < 20; ++i) w.write({i, 0});

  // 20 sent into 8 slots: 0..11 are gone. Known before the reader looks, not yet in the total.
  EXPECT_EQ(reader.lost(), 12u);
  EXPECT_EQ(t.ring.undetected_losses(), 12u);
  EXPECT_EQ(t.ring.header().dropped_total.load(), 0u);
  EXPECT_EQ(reader.pending(), 8u);

  Msg m{};
  ASSERT_TRUE(reader.read(m));
  EXPECT_EQ(m.seq, 12u) << "the reader continues at the oldest message still there";
  for (std::uint64_t want = 13; want < 20; ++want) {
    ASSERT_TRUE(reader.read(m));
    EXPECT_EQ(m.seq, want);
  }
  EXPECT_FALSE(reader.read(m));
  EXPECT_EQ(reader.lost(), 12u) << "noticed losses are counted once";
  EXPECT_EQ(t.ring.header().dropped_total.load(), 12u);
  EXPECT_EQ(t.ring.undetected_losses(), 0u);
  EXPECT_EQ(reader.delivered(), 8u);

  // Keeping up afterwards loses nothing more.
  for (std::uint64_t i = 20; i < 23; ++i) w.write({i, 0});
  for (std::uint64_t want = 20; want < 23; ++want) {
    ASSERT_TRUE(reader.read(m));
    EXPECT_EQ(m.seq, want);
  }
  EXPECT_EQ(reader.lost(), 12u);
  EXPECT_EQ(reader.delivered(), 11u);
}

TEST(RingProtocol, ReadLatestReturnsTheNewestAndMarksEarlierOnesRead) {
  auto t = make_ring(16, sizeof(Msg));
  RingReader<Msg> reader(t.ring, 1);
  ASSERT_TRUE(reader.subscribe());
  RingWriter<Msg> a(t.ring, 2);
  RingWriter<Msg> b(t.ring, 3);
  ASSERT_TRUE(a.ensure_lane() && b.ensure_lane());
  for (std::uint64_t i = 0; i < 3; ++i) a.write({i, 0});
  for (std::uint64_t i = 0; i < 5; ++i) b.write({i, 1});

  Msg m{};
  ASSERT_TRUE(reader.read_latest(m));
  EXPECT_EQ(m.writer, 1u);
  EXPECT_EQ(m.seq, 4u);
  EXPECT_FALSE(reader.has_message()) << "every earlier message, of both lanes, counts as read";
  EXPECT_FALSE(reader.read(m));
  EXPECT_EQ(reader.pending(), 0u);
  EXPECT_EQ(reader.lost(), 0u) << "skipped messages that were still there are not losses";

  // Later messages are read as usual.
  a.write({3, 0});
  ASSERT_TRUE(reader.read(m));
  EXPECT_EQ(m.writer, 0u);
  EXPECT_EQ(m.seq, 3u);
  EXPECT_FALSE(reader.read(m));
}

TEST(RingProtocol, ReadLatestCountsTheOverwrittenMessagesItSkipsAsLost) {
  auto t = make_ring(4, sizeof(Msg));
  RingReader<Msg> reader(t.ring, 1);
  ASSERT_TRUE(reader.subscribe());
  RingWriter<Msg> w(t.ring, 2);
  ASSERT_TRUE(w.ensure_lane());
  for (std::uint64_t i = 0; i < 10; ++i) w.write({i, 0});

  Msg m{};
  ASSERT_TRUE(reader.read_latest(m));
  EXPECT_EQ(m.seq, 9u);
  EXPECT_EQ(reader.lost(), 6u);  // 0..5 were overwritten; 6..8 were still there (skipped)
  EXPECT_EQ(t.ring.header().dropped_total.load(), 6u);
  EXPECT_FALSE(reader.read(m));
}

TEST(RingProtocol, AWriterThatDiedMidWriteIsNeverReadAndTheLanesNextOwnerRewritesThatMessage) {
  auto t = make_ring(8, sizeof(Msg));
  RingReader<Msg> reader(t.ring, 1);
  ASSERT_TRUE(reader.subscribe());
  RingWriter<Msg> dead(t.ring, 2);
  ASSERT_TRUE(dead.ensure_lane());
  const std::uint32_t lane = dead.lane();
  for (std::uint64_t i = 0; i < 3; ++i) dead.write({i, 0});

  // The writer starts message 3 and dies: odd sequence, half a payload, head still 3.
  std::byte* slot = slot_at(t.ring, lane, 3);
  store_seq(slot, 2 * 3 + 1);
  const std::uint64_t half = 0xDEADBEEF;
  std::memcpy(slot + 8, &half, sizeof half);

  Msg m{};
  for (std::uint64_t want = 0; want < 3; ++want) {
    ASSERT_TRUE(reader.read(m));
    EXPECT_EQ(m.seq, want);
  }
  EXPECT_FALSE(reader.read(m)) << "a slot with an odd sequence is not a message";
  EXPECT_FALSE(reader.has_message());
  EXPECT_EQ(reader.lost(), 0u);

  // The reaper frees the lane in the dead owner's name; the next writer gets it and goes on.
  t.ring.release_lane(lane, 2);
  RingWriter<Msg> next(t.ring, 3);
  ASSERT_TRUE(next.ensure_lane());
  EXPECT_EQ(next.lane(), lane);
  EXPECT_EQ(next.head(), 3u);
  next.write({3, 7});
  ASSERT_TRUE(reader.read(m));
  EXPECT_EQ(m.seq, 3u);
  EXPECT_EQ(m.writer, 7u);
  EXPECT_EQ(reader.lost(), 0u);
  EXPECT_EQ(t.ring.publisher_count(), 1u);
}

TEST(RingProtocol, AWriterThatDiedMidWriteCostsTheMessageItWasOverwritingButIsNeverReadTorn) {
  auto t = make_ring(4, sizeof(Msg));
  RingReader<Msg> reader(t.ring, 1);
  ASSERT_TRUE(reader.subscribe());
  RingWriter<Msg> w(t.ring, 2);
  ASSERT_TRUE(w.ensure_lane());
  for (std::uint64_t i = 0; i < 4; ++i) w.write({i, 0});

  // Message 4 goes where message 0 was; the writer dies after the odd sequence and one word.
  std::byte* slot = slot_at(t.ring, w.lane(), 4);
  store_seq(slot, 2 * 4 + 1);
  const std::uint64_t half = 4;
  std::memcpy(slot + 8, &half, sizeof half);

  Msg m{};
  for (std::uint64_t want = 1; want < 4; ++want) {
    ASSERT_TRUE(reader.read(m));
    EXPECT_EQ(m.seq, want);
    EXPECT_EQ(m.writer, 0u);
  }
  EXPECT_FALSE(reader.read(m));
  EXPECT_EQ(reader.lost(), 1u);
  EXPECT_EQ(t.ring.header().dropped_total.load(), 1u);
}

TEST(RingProtocol, SerializedSlotsRoundTripEverySize) {
  constexpr std::uint32_t kMax = 100;
  auto t = make_ring(8, 8 + kMax);
  RingWriter<ByteMessage> w(t.ring, 2);
  ASSERT_TRUE(w.ensure_lane());
  EXPECT_EQ(w.max_bytes(), kMax);
  RingReader<ByteMessage> reader(t.ring, 1);
  ASSERT_TRUE(reader.subscribe());
  ByteMessage out;
  out.reserve(max_serialized_size(t.ring.header().payload_size));

  for (std::size_t size : {0u, 1u, 7u, 8u, 9u, 13u, 64u, 99u, 100u}) {
    std::vector<std::byte> msg(size);
    for (std::size_t i = 0; i < size; ++i) msg[i] = static_cast<std::byte>((size * 31 + i) & 0xFF);
    w.write_bytes(msg);
    ASSERT_TRUE(reader.read(out)) << size;
    ASSERT_EQ(out.size, size);
    EXPECT_TRUE(std::equal(msg.begin(), msg.end(), out.view().begin())) << size;
  }
  EXPECT_FALSE(reader.read(out));
  EXPECT_EQ(reader.corrupt(), 0u);
  EXPECT_EQ(reader.delivered(), 9u);
}

TEST(RingProtocol, ASerializedSlotWithACorruptLengthIsSkippedAndCounted) {
  constexpr std::uint32_t kMax = 100;
  auto t = make_ring(8, 8 + kMax);
  RingWriter<ByteMessage> w(t.ring, 2);
  ASSERT_TRUE(w.ensure_lane());
  RingReader<ByteMessage> reader(t.ring, 1);
  ASSERT_TRUE(reader.subscribe());
  ByteMessage out;
  out.reserve(kMax);

  const std::vector<std::byte> a(10, std::byte{0xA}), b(20, std::byte{0xB}), c(30, std::byte{0xC});
  w.write_bytes(a);
  w.write_bytes(b);
  w.write_bytes(c);
  // Damage message 1's committed length: [ seq ][ length ][ bytes ].
  const std::uint64_t bad = 1000;
  std::memcpy(slot_at(t.ring, w.lane(), 1) + 8, &bad, sizeof bad);

  ASSERT_TRUE(reader.read(out));
  EXPECT_EQ(out.size, 10u);
  ASSERT_TRUE(reader.read(out));
  EXPECT_EQ(out.size, 30u) << "the corrupt message is skipped";
  EXPECT_EQ(out.view()[0], std::byte{0xC});
  EXPECT_FALSE(reader.read(out));
  EXPECT_EQ(reader.corrupt(), 1u);
  EXPECT_EQ(reader.lost(), 0u);
  EXPECT_EQ(reader.delivered(), 2u);
}

namespace {

// Writers overwrite freely (no waiting) in a small ring while readers read: every message a
// reader returns must be intact, each writer's messages must come in order, and what a reader
// did not get it must have counted as lost.
template <class T>
void stress_without_tearing(std::uint64_t per_writer) {
  constexpr int kWriters = 2;
  constexpr int kReaders = 2;
  auto t = make_ring(4, sizeof(T));
  auto readers = subscribed_readers<T>(t.ring, kReaders);
  auto writers = writers_with_lanes<T>(t.ring, kWriters);
  if (::testing::Test::HasFailure()) return;
  std::atomic<int> done{0};
  std::latch start(kWriters + kReaders);
  struct Seen {
    std::uint64_t received = 0, torn = 0, out_of_order = 0;
  };
  std::vector<Seen> seen(kReaders);

  std::vector<std::thread> threads;
  for (int wi = 0; wi < kWriters; ++wi)
    threads.emplace_back([&, wi] {
      auto& w = writers[static_cast<std::size_t>(wi)];
      start.arrive_and_wait();
      // Each message's words all hold (seq << 8) | writer; seq starts at 1.
      for (std::uint64_t s = 1; s <= per_writer; ++s) w.write(T::of((s << 8) | static_cast<std::uint64_t>(wi)));
      done.fetch_add(1, std::memory_order_release);
    });
  for (int ri = 0; ri < kReaders; ++ri)
    threads.emplace_back([&, ri] {
      auto& r = readers[static_cast<std::size_t>(ri)];
      auto& s = seen[static_cast<std::size_t>(ri)];
      std::uint64_t last[kWriters] = {};
      T m{};
      start.arrive_and_wait();
      bool finished = false;
      for (;;) {
        if (r.read(m)) {
          ++s.received;
          if (!m.intact()) {
            ++s.torn;
            continue;
          }
          const std::uint64_t wi = m.w[0] & 0xFF, seq = m.w[0] >> 8;
          if (wi >= static_cast<std::uint64_t>(kWriters) || seq <= last[wi]) ++s.out_of_order;
          else last[wi] = seq;
          continue;
        }
        if (finished) break;
        finished = done.load(std::memory_order_acquire) == kWriters;
        if (!finished) cpu_relax();
      }
    });
  for (auto& th : threads) th.join();

  for (int ri = 0; ri < kReaders; ++ri) {
    const auto& s = seen[static_cast<std::size_t>(ri)];
    const auto& r = readers[static_cast<std::size_t>(ri)];
    EXPECT_EQ(s.torn, 0u) << "reader " << ri;
    EXPECT_EQ(s.out_of_order, 0u) << "reader " << ri;
    EXPECT_EQ(r.delivered(), s.received) << "reader " << ri;
    EXPECT_EQ(s.received + r.lost(), kWriters * per_writer) << "reader " << ri << ": every message read or lost";
    EXPECT_GE(s.received, kWriters * t.ring.capacity()) << "reader " << ri << ": each lane's last messages stay";
  }
}

}  // namespace

TEST(RingProtocol, ConcurrentWritersAndReadersNeverTearASmallMessageAndAccountForEveryOne) {
  stress_without_tearing<SmallUniform>(100'000);
}

TEST(RingProtocol, ConcurrentWritersAndReadersNeverTearALargeMessageAndAccountForEveryOne) {
  stress_without_tearing<LargeUniform>(100'000);
}

TEST(RingProtocol, ReadExceptPassesOverOneLaneAndDeliversTheOthersInOrder) {
  auto t = make_ring(8, sizeof(Msg));
  RingReader<Msg> bridge(t.ring, 100);
  ASSERT_TRUE(bridge.subscribe());
  auto writers = writers_with_lanes<Msg>(t.ring, 2);
  const std::uint32_t own = writers[0].lane();  // the bridge's import lane
  for (std::uint64_t i = 0; i < 5; ++i) {
    writers[0].write({i, 0});  // imported: never exported again
    writers[1].write({i, 1});  // a local publisher's
  }
  Msg m{};
  for (std::uint64_t i = 0; i < 5; ++i) {
    ASSERT_TRUE(bridge.read_except(m, own)) << i;
    EXPECT_EQ(m.writer, 1u);
    EXPECT_EQ(m.seq, i);
  }
  EXPECT_FALSE(bridge.read_except(m, own));
  EXPECT_FALSE(bridge.has_message());  // the passed-over lane is not left unread
  EXPECT_EQ(bridge.delivered(), 5u);
  EXPECT_EQ(bridge.lost(), 0u);
  // More than a lane's capacity on the own lane costs nothing and counts no loss.
  for (std::uint64_t i = 0; i < 20; ++i) writers[0].write({i, 0});
  writers[1].write({99, 1});
  ASSERT_TRUE(bridge.read_except(m, own));
  EXPECT_EQ(m.seq, 99u);
  EXPECT_EQ(bridge.lost(), 0u);
  // A plain reader of the same ring still gets both lanes.
  RingReader<Msg> other(t.ring, 101);
  ASSERT_TRUE(other.subscribe());
  writers[0].write({7, 0});
  writers[1].write({8, 1});
  int got = 0;
  while (other.read(m)) ++got;
  EXPECT_EQ(got, 2);
  // An out-of-range lane passes over nothing: both lanes' newest messages arrive.
  got = 0;
  while (bridge.read_except(m, ~0u)) ++got;
  EXPECT_EQ(got, 2);  // {7, 0} and {8, 1}
}
