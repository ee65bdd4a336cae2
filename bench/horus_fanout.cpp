// horus-fanout: one publisher to many subscriber processes, and many topics in one process.
//
//   * fan-out latency: one publisher process sends a 16-byte message (a sequence number and the
//     TSC at send) every --gap-us to N subscriber processes (N = 1, 2, 4, 8, 16 by default),
//     each blocked in recv_for; every subscriber records (TSC at receipt - TSC at send) in
//     shared memory. Printed per N: p50/p99/p99.9 over every (message, subscriber) pair, and
//     the p50/p99 of "all delivered" (the last subscriber's receipt of each message).
//   * fan-out throughput: the publisher sends as fast as send_blocking lets it (lossless: it
//     waits for the slowest subscriber), the subscribers still in recv_for: messages per second
//     that reached every subscriber.
//   * many topics: 1, 100 and 1000 topics open in both processes of a CmdVel ping-pong (spins
//     with pause, as horus-latency-shm), latency measured on one of them; and the memory of a
//     topic by message size: its segment's size in /dev/shm (virtual and allocated) and the RSS
//     a process gains per topic opened and used.
// The TSC is the clock across processes: the tool says when /proc/cpuinfo lacks constant_tsc or
// nonstop_tsc (then cross-process stamps are not comparable). The machine is shared: --rounds
// repeats every measurement and the spread is printed.
#include <CLI/CLI.hpp>
#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <linux/futex.h>
#include <sys/syscall.h>
#include <sys/mman.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <bit>
#include <climits>
#include <atomic>
#include <chrono>
#include <cstdint>
#include <fstream>
#include <optional>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "bench_common.hpp"
#include "fanout_probes.hpp"
#include "dds/bench_types.hpp"  // the 1 KiB message
#include "horus/detail/cache_floor.hpp"
#ifdef HORUS_BENCH_ICEORYX
#include "iox_baseline.hpp"
#endif
#include "horus/horus.hpp"

namespace bench_msg {
/// The fan-out message: 16 bytes, as a CmdVel.
struct Stamp {
  std::uint64_t seq{};
  std::uint64_t tsc{};
};
HORUS_REFLECT(Stamp, seq, tsc)
/// A 64 KiB message, for the memory table.
struct Block64k {
  std::uint64_t seq{};
  std::array<std::uint8_t, 65528> payload{};
};
HORUS_REFLECT(Block64k, seq, payload)
}  // namespace bench_msg

