// horus_fleet_member: one process of a fleet test on a namespace host. The backend comes from
// HORUS_BACKEND (or the scope argument), the settings from HORUS_DOMAIN_ID / HORUS_LCM_URL.
//
//   horus_fleet_member <topic> <scope> <id> <count> <start_unix_ms> <publishers> <seconds> [best-effort]
//                      [await-reader | await-readers=<n>] [await-file=<path>] [ready=<path>] [deadline=<ms>]
//                      [period=<ms>]
//
// (reliable unless best-effort is given; await-reader: a publisher starts at <start_unix_ms> or
// once a remote reader matched, whichever comes later: DDS delivers nothing written before the
// match, and under load on a lossy link discovery may take longer than a test's head start;
// await-readers=<n>: the same, once <n> remote readers matched (one per host that reads: under
// DDS-Security each host authenticates in its own time, so the first one says nothing of the others);
// await-file=<path>: a publisher also waits until <path> exists; ready=<path>: a receiver creates
// <path> once its host's bridge matched a remote writer (pub_count() >= 1). The pair is a
// handshake for best-effort topics: a DDS reader drops what comes from a writer it has not
// matched yet, and on a lossy link it may match seconds after the writer matched it;
// deadline=<ms>: the subscribing handle watches that deadline and a receiver's last lines are
// "deadline missed <n> while receiving" and, 5 periods later, "deadline missed <n> after";
// period=<ms>: the publisher's messages go that far apart, 2 ms unless given)
// Opens <topic> (scope: fleet, host or process) with a subscribing handle and, unless id is 0,
// a publishing one. At <start_unix_ms> it publishes <count> Pose2D messages (x = id, y = sequence number
// 0..count-1) 2 ms apart (period=) with send_blocking, unless id is 0 (a listener). It receives until it
// has <count> messages from each of <publishers> publishers, or each one's last arrived and 1 s
// passed without a message, or <seconds> passed, then prints
//   received <n> from <k> publishers; duplicates <d>; out of order <o>; missing <m>; dropped <x>
// and exits 0 when every message of every publisher arrived exactly once and in order, 1 when
// not, 2 on a usage error, 3 when the topic does not open. A listener with <publishers> = 0
// listens 3 s after <start_unix_ms> and exits 0 when it received nothing; with -1 it stays
// until <seconds> passed (a process that only keeps the topic open: a bridge candidate). Its
// last line is "main returns at <unix_ms>".
#include <poll.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <string>
#include <thread>

#include "horus/msg/all.hpp"
#include "horus/topic.hpp"

namespace {

using Clock = std::chrono::steady_clock;
using namespace std::chrono_literals;

std::int64_t unix_ms() {
  return std::chrono::duration_cast<std::chrono::milliseconds>(std::chrono::system_clock::now().time_since_epoch())
      .count();
}

struct Tally {
  std::map<int, std::int64_t> next;   // per publisher id: the sequence number expected next
  std::map<int, std::int64_t> first;  // per publisher id: the first sequence number received
  std::uint64_t received = 0;
  std::uint64_t duplicates = 0;
  std::uint64_t out_of_order = 0;
  void add(const horus::msg::Pose2D& m) {
    ++received;
    const int id = static_cast<int>(m.x);
    const auto seq = static_cast<std::int64_t>(m.y);
    auto [it, fresh] = next.try_emplace(id, 0);
    if (fresh) first.emplace(id, seq);
    if (seq < it->second) {
      ++duplicates;  // seen (or passed) already
    } else {
      if (seq > it->second) ++out_of_order;  // a gap: something before it did not arrive (yet)
      it->second = seq + 1;
    }
  }
};

}  // namespace

