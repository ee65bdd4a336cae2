// horus_fleet_load: one host of the fleet load test (test_fleet.cpp, label load; CI does not run it).
//
//   horus_fleet_load <host index> <hosts> <topics> <hz> <seconds> <start_unix_ms>
//
// Publishes <topics> reliable fleet topics (fleet.load.h<index>.t<k>, Pose2D, x = seq) at <hz>
// each from <start_unix_ms> for <seconds>, subscribes to the same topics of every other host,
// and keeps a horus::Fleet. Prints resident memory every 5 s ("rss_kb <t> <kB>") and at the
// end, per other host: "from h<j> received <n> gaps <g> duplicates <d> dropped_counted <c>",
// then "sent <n> per topic" (each host's own count: the test compares) and
// "hosts alive <n> lost_events <n>".
#include <fmt/format.h>

#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "horus/executor.hpp"
#include "horus/fleet.hpp"
#include "horus/msg/geometry.hpp"
#include "horus/topic.hpp"

namespace {

long rss_kb() {
  std::ifstream in("/proc/self/status");
  std::string key;
  while (in >> key) {
    if (key == "VmRSS:") {
      long v = 0;
      in >> v;
      return v;
    }
    in.ignore(1 << 12, '\n');
  }
  return -1;
}

std::int64_t unix_ms() {
  return std::chrono::duration_cast<std::chrono::milliseconds>(std::chrono::system_clock::now().time_since_epoch())
      .count();
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 7) {
    std::fprintf(stderr, "usage: %s <index> <hosts> <topics> <hz> <seconds> <start_unix_ms>\n", argv[0]);
    return 2;
  }
  const int index = std::atoi(argv[1]), hosts = std::atoi(argv[2]), topics = std::atoi(argv[3]);
  const double hz = std::atof(argv[4]);
  const int seconds = std::atoi(argv[5]);
  const std::int64_t start = std::atoll(argv[6]);
  horus::TopicOptions reliable;
  reliable.reliability = horus::net::Reliability::Reliable;
  reliable.capacity = 256;
  std::vector<horus::Topic<horus::msg::Pose2D>> out;
  for (int k = 0; k < topics; ++k)
    out.push_back(horus::Topic<horus::msg::Pose2D>::open(fmt::format("fleet.load.h{}.t{}", index, k), reliable).value());
  for (auto& t : out) t.publish_only();
  struct Inbox {
    std::int64_t next = 0;
    std::uint64_t received = 0, gaps = 0, duplicates = 0;
  };
  std::vector<std::vector<Inbox>> inbox(static_cast<std::size_t>(hosts), std::vector<Inbox>(static_cast<std::size_t>(topics)));
  std::atomic<std::uint64_t> arrived{0};  // read by the main thread while the executor counts
  horus::Executor ex;
  std::vector<std::vector<horus::Executor::Id>> ids(static_cast<std::size_t>(hosts));
  for (int j = 0; j < hosts; ++j) {
    if (j == index) continue;
    for (int k = 0; k < topics; ++k) {
      auto* box = &inbox[static_cast<std::size_t>(j)][static_cast<std::size_t>(k)];
      ids[static_cast<std::size_t>(j)].push_back(ex.subscribe<horus::msg::Pose2D>(fmt::format("fleet.load.h{}.t{}", j, k), reliable, [box, &arrived](const horus::msg::Pose2D& m) {
        arrived.fetch_add(1, std::memory_order_relaxed);
        const auto seq = static_cast<std::int64_t>(m.x);
        ++box->received;
        if (seq < box->next) ++box->duplicates;
        else {
          if (seq > box->next) box->gaps += static_cast<std::uint64_t>(seq - box->next);
          box->next = seq + 1;
        }
      }));
    }
  }
  int lost_events = 0;
  auto fleet = horus::Fleet::open(ex);
  if (fleet)
    (*fleet)->on_change([&](const horus::FleetEvent& e) { lost_events += e.kind == horus::FleetEvent::Kind::Lost; });
  std::thread spinner([&] { ex.spin(); });
  while (unix_ms() < start) std::this_thread::sleep_for(std::chrono::milliseconds(5));
  const auto t0 = std::chrono::steady_clock::now();
  const auto end = t0 + std::chrono::seconds(seconds);
  const auto period = std::chrono::duration_cast<std::chrono::steady_clock::duration>(std::chrono::duration<double>(1.0 / hz));
  auto next = t0;
  auto next_rss = t0;
  std::int64_t seq = 0;
  std::uint64_t refused = 0;
  while (std::chrono::steady_clock::now() < end) {
    for (auto& t : out)
      if (!t.send_blocking(horus::msg::Pose2D{static_cast<double>(seq), 0, 0, 0}, std::chrono::seconds(10))) ++refused;
    ++seq;
    next += period;
    if (std::chrono::steady_clock::now() >= next_rss) {
      std::printf("rss_kb %.0f %ld\n", std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), rss_kb());
      std::fflush(stdout);
      next_rss += std::chrono::seconds(5);
    }
    std::this_thread::sleep_until(next);
  }
  // Every host stays 20 s after the sending ends (all end together): what is on the way, and
  // what back-pressure kept in the hosts' rings and DDS histories, arrives meanwhile.
  while (std::chrono::steady_clock::now() < end + std::chrono::seconds(20))
    std::this_thread::sleep_for(std::chrono::milliseconds(200));
  (void)arrived.load();
  ex.stop();
  spinner.join();
  for (int j = 0; j < hosts; ++j) {
    if (j == index) continue;
    std::uint64_t received = 0, gaps = 0, dups = 0, counted = 0;
    for (const auto id : ids[static_cast<std::size_t>(j)])
      if (auto m = ex.metrics(id)) counted += m->messages_dropped();
    for (const auto& b : inbox[static_cast<std::size_t>(j)]) {
      received += b.received;
      gaps += b.gaps;
      dups += b.duplicates;
    }
    std::printf("from h%d received %llu gaps %llu duplicates %llu dropped_counted %llu\n", j,
                static_cast<unsigned long long>(received), static_cast<unsigned long long>(gaps),
                static_cast<unsigned long long>(dups), static_cast<unsigned long long>(counted));
  }
  std::uint64_t out_dropped = 0;
  for (const auto& t : out) out_dropped += t.dropped_count();
  std::printf("own topics: dropped_count %llu\n", static_cast<unsigned long long>(out_dropped));
  std::size_t alive = 0;
  if (fleet)
    for (const auto& h : (*fleet)->hosts()) alive += h.state != horus::HostState::Lost ? 1 : 0;
  std::printf("sent %lld per topic, %llu refused\nhosts alive %zu lost_events %d\nrss_kb end %ld\n",
              static_cast<long long>(seq), static_cast<unsigned long long>(refused), alive, lost_events, rss_kb());
  return 0;
}