namespace {

namespace hb = horus::bench;
namespace probe = horus::bench::fanout;
using Clock = std::chrono::steady_clock;

constexpr int kMaxSubs = 64;

// Shared between the publisher and the subscriber processes (MAP_SHARED | MAP_ANONYMOUS).
struct alignas(128) Slot64 {
  std::atomic<std::uint64_t> v{0};
};
struct Control {
  Slot64 ready;                      // subscribers that have subscribed
  Slot64 stop;                       // the publisher is done
  Slot64 word;                       // the raw futex fan-out: its futex word (low half)
  Slot64 seq, tsc;                   // the raw futex fan-out: the message
  Slot64 last[kMaxSubs];             // per subscriber: messages received
};                                   // then the samples: [subscriber][message] ticks

struct Shared {
  Control* c = nullptr;
  std::size_t bytes = 0;
  std::size_t per_sub = 0;
  std::uint64_t* at(int sub) const {
    return reinterpret_cast<std::uint64_t*>(reinterpret_cast<char*>(c) + sizeof(Control)) +
           static_cast<std::size_t>(sub) * per_sub;
  }
};

Shared map_control(std::size_t per_sub) {
  Shared s;
  s.per_sub = per_sub;
  s.bytes = sizeof(Control) + kMaxSubs * per_sub * sizeof(std::uint64_t);
  void* p = ::mmap(nullptr, s.bytes, PROT_READ | PROT_WRITE, MAP_SHARED | MAP_ANONYMOUS, -1, 0);
  if (p == MAP_FAILED) throw std::runtime_error("mmap of the control block failed");
  s.c = new (p) Control{};
  return s;
}

void unmap(Shared& s) { ::munmap(s.c, s.bytes); }

std::string unique(const char* what) {
  static int n = 0;
  return fmt::format("bench.fanout.{}.{}.{}", what, ::getpid(), n++);
}

template <class F>
pid_t spawn(F&& f) {
  const pid_t pid = ::fork();
  if (pid < 0) throw std::runtime_error("fork failed");
  if (pid == 0) {
    int rc = 0;
    try {
      f();
    } catch (const std::exception& e) {
      fmt::print(stderr, "horus-fanout child: {}\n", e.what());
      rc = 1;
    }
    ::_exit(rc);
  }
  return pid;
}

bool wait_all(const std::vector<pid_t>& pids) {
  bool ok = true;
  for (pid_t p : pids) {
    int st = 0;
    ::waitpid(p, &st, 0);
    ok = ok && WIFEXITED(st) && WEXITSTATUS(st) == 0;
  }
  return ok;
}

// Waits until `pred` holds (true) or the deadline passes (false). `pred` reads counters the
// subscriber processes write in the shared control block; the publisher polls it every 20 us
// asleep rather than spinning or blocking on a topic of its own: on 2 vCPUs a spinning
// publisher would take a CPU from the subscribers it measures, and an acknowledgement topic
// would add wake-ups of its own to the figures.
template <class Pred>
bool sleep_until(Pred pred, std::chrono::milliseconds limit) {
  const auto end = Clock::now() + limit;
  while (!pred()) {
    if (Clock::now() > end) return false;
    std::this_thread::sleep_for(std::chrono::microseconds(20));
  }
  return true;
}

struct FanoutResult {
  hb::Percentiles each, all;
  std::uint64_t missing = 0;  // (message, subscriber) pairs never received
};

template <class TickOf>
FanoutResult summarize(int n, std::uint64_t messages, TickOf&& tick_of, bool ok, const hb::TscClock& tsc);

// One publisher (this process) to n subscriber processes: `subscriber(i, sh)` runs in child i
// (it counts itself in sh.c->ready once it receives, writes each message's latency in ticks to
// sh.at(i)[seq] and its count to sh.c->last[i]); `send(k)` sends message k.
template <class Subscriber, class Send>
FanoutResult run_fanout(int n, std::uint64_t messages, std::chrono::microseconds gap, const hb::TscClock& tsc,
                        Shared& sh, Subscriber&& subscriber, Send&& send) {
  std::vector<pid_t> pids;
  for (int i = 0; i < n; ++i) pids.push_back(spawn([&, i] { subscriber(i, sh); }));
  if (!sleep_until([&] { return sh.c->ready.v.load(std::memory_order_acquire) == static_cast<std::uint64_t>(n); },
                   std::chrono::seconds(20)))
    throw std::runtime_error("subscribers did not start");
  for (std::uint64_t k = 0; k < messages; ++k) {
    send(k);
    // The next one once every subscriber has this one (or 100 ms: a pair never received is
    // counted in `missing`), then the gap (--gap-us, the benchmark's pacing, not a wait for
    // anything): the subscribers are blocked again when the next one goes.
    sleep_until(
        [&] {
          for (int i = 0; i < n; ++i)
            if (sh.c->last[i].v.load(std::memory_order_acquire) <= k) return false;
          return true;
        },
        std::chrono::milliseconds(100));
    std::this_thread::sleep_for(gap);
  }
  sh.c->stop.v.store(1, std::memory_order_release);
  const bool ok = wait_all(pids);
  return summarize(n, messages, [&](int i, std::uint64_t k) { return sh.at(i)[k]; }, ok, tsc);
}

// Percentiles of every (message, subscriber) pair and of "all delivered"; tick_of(i, k): TSC
// ticks from send to receipt of message k by subscriber i, 0 when never received.
template <class TickOf>
FanoutResult summarize(int n, std::uint64_t messages, TickOf&& tick_of, bool ok, const hb::TscClock& tsc) {
  FanoutResult r;
  std::vector<double> each, all;
  for (std::uint64_t k = 0; k < messages; ++k) {
    double worst = 0;
    bool complete = true;
    for (int i = 0; i < n; ++i) {
      const std::uint64_t t = tick_of(i, k);
      if (t == 0) {
        ++r.missing;
        complete = false;
        continue;
      }
      const double ns = tsc.to_ns(t);
      each.push_back(ns);
      worst = std::max(worst, ns);
    }
    if (complete) all.push_back(worst);
  }
  if (!ok) r.missing += 1;  // a child failed: never report a clean result
  r.each = hb::percentiles(each);
  r.all = hb::percentiles(all);
  return r;
}

// horus: n subscriber processes blocked in recv_for.
FanoutResult fanout_latency(int n, std::uint64_t messages, std::chrono::microseconds gap, const hb::TscClock& tsc) {
  const std::string name = unique("lat");
  Shared sh = map_control(messages);
  horus::Topic<bench_msg::Stamp> pub(name);
  const auto r = run_fanout(
      n, messages, gap, tsc, sh,
      [&](int i, Shared& s) {
        horus::Topic<bench_msg::Stamp> sub(name);
        (void)sub.recv();  // subscribes: every message from now on is delivered
        s.c->ready.v.fetch_add(1, std::memory_order_acq_rel);
        std::uint64_t* out = s.at(i);
        std::uint64_t got = 0;
        while (got < messages && s.c->stop.v.load(std::memory_order_acquire) == 0) {
          auto m = sub.recv_for(std::chrono::milliseconds(200));
          if (!m) continue;
          const std::uint64_t now = hb::TscClock::now();
          if (m->seq < messages) out[m->seq] = now - m->tsc;
          ++got;
          s.c->last[i].v.store(got, std::memory_order_release);
        }
      },
      [&](std::uint64_t k) { pub.send({k, hb::TscClock::now()}); });
  unmap(sh);
  return r;
}

// The machine's floor for the same thing: n processes asleep in FUTEX_WAIT on one shared word,
// the publisher stores the message (sequence, TSC) beside it, bumps it and makes one
// FUTEX_WAKE for all: the kernel's sleep and wake-up of n processes and nothing else.
FanoutResult fanout_latency_futex(int n, std::uint64_t messages, std::chrono::microseconds gap,
                                  const hb::TscClock& tsc) {
  Shared sh = map_control(messages);
  auto* word = reinterpret_cast<std::uint32_t*>(&sh.c->word.v);  // the low half (little-endian)
  static_assert(std::endian::native == std::endian::little);
  const auto r = run_fanout(
      n, messages, gap, tsc, sh,
      [&](int i, Shared& s) {
        s.c->ready.v.fetch_add(1, std::memory_order_acq_rel);
        std::uint64_t* out = s.at(i);
        std::uint64_t got = 0;
        std::uint32_t seen = std::atomic_ref(*word).load(std::memory_order_acquire);
        while (got < messages && s.c->stop.v.load(std::memory_order_acquire) == 0) {
          const std::uint32_t now_word = std::atomic_ref(*word).load(std::memory_order_acquire);
          if (now_word == seen) {
            const timespec limit{0, 200'000'000};
            ::syscall(SYS_futex, word, FUTEX_WAIT, seen, &limit, nullptr, 0);
            continue;
          }
          seen = now_word;
          const std::uint64_t now = hb::TscClock::now();
          const std::uint64_t seq = s.c->seq.v.load(std::memory_order_relaxed);
          if (seq < messages) out[seq] = now - s.c->tsc.v.load(std::memory_order_relaxed);
          ++got;
          s.c->last[i].v.store(got, std::memory_order_release);
        }
      },
      [&](std::uint64_t k) {
        sh.c->seq.v.store(k, std::memory_order_relaxed);
        sh.c->tsc.v.store(hb::TscClock::now(), std::memory_order_relaxed);
        std::atomic_ref(*word).fetch_add(1, std::memory_order_release);
        ::syscall(SYS_futex, word, FUTEX_WAKE, INT_MAX, nullptr, nullptr, 0);
      });
  unmap(sh);
  return r;
}

// Lossless fan-out throughput: send_blocking to n subscribers in recv_for.
double fanout_throughput(int n, std::uint64_t messages) {
  const std::string name = unique("tput");
  Shared sh = map_control(0);
  horus::Topic<bench_msg::Stamp> pub(name);
  std::vector<pid_t> pids;
  for (int i = 0; i < n; ++i)
    pids.push_back(spawn([&, i] {
      horus::Topic<bench_msg::Stamp> sub(name);
      (void)sub.recv();
      sh.c->ready.v.fetch_add(1, std::memory_order_acq_rel);
      std::uint64_t got = 0;
      while (got < messages) {
        auto m = sub.recv_for(std::chrono::seconds(5));
        if (!m) throw std::runtime_error(fmt::format("subscriber {}: nothing for 5 s after {}", i, got));
        if (m->seq != got) throw std::runtime_error(fmt::format("subscriber {}: got {} for {}", i, m->seq, got));
        ++got;
      }
      sh.c->last[i].v.store(got, std::memory_order_release);
    }));
  if (!sleep_until([&] { return sh.c->ready.v.load(std::memory_order_acquire) == static_cast<std::uint64_t>(n); },
                   std::chrono::seconds(20)))
    throw std::runtime_error("subscribers did not start");
  const auto t0 = Clock::now();
  for (std::uint64_t k = 0; k < messages; ++k) {
    auto r = pub.send_blocking({k, 0}, std::chrono::seconds(5));
    if (!r) throw std::runtime_error("send_blocking: " + r.error().message());
  }
  sleep_until(
      [&] {
        for (int i = 0; i < n; ++i)
          if (sh.c->last[i].v.load(std::memory_order_acquire) < messages) return false;
        return true;
      },
      std::chrono::seconds(30));
  const double secs = std::chrono::duration<double>(Clock::now() - t0).count();
  const bool ok = wait_all(pids);
  unmap(sh);
  if (!ok) throw std::runtime_error("a throughput subscriber failed");
  return static_cast<double>(messages) / secs;
}

// A CmdVel-sized ping-pong between two pinned processes with `topics` topics open in each
// (and each used once), measured on the last one opened.
std::vector<double> many_topics_latency(int topics, std::uint64_t rounds, const std::vector<int>& cpus,
                                        const hb::TscClock& tsc) {
  const std::string base = unique("many");
  Shared sh = map_control(0);
  auto open_all = [&](std::vector<horus::Topic<bench_msg::Stamp>>& v) {
    v.reserve(static_cast<std::size_t>(topics));
    for (int i = 0; i < topics - 1; ++i) {
      v.emplace_back(fmt::format("{}.{}", base, i));
      v.back().send({0, 0});
      (void)v.back().recv();
    }
  };
  const std::string ping = base + ".ping", pong = base + ".pong";
  const pid_t child = spawn([&] {
    hb::pin_to_cpu(cpus[1]);  // the child has one thread
    std::vector<horus::Topic<bench_msg::Stamp>> others;
    open_all(others);
    horus::Topic<bench_msg::Stamp> in(ping), out(pong);
    (void)in.recv();
    sh.c->ready.v.store(1, std::memory_order_release);
    for (std::uint64_t k = 0; k < rounds;) {
      if (auto m = in.recv()) {
        out.send(*m);
        ++k;
      } else {
        hb::spin_pause();
      }
    }
  });
  hb::pin_to_cpu(cpus[0]);
  std::vector<horus::Topic<bench_msg::Stamp>> others;
  open_all(others);
  horus::Topic<bench_msg::Stamp> out(ping), in(pong);
  (void)in.recv();
  while (sh.c->ready.v.load(std::memory_order_acquire) == 0) hb::spin_pause();
  std::vector<double> v;
  v.reserve(rounds);
  for (std::uint64_t k = 0; k < rounds; ++k) {
    const auto t0 = hb::TscClock::now();
    out.send({k, t0});
    for (;;) {
      if (auto m = in.recv()) {
        if (m->seq == k) break;
      } else {
        hb::spin_pause();
      }
    }
    v.push_back(tsc.to_ns(hb::TscClock::now() - t0) / 2.0);
  }
  wait_all({child});
  unmap(sh);
  return v;
}

struct MemoryRow {
  std::string type;
  std::size_t bytes;
  std::uint64_t segment, allocated;
  double rss_per_topic_kib;
};

// Opens `count` topics of T (each sent to and received from once), in a child process so that
// its RSS starts clean; reports the segment of one and the RSS gained per topic.
template <class T>
MemoryRow memory_of(const char* type, int count) {
  Shared sh = map_control(0);
  const std::string base = unique("mem");
  const pid_t child = spawn([&] {
    std::vector<horus::Topic<T>> v;
    v.reserve(static_cast<std::size_t>(count));
    auto msg = std::make_unique<T>();
    const long before = probe::rss_kib();
    for (int i = 0; i < count; ++i) {
      v.emplace_back(fmt::format("{}.{}", base, i));
      v.back().send(*msg);
      (void)v.back().recv();
    }
    const long after = probe::rss_kib();
    const auto seg = probe::segment_bytes(base + ".0");
    sh.c->last[0].v.store(seg.first, std::memory_order_relaxed);
    sh.c->last[1].v.store(seg.second, std::memory_order_relaxed);
    sh.c->last[2].v.store(static_cast<std::uint64_t>(std::max(0L, after - before)), std::memory_order_relaxed);
    sh.c->ready.v.store(1, std::memory_order_release);
  });
  const bool ok = wait_all({child});
  MemoryRow r{type, sizeof(T), sh.c->last[0].v.load(), sh.c->last[1].v.load(),
              static_cast<double>(sh.c->last[2].v.load()) / count};
  unmap(sh);
  if (!ok) throw std::runtime_error("the memory probe failed");
  return r;
}

double median(std::vector<double> v) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}
// "median (min-max)" of the rounds, with `digits` decimals.
std::string spread(const std::vector<double>& v, int digits = 0) {
  if (v.empty()) return "-";
  const auto [lo, hi] = std::minmax_element(v.begin(), v.end());
  if (v.size() == 1) return fmt::format("{:.{}f}", v[0], digits);
  return fmt::format("{:.{}f} ({:.{}f}-{:.{}f})", median(v), digits, *lo, digits, *hi, digits);
}

