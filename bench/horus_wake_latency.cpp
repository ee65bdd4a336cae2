// horus-wake-latency: what a blocked receiver costs, against the raw kernel primitive in the
// same run.
//
//   * wake-up latency between two processes: a ping-pong where each side sleeps until the
//     other's message arrives, one-way = RTT/2, p50/p99/p99.9:
//       raw    two futex words in a MAP_SHARED page: store, FUTEX_WAKE; the other side in
//              FUTEX_WAIT (the floor: nothing but the kernel's sleep and wake-up)
//       horus  Topic<CmdVel> over shared memory, both sides blocked in recv_for
//     Rounds alternate raw and horus blocks; the ratio is the median of the per-round p50
//     ratios, with its spread (the machine is shared and noisy).
//   * idle cost: the CPU time (getrusage, this thread) of a recv_for that waits 1 s for nothing.
// Parent and child are pinned to two CPUs when there are two.
#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include <linux/futex.h>
#include <sys/mman.h>
#include <sys/resource.h>
#include <sys/syscall.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <climits>
#include <cstdint>
#include <string>
#include <vector>

#include "bench_common.hpp"
#include "horus/msg/geometry.hpp"
#include "horus/topic.hpp"

namespace hb = horus::bench;
using Clock = std::chrono::steady_clock;
using horus::msg::CmdVel;

namespace {

struct alignas(128) Word {
  std::atomic<std::uint32_t> v{0};
};
struct Raw {
  Word ping, pong;
};

void futex_wait(std::atomic<std::uint32_t>& w, std::uint32_t val) {
  ::syscall(SYS_futex, &w, FUTEX_WAIT, val, nullptr, nullptr, 0);
}
void futex_wake(std::atomic<std::uint32_t>& w) { ::syscall(SYS_futex, &w, FUTEX_WAKE, INT_MAX, nullptr, nullptr, 0); }

// Sleeps until w == want (FUTEX_WAIT on whatever value it has).
void wait_for_value(std::atomic<std::uint32_t>& w, std::uint32_t want) {
  for (;;) {
    const std::uint32_t v = w.load(std::memory_order_acquire);
    if (v == want) return;
    futex_wait(w, v);
  }
}

double ns_since(Clock::time_point t0) {
  return static_cast<double>(std::chrono::duration_cast<std::chrono::nanoseconds>(Clock::now() - t0).count());
}

std::vector<double> raw_round(int iters, bool pin) {
  auto* raw = static_cast<Raw*>(::mmap(nullptr, sizeof(Raw), PROT_READ | PROT_WRITE, MAP_SHARED | MAP_ANONYMOUS, -1, 0));
  if (raw == MAP_FAILED) throw std::runtime_error("mmap failed");
  new (raw) Raw{};
  const pid_t child = ::fork();
  if (child == 0) {
    if (pin) hb::pin_to_cpu(1);
    for (int i = 1; i <= iters; ++i) {
      wait_for_value(raw->ping.v, static_cast<std::uint32_t>(i));
      raw->pong.v.store(static_cast<std::uint32_t>(i), std::memory_order_release);
      futex_wake(raw->pong.v);
    }
    ::_exit(0);
  }
  std::vector<double> ns;
  ns.reserve(static_cast<std::size_t>(iters));
  for (int i = 1; i <= iters; ++i) {
    const auto t0 = Clock::now();
    raw->ping.v.store(static_cast<std::uint32_t>(i), std::memory_order_release);
    futex_wake(raw->ping.v);
    wait_for_value(raw->pong.v, static_cast<std::uint32_t>(i));
    ns.push_back(ns_since(t0) / 2);
  }
  ::waitpid(child, nullptr, 0);
  ::munmap(raw, sizeof(Raw));
  return ns;
}

std::vector<double> horus_round(int iters, bool pin, int round) {
  const std::string base = "bench.wake." + std::to_string(::getpid()) + "." + std::to_string(round);
  horus::TopicOptions shm;
  shm.backend = horus::Backend::SharedMemory;
  auto pong = horus::Topic<CmdVel>::open(base + ".pong", shm);
  if (!pong) throw std::runtime_error(pong.error().message());
  const pid_t child = ::fork();
  if (child == 0) {
    if (pin) hb::pin_to_cpu(1);
    auto ping_sub = horus::Topic<CmdVel>::open(base + ".ping", shm);
    auto pong_pub = horus::Topic<CmdVel>::open(base + ".pong", shm);
    if (!ping_sub || !pong_pub) ::_exit(3);
    pong_pub->send(CmdVel::make(-1.0f, 0.0f));  // ready
    for (int i = 0; i < iters; ++i) {
      auto m = ping_sub->recv_for(std::chrono::seconds(5));
      if (!m) ::_exit(4);
      pong_pub->send(*m);
    }
    ::_exit(0);
  }
  auto ping = horus::Topic<CmdVel>::open(base + ".ping", shm);
  if (!ping) throw std::runtime_error(ping.error().message());
  if (!pong->recv_for(std::chrono::seconds(10))) throw std::runtime_error("the child did not start");
  std::vector<double> ns;
  ns.reserve(static_cast<std::size_t>(iters));
  for (int i = 0; i < iters; ++i) {
    const auto t0 = Clock::now();
    ping->send(CmdVel::make(static_cast<float>(i), 0.0f));
    if (!pong->recv_for(std::chrono::seconds(5))) throw std::runtime_error("a pong was lost");
    ns.push_back(ns_since(t0) / 2);
  }
  int status = 0;
  ::waitpid(child, &status, 0);
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) throw std::runtime_error("the child failed");
  return ns;
}