int main(int argc, char** argv) {
  bool best_effort = false, usage = argc < 8;
  long await_readers = 0;  // remote readers a publisher waits for (await-reader: 1)
  long deadline_ms = 0, period_ms = 2;
  std::string await_file, ready_file;
  for (int i = 8; i < argc; ++i) {
    const std::string flag = argv[i];
    if (flag == "best-effort") best_effort = true;
    else if (flag == "await-reader") await_readers = 1;
    else if (flag.starts_with("await-readers=")) await_readers = std::atol(flag.c_str() + 14);
    else if (flag.starts_with("await-file=")) await_file = flag.substr(11);
    else if (flag.starts_with("ready=")) ready_file = flag.substr(6);
    else if (flag.starts_with("deadline=")) deadline_ms = std::atol(flag.c_str() + 9);
    else if (flag.starts_with("period=")) period_ms = std::atol(flag.c_str() + 7);
    else usage = true;
  }
  if (deadline_ms < 0 || period_ms < 1 || period_ms > 1000 || await_readers < 0 || await_readers > 64) usage = true;
  if (usage) {
    std::fprintf(stderr,
                 "usage: %s <topic> <fleet|host|process> <id> <count> <start_unix_ms> <publishers> <seconds> "
                 "[best-effort] [await-reader | await-readers=<n>] [await-file=<path>] [ready=<path>] [deadline=<ms>] "
                 "[period=<ms>]\n",
                 argv[0]);
    return 2;
  }
  const std::string topic = argv[1];
  const std::string scope = argv[2];
  const int id = std::atoi(argv[3]);
  const int count = std::atoi(argv[4]);
  const std::int64_t start = std::atoll(argv[5]);
  const int publishers = std::atoi(argv[6]);
  const auto deadline = Clock::now() + std::chrono::seconds(std::atoi(argv[7]));

  horus::TopicOptions options;
  options.reliability = best_effort ? horus::net::Reliability::BestEffort : horus::net::Reliability::Reliable;
  if (scope == "host") options.backend = horus::Backend::SharedMemory;
  else if (scope == "process") options.backend = horus::Backend::InProcess;
  else if (scope != "fleet") return 2;
  if (deadline_ms > 0) options.deadline = std::chrono::milliseconds(deadline_ms);
  auto sub = horus::Topic<horus::msg::Pose2D>::open(topic, options);
  if (!sub) {
    std::fprintf(stderr, "horus_fleet_member: %s\n", sub.error().message().c_str());
    return 3;
  }
  std::printf("open: pid %d, scope %s, backend %s\n", static_cast<int>(::getpid()),
              std::string(horus::to_string(sub->scope())).c_str(), std::string(horus::to_string(sub->backend())).c_str());
  std::fflush(stdout);

  Tally tally;
  std::uint64_t missed_before = 0;  // deadline periods missed before the first message
  auto add = [&](const horus::msg::Pose2D& m) {
    tally.add(m);
    if (tally.received == 1) missed_before = sub->deadline_missed_count();
  };
  auto drain = [&] {
    while (auto m = sub->recv()) add(*m);
  };
  // A receiver says it matched a remote writer (once) by creating ready_file.
  auto announce_ready = [&] {
    if (ready_file.empty() || sub->pub_count() < 1) return;
    if (std::FILE* f = std::fopen(ready_file.c_str(), "w")) std::fclose(f);
    std::printf("matched a writer %lld ms after the start\n", static_cast<long long>(unix_ms() - start));
    std::fflush(stdout);
    ready_file.clear();
  };
  auto awaited = [&] {
    if (id == 0) return true;
    // This handle plus the remote readers.
    if (await_readers > 0 && sub->sub_count() < static_cast<std::size_t>(1 + await_readers)) return false;
    return await_file.empty() || ::access(await_file.c_str(), F_OK) == 0;
  };
  while ((unix_ms() < start || !awaited()) && Clock::now() < deadline) {
    drain();
    announce_ready();
    std::this_thread::sleep_for(1ms);
  }
  if ((await_readers > 0 || !await_file.empty()) && id != 0) {
    std::printf("publishing %lld ms after the start\n", static_cast<long long>(unix_ms() - start));
    std::fflush(stdout);
  }
  if (id != 0) {
    // A handle that subscribes until its first send (a listener would never read it).
    auto pub = horus::Topic<horus::msg::Pose2D>::open(topic, options);
    if (!pub) {
      std::fprintf(stderr, "horus_fleet_member: %s\n", pub.error().message().c_str());
      return 3;
    }
    for (int seq = 0; seq < count && Clock::now() < deadline; ++seq) {
      const horus::msg::Pose2D m{static_cast<double>(id), static_cast<double>(seq), 0.0,
                                 static_cast<std::uint64_t>(seq)};
      if (auto ok = pub->send_blocking(m, 2s); !ok) {
        std::fprintf(stderr, "horus_fleet_member: send %d: %s\n", seq, ok.error().message().c_str());
        --seq;
      }
      drain();
      std::this_thread::sleep_for(std::chrono::milliseconds(period_ms));
    }
  }
  // The moment main returns (the handles close after it): a test measures how long the process
  // takes to end from here, whatever the network does.
  auto returning = [](int code) {
    std::printf("main returns at %lld\n", static_cast<long long>(unix_ms()));
    std::fflush(stdout);
    return code;
  };
  const bool stay = publishers < 0;
  if (stay) {  // a bridge candidate: keeps the topic open (and reads it) until the deadline
    while (Clock::now() < deadline) (void)sub->recv_for(50ms);
    return returning(0);
  }
  const std::uint64_t want = static_cast<std::uint64_t>(publishers) * static_cast<std::uint64_t>(count);
  const auto quiet_until = Clock::now() + (publishers == 0 ? 3s : 0s);  // a listener listens a while
  // Every publisher's last message came and 1 s passed without another: what is missing was lost
  // (a gap stays a gap; waiting until <seconds> would only make a test with losses slower).
  auto all_ended = [&] {
    if (publishers <= 0 || tally.next.size() < static_cast<std::size_t>(publishers)) return false;
    for (const auto& [pid, next] : tally.next)
      if (next < count) return false;
    return true;
  };
  auto last_message = Clock::now();
  while (Clock::now() < deadline && (tally.received < want || Clock::now() < quiet_until) &&
         !(all_ended() && Clock::now() - last_message > 1s)) {
    if (auto m = sub->recv_for(50ms)) {
      add(*m);
      last_message = Clock::now();
    }
    announce_ready();
  }
  drain();
  std::uint64_t missing = 0;
  for (const auto& [pid, next] : tally.next) missing += static_cast<std::uint64_t>(count - std::min<std::int64_t>(next, count));
  missing += static_cast<std::uint64_t>(publishers - static_cast<int>(std::min<std::size_t>(tally.next.size(), publishers))) *
             static_cast<std::uint64_t>(count);
  std::int64_t last = -1;  // the highest sequence number received (of any publisher)
  for (const auto& [pid, next] : tally.next) last = std::max(last, next - 1);
  std::int64_t first = -1;  // the lowest first sequence number received
  for (const auto& [pid, seq] : tally.first) first = first < 0 ? seq : std::min(first, seq);
  std::printf("received %llu from %zu publishers; duplicates %llu; out of order %llu; missing %llu; dropped %llu; "
              "last %lld; first %lld\n",
              static_cast<unsigned long long>(tally.received), tally.next.size(),
              static_cast<unsigned long long>(tally.duplicates), static_cast<unsigned long long>(tally.out_of_order),
              static_cast<unsigned long long>(missing), static_cast<unsigned long long>(sub->dropped_count()),
              static_cast<long long>(last), static_cast<long long>(first));
  if (deadline_ms > 0) {
    std::printf("deadline missed %llu while receiving\n",
                static_cast<unsigned long long>(sub->deadline_missed_count() - missed_before));
    std::this_thread::sleep_for(std::chrono::milliseconds(5 * deadline_ms));
    std::printf("deadline missed %llu after\n",
                static_cast<unsigned long long>(sub->deadline_missed_count() - missed_before));
  }
  std::fflush(stdout);
  const bool exact = tally.received == want && tally.next.size() == static_cast<std::size_t>(publishers) &&
                     tally.duplicates == 0 && tally.out_of_order == 0 && missing == 0;
  return returning(exact ? 0 : 1);
}