struct Options {
  std::vector<int> subs{1, 2, 4, 8, 16};
  std::vector<int> topic_counts{1, 100, 1000};
  std::uint64_t messages = 2000, tput_messages = 200000, pingpong_rounds = 20000;
  int rounds = 3, gap_us = 200;
  std::vector<int> cpus{0, 1};
  bool quick = false, no_iceoryx = false;
  std::string json_path;
};

// Reads the command line into `o` (--quick shrinks the run); the exit code when the program
// stops there (--help, a bad option).
std::optional<int> parse_options(Options& o, int argc, char** argv) {
  CLI::App app{"horus fan-out: one publisher to N subscriber processes, and many topics in one process"};
  app.add_option("--subscribers", o.subs, "subscriber counts")->check(CLI::Range(1, kMaxSubs));
  app.add_option("--topics", o.topic_counts, "topic counts for the many-topics ping-pong")->check(CLI::Range(1, 5000));
  app.add_option("--messages", o.messages, "messages per fan-out latency measurement");
  app.add_option("--throughput", o.tput_messages, "messages per fan-out throughput measurement");
  app.add_option("--rounds", o.rounds, "repeats of every measurement (medians and spread)")->check(CLI::Range(1, 50));
  app.add_option("--gap-us", o.gap_us, "pause between fan-out messages (subscribers fall asleep)");
  app.add_option("--cpus", o.cpus, "the two CPUs of the ping-pong")->expected(2);
  app.add_option("--json", o.json_path, "also write the figures as JSON");
  app.add_flag("--quick", o.quick, "a short smoke run (without iceoryx)");
  app.add_flag("--no-iceoryx", o.no_iceoryx, "leave out the iceoryx 2.0 fan-out");
  CLI11_PARSE(app, argc, argv);
  if (o.quick) {
    o.subs = {1, 4};
    o.topic_counts = {1, 100};
    o.messages = 100;
    o.tput_messages = 5000;
    o.pingpong_rounds = 2000;
    o.rounds = 1;
  }
  return std::nullopt;
}