double thread_cpu_us() {
  rusage ru{};
  ::getrusage(RUSAGE_THREAD, &ru);
  return static_cast<double>(ru.ru_utime.tv_sec + ru.ru_stime.tv_sec) * 1e6 +
         static_cast<double>(ru.ru_utime.tv_usec + ru.ru_stime.tv_usec);
}

void print_row(const std::string& what, const hb::Percentiles& p) {
  fmt::print("  {:<34} p50 {:>8.0f} ns   p99 {:>8.0f} ns   p99.9 {:>8.0f} ns\n", what, p.p50, p.p99, p.p999);
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"horus-wake-latency: blocked receivers, horus recv_for against a raw futex ping-pong"};
  int rounds = 7;
  int iters = 2000;
  bool quick = false;
  app.add_option("--rounds", rounds, "alternating raw/horus rounds")->check(CLI::PositiveNumber);
  app.add_option("--iters", iters, "round trips per round")->check(CLI::PositiveNumber);
  app.add_flag("--quick", quick, "2 rounds of 300 (a smoke run)");
  CLI11_PARSE(app, argc, argv);
  if (quick) {
    rounds = 2;
    iters = 300;
  }
  const bool pin = hb::cpu_count() >= 2;
  if (pin) hb::pin_to_cpu(0);
  try {
    fmt::print("wake-up latency between two processes, both sides blocked (one-way = RTT/2), {} rounds of {}\n",
               rounds, iters);
    std::vector<double> ratios;
    std::vector<double> all_raw, all_horus;
    for (int r = 0; r < rounds; ++r) {
      auto raw = raw_round(iters, pin);
      auto hs = horus_round(iters, pin, r);
      all_raw.insert(all_raw.end(), raw.begin(), raw.end());
      all_horus.insert(all_horus.end(), hs.begin(), hs.end());
      const auto pr = hb::percentiles(raw);
      const auto ph = hb::percentiles(hs);
      fmt::print(" round {}\n", r + 1);
      print_row("raw futex ping-pong", pr);
      print_row("horus Topic<CmdVel> recv_for", ph);
      ratios.push_back(ph.p50 / pr.p50);
    }
    std::sort(ratios.begin(), ratios.end());
    fmt::print(" all rounds\n");
    print_row("raw futex ping-pong", hb::percentiles(all_raw));
    print_row("horus Topic<CmdVel> recv_for", hb::percentiles(all_horus));
    fmt::print("horus/raw p50: median {:.2f}x (rounds {:.2f}x .. {:.2f}x; target <= 1.30x)\n",
               ratios[ratios.size() / 2], ratios.front(), ratios.back());

    horus::TopicOptions shm;
    shm.backend = horus::Backend::SharedMemory;
    auto idle = horus::Topic<CmdVel>::open("bench.wake.idle." + std::to_string(::getpid()), shm);
    if (!idle) throw std::runtime_error(idle.error().message());
    const double cpu0 = thread_cpu_us();
    const auto t0 = Clock::now();
    (void)idle->recv_for(std::chrono::seconds(1));
    const double wall_ms = ns_since(t0) / 1e6;
    fmt::print("idle: recv_for waited {:.0f} ms for nothing and used {:.0f} us of CPU (target < 1000 us)\n", wall_ms,
               thread_cpu_us() - cpu0);
  } catch (const std::exception& e) {
    fmt::print(stderr, "horus-wake-latency: {}\n", e.what());
    return 1;
  }
  return 0;
}