// The iceoryx 2.0 fan-out beside horus: on while it works, else why not (said under the table).
struct IoxRun {
  bool on = false;
  std::string why = "not built (iceoryx_posh not found by CMake)";
  std::string self_exe;  // its helpers are re-executed from this binary
};

// One implementation's fan-out latency to one N: a figure per round.
struct Rows {
  std::vector<double> p50, p99, p999, a50, a99;
  std::uint64_t missing = 0;
  void add(const FanoutResult& res) {
    p50.push_back(res.each.p50);
    p99.push_back(res.each.p99);
    p999.push_back(res.each.p999);
    a50.push_back(res.all.p50);
    a99.push_back(res.all.p99);
    missing += res.missing;
  }
};
struct FanoutRounds {
  Rows horus, futex, iox;
  std::vector<double> ratio, iox_ratio;  // all delivered p50: horus / raw futex, iceoryx / horus
};

// --rounds fan-outs to n subscribers of horus, the raw futex floor and iceoryx, alternating.
FanoutRounds fanout_rounds(const Options& o, int n, const hb::TscClock& tsc, [[maybe_unused]] IoxRun& iox) {
  FanoutRounds f;
  for (int r = 0; r < o.rounds; ++r) {  // alternating: all see the same machine
    f.horus.add(fanout_latency(n, o.messages, std::chrono::microseconds(o.gap_us), tsc));
    f.futex.add(fanout_latency_futex(n, o.messages, std::chrono::microseconds(o.gap_us), tsc));
    f.ratio.push_back(f.horus.a50.back() / f.futex.a50.back());
#ifdef HORUS_BENCH_ICEORYX
    if (iox.on) {
      const auto ticks = hb::iox::fanout(n, o.messages, static_cast<std::uint64_t>(o.gap_us), iox.self_exe, &iox.why);
      if (ticks.empty()) {
        iox.on = false;  // said once below, with the reason
      } else {
        f.iox.add(summarize(n, o.messages, [&](int i, std::uint64_t k) { return ticks[static_cast<std::size_t>(i)][k]; },
                            true, tsc));
        f.iox_ratio.push_back(f.iox.a50.back() / f.horus.a50.back());
      }
    }
#endif
  }
  return f;
}

void print_fanout_rows(int n, const FanoutRounds& f) {
  for (const auto* rows : {&f.horus, &f.futex, &f.iox}) {
    if (rows->p50.empty()) continue;
    fmt::print("{:>4} {:<10} {:>22} {:>22} {:>22} {:>22} {:>22}{}\n", n,
               rows == &f.horus ? "horus" : rows == &f.futex ? "raw futex" : "iceoryx",
               spread(rows->p50), spread(rows->p99), spread(rows->p999), spread(rows->a50), spread(rows->a99),
               rows->missing != 0 ? fmt::format("  ({} not received)", rows->missing) : "");
  }
  fmt::print("{:>4} {:<10} all delivered p50 horus / raw futex: {}{}\n", n, "", spread(f.ratio, 2),
             f.iox_ratio.empty() ? "" : ", iceoryx / horus: " + spread(f.iox_ratio, 2));
}

void add_fanout_json(nlohmann::json& j, int n, const FanoutRounds& f) {
  j["fanout_latency"].push_back({{"subscribers", n},
                                 {"p50_ns", f.horus.p50},
                                 {"p99_ns", f.horus.p99},
                                 {"p999_ns", f.horus.p999},
                                 {"all_p50_ns", f.horus.a50},
                                 {"all_p99_ns", f.horus.a99},
                                 {"missing", f.horus.missing},
                                 {"futex_p50_ns", f.futex.p50},
                                 {"futex_p99_ns", f.futex.p99},
                                 {"futex_all_p50_ns", f.futex.a50},
                                 {"futex_all_p99_ns", f.futex.a99},
                                 {"futex_missing", f.futex.missing},
                                 {"all_p50_over_futex", f.ratio}});
  if (!f.iox.p50.empty()) {
    auto& row = j["fanout_latency"].back();
    row["iox_p50_ns"] = f.iox.p50;
    row["iox_p99_ns"] = f.iox.p99;
    row["iox_all_p50_ns"] = f.iox.a50;
    row["iox_all_p99_ns"] = f.iox.a99;
    row["iox_missing"] = f.iox.missing;
    row["iox_all_p50_over_horus"] = f.iox_ratio;
  }
}

// The fan-out latency table; by N, horus's median p50 and all-delivered ratio to the raw futex.
void fanout_latency_table(const Options& o, const hb::TscClock& tsc, IoxRun& iox, nlohmann::json& j,
                          std::vector<double>& p50_by_n, std::vector<double>& ratio_by_n) {
  fmt::print("\n1 publisher -> N subscriber processes blocked in recv_for, a 16 B message every {} us;\n"
             "beside it the machine's floor: N processes asleep in FUTEX_WAIT on one word, one FUTEX_WAKE for all\n",
             o.gap_us);
  fmt::print("{:>4} {:<10} {:>22} {:>22} {:>22} {:>22} {:>22}\n", "N", "", "p50 ns", "p99 ns", "p99.9 ns",
             "all delivered p50", "all delivered p99");
  for (int n : o.subs) {
    const FanoutRounds f = fanout_rounds(o, n, tsc, iox);
    p50_by_n.push_back(median(f.horus.p50));
    ratio_by_n.push_back(median(f.ratio));
    print_fanout_rows(n, f);
    add_fanout_json(j, n, f);
  }
  if (!iox.on) fmt::print("iceoryx 2.0: {}\n", iox.why);
  else fmt::print("iceoryx 2.0: subscribers blocked in a WaitSet (HAS_DATA), 16-byte loaned samples, a private RouDi\n");
}

void fanout_throughput_table(const Options& o, nlohmann::json& j) {
  fmt::print("\nlossless fan-out throughput (send_blocking; subscribers in recv_for), 16 B messages\n");
  fmt::print("{:>4} {:>30}\n", "N", "M msg/s to every subscriber");
  for (int n : o.subs) {
    std::vector<double> t;
    for (int r = 0; r < o.rounds; ++r) t.push_back(fanout_throughput(n, o.tput_messages) / 1e6);
    fmt::print("{:>4} {:>30}\n", n, spread(t, 2));
    j["fanout_throughput"].push_back({{"subscribers", n}, {"msgs_per_s_millions", t}});
  }
}

// The many-topics table; returns the median p50 by topic count.
std::vector<double> many_topics_table(const Options& o, const hb::TscClock& tsc, nlohmann::json& j) {
  fmt::print("\nmany topics open in both processes, CmdVel-sized ping-pong on one (RTT/2, spins with pause)\n");
  fmt::print("{:>7} {:>22} {:>22}\n", "topics", "p50 ns", "p99 ns");
  std::vector<double> many_p50;
  for (int t : o.topic_counts) {
    std::vector<double> p50, p99;
    for (int r = 0; r < o.rounds; ++r) {
      auto v = many_topics_latency(t, o.pingpong_rounds, o.cpus, tsc);
      const auto p = hb::percentiles(v);
      p50.push_back(p.p50);
      p99.push_back(p.p99);
    }
    many_p50.push_back(median(p50));
    fmt::print("{:>7} {:>22} {:>22}\n", t, spread(p50, 1), spread(p99, 1));
    j["many_topics"].push_back({{"topics", t}, {"p50_ns", p50}, {"p99_ns", p99}});
  }
  return many_p50;
}

void memory_table(const Options& o, nlohmann::json& j) {
  fmt::print("\nmemory of a topic (default capacity), by message size\n");
  fmt::print("{:<10} {:>8} {:>16} {:>16} {:>22}\n", "message", "bytes", "segment (size)", "allocated",
             "RSS per topic (KiB)");
  const int mem_topics = o.quick ? 10 : 100;
  for (const auto& row : {memory_of<bench_msg::Stamp>("16 B", mem_topics),
                          memory_of<horus_bench::Kilobyte>("1 KiB", mem_topics),
                          memory_of<bench_msg::Block64k>("64 KiB", std::max(2, mem_topics / 10))}) {
    fmt::print("{:<10} {:>8} {:>16} {:>16} {:>22.1f}\n", row.type, row.bytes, row.segment, row.allocated,
               row.rss_per_topic_kib);
    j["memory"].push_back({{"message", row.type}, {"bytes", row.bytes}, {"segment_bytes", row.segment},
                           {"allocated_bytes", row.allocated}, {"rss_per_topic_kib", row.rss_per_topic_kib}});
  }
}

void print_targets(const Options& o, const std::vector<double>& p50_by_n, const std::vector<double>& ratio_by_n,
                   const std::vector<double>& many_p50) {
  fmt::print("\nreference: HORUS (Rust) publishes 198 / 236 / 276 ns for 2 / 4 / 8 subscribers on an i7-10750H\n");
  if (p50_by_n.size() >= 2) {
    const double ratio = p50_by_n.back() / p50_by_n.front();
    fmt::print("targets: p50 with {} subscribers <= 2x one subscriber: {:.2f}x {} (all delivered: {:.2f}x the raw "
               "futex floor of {} sleeping processes)",
               o.subs.back(), ratio, ratio <= 2.0 ? "met" : "MISSED", ratio_by_n.back(), o.subs.back());
  }
  if (many_p50.size() >= 2) {
    const double ratio = many_p50.back() / many_p50.front();
    fmt::print(" | {} topics open do not slow one (p50 <= 1.1x of 1 topic): {:.2f}x {}", o.topic_counts.back(), ratio,
               ratio <= 1.1 ? "met" : "MISSED");
  }
  fmt::print("\n");
}

}  // namespace

int main(int argc, char** argv) {
#ifdef HORUS_BENCH_ICEORYX
  if (auto rc = hb::iox::child_main(argc, argv)) return *rc;  // the iceoryx fan-out helpers
#endif
  Options o;
  if (auto rc = parse_options(o, argc, argv)) return *rc;
  probe::raise_fd_limit();
  const hb::TscClock tsc;
  // iceoryx 2.0 beside horus: a private RouDi for the run, helpers re-executed from this binary.
  IoxRun iox;
#ifdef HORUS_BENCH_ICEORYX
  if (o.quick || o.no_iceoryx) iox.why = o.quick ? "left out of --quick" : "skipped (--no-iceoryx)";
  const std::optional<hb::iox::Roudi> roudi =
      o.quick || o.no_iceoryx ? std::nullopt : hb::iox::Roudi::start(&iox.why);  // stopped when main returns
  iox.on = roudi.has_value();
  char self_buf[4096];
  const ssize_t self_len = ::readlink("/proc/self/exe", self_buf, sizeof(self_buf) - 1);
  iox.self_exe = self_len > 0 ? std::string(self_buf, static_cast<std::size_t>(self_len)) : argv[0];
#endif
  nlohmann::json j;
  fmt::print("horus fan-out and scale, shared memory ({} CPUs, {} round{} of each measurement)\n", hb::cpu_count(),
             o.rounds, o.rounds == 1 ? "" : "s");
  if (!probe::tsc_is_invariant())
    fmt::print("warning: /proc/cpuinfo lacks constant_tsc/nonstop_tsc: cross-process TSC stamps may not compare\n");

  std::vector<double> p50_by_n, ratio_by_n;
  fanout_latency_table(o, tsc, iox, j, p50_by_n, ratio_by_n);
  fanout_throughput_table(o, j);
  const std::vector<double> many_p50 = many_topics_table(o, tsc, j);
  memory_table(o, j);
  print_targets(o, p50_by_n, ratio_by_n, many_p50);
  if (!o.json_path.empty()) std::ofstream(o.json_path) << j.dump(2) << "\n";
  return 0;
}
