// horus-latency-shm: cross-process latency and throughput of shared-memory topics, with the
// floor measured in the same run.
//
//   * floor: one cache line bounced between two processes through a MAP_SHARED page;
//   * horus Topic<CmdVel> (16 B), a 1 KiB message, and a 1920x1080 RGB Image: ping-pong between
//     two processes (fork), one-way = RTT/2, p50/p99/p99.9;
//   * throughput: CmdVel messages per second from one process to another, lossless
//     (try_send until accepted).
// Parent and child are pinned to two CPUs (--cpus). Blocks of floor and horus rounds are
// interleaved and the ratio to the floor is the median over blocks of the per-block ratio,
// because on a shared VM the floor itself moves from run to run.
#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include <sched.h>
#include <sys/mman.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <stdexcept>
#include <atomic>
#include <cstdint>
#include <fstream>
#include <string>
#include <vector>

#include "bench_common.hpp"
#include "horus/horus.hpp"

namespace hb = horus::bench;

namespace bench_msg {
/// A 1 KiB message: a sequence number and 1016 bytes of payload.
struct Kilobyte {
  std::uint64_t seq{};
  std::array<std::uint8_t, 1016> payload{};
};
HORUS_REFLECT(Kilobyte, seq, payload)
}  // namespace bench_msg

namespace {

inline void hb_relax() { horus::shm::cpu_relax(); }

struct alignas(64) Line {
  std::atomic<std::uint64_t> v{0};
};
struct Shared {
  Line ping, pong;
  Line ready;
  Line done;
};

Shared* map_shared() {
  void* p = ::mmap(nullptr, sizeof(Shared), PROT_READ | PROT_WRITE, MAP_SHARED | MAP_ANONYMOUS, -1, 0);
  if (p == MAP_FAILED) throw std::runtime_error("mmap failed");
  return new (p) Shared{};
}

void pin_process(int cpu) {
  cpu_set_t set;
  CPU_ZERO(&set);
  CPU_SET(cpu, &set);
  ::sched_setaffinity(0, sizeof(set), &set);
}

template <class F>
pid_t spawn(int cpu, F&& f) {
  const pid_t pid = ::fork();
  if (pid == 0) {
    pin_process(cpu);
    f();
    ::_exit(0);
  }
  return pid;
}

void wait_child(pid_t pid) { ::waitpid(pid, nullptr, 0); }

std::string unique(const char* what) {
  static int n = 0;
  return fmt::format("bench.shm.{}.{}.{}", what, ::getpid(), n++);
}

// The floor: a cache line to the other process and back.
std::vector<double> floor_rounds(std::uint64_t rounds, int cpu, const hb::TscClock& tsc) {
  Shared* s = map_shared();
  const pid_t child = spawn(cpu, [&] {
    for (std::uint64_t k = 1; k <= rounds; ++k) {
      while (s->ping.v.load(std::memory_order_acquire) != k) hb_relax();
      s->pong.v.store(k, std::memory_order_release);
    }
  });
  std::vector<double> out;
  out.reserve(rounds);
  for (std::uint64_t k = 1; k <= rounds; ++k) {
    const auto t0 = hb::TscClock::now();
    s->ping.v.store(k, std::memory_order_release);
    while (s->pong.v.load(std::memory_order_acquire) != k) hb_relax();
    out.push_back(tsc.to_ns(hb::TscClock::now() - t0) / 2.0);
  }
  wait_child(child);
  ::munmap(s, sizeof(Shared));
  return out;
}

// Ping-pong of M through two shared-memory topics; make(k) builds message k, seq(m) reads it back.
template <class M, class Make, class Seq>
std::vector<double> topic_rounds(std::uint64_t rounds, int cpu, const hb::TscClock& tsc, Make make, Seq seq) {
  const std::string ping = unique("ping"), pong = unique("pong");
  Shared* s = map_shared();
  horus::Topic<M> pong_sub(pong);
  horus::Topic<M> ping_pub(ping);
  const pid_t child = spawn(cpu, [&] {
    horus::Topic<M> ping_sub(ping);
    horus::Topic<M> pong_pub(pong);
    s->ready.v.store(1, std::memory_order_release);
    for (std::uint64_t k = 0; k < rounds;) {
      if (auto m = ping_sub.recv()) {
        pong_pub.send(*m);
        ++k;
      }
    }
  });
  while (s->ready.v.load(std::memory_order_acquire) == 0) hb_relax();
  std::vector<double> out;
  out.reserve(rounds);
  for (std::uint64_t k = 0; k < rounds; ++k) {
    const M msg = make(k);
    const auto t0 = hb::TscClock::now();
    ping_pub.send(msg);
    for (;;) {
      if (auto m = pong_sub.recv()) {
        if (seq(*m) == k) break;
      }
    }
    out.push_back(tsc.to_ns(hb::TscClock::now() - t0) / 2.0);
  }
  wait_child(child);
  ::munmap(s, sizeof(Shared));
  return out;
}

double throughput_cmdvel(std::uint64_t count, int cpu) {
  const std::string name = unique("tput");
  Shared* s = map_shared();
  horus::Topic<horus::msg::CmdVel> pub(name);
  const pid_t child = spawn(cpu, [&] {
    horus::Topic<horus::msg::CmdVel> sub(name);
    s->ready.v.store(1, std::memory_order_release);
    std::uint64_t got = 0;
    while (got < count)
      if (sub.recv()) ++got;
    s->done.v.store(1, std::memory_order_release);
  });
  while (s->ready.v.load(std::memory_order_acquire) == 0) hb_relax();
  auto msg = horus::msg::CmdVel::make(1.0f, 0.5f);
  const auto t0 = std::chrono::steady_clock::now();
  for (std::uint64_t i = 0; i < count; ++i) {
    msg.stamp_nanos = i;
    while (!pub.try_send(msg)) hb_relax();
  }
  while (s->done.v.load(std::memory_order_acquire) == 0) hb_relax();
  const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  wait_child(child);
  ::munmap(s, sizeof(Shared));
  return static_cast<double>(count) / secs;
}

double p50(std::vector<double> v) { return hb::percentiles(v).p50; }

}  // namespace

int main(int argc, char** argv) {
  std::uint64_t rounds = 100000;
  int blocks = 10;
  std::uint64_t image_rounds = 200;
  std::uint64_t tput = 2'000'000;
  std::vector<int> cpus{0, 1};
  bool quick = false;
  std::string json_path;
  CLI::App app{"horus cross-process latency (shared memory) with the floor measured in the same run"};
  app.add_option("--rounds", rounds, "round trips per kind (split into blocks)");
  app.add_option("--blocks", blocks, "interleaved blocks")->check(CLI::Range(1, 100));
  app.add_option("--image-rounds", image_rounds, "round trips of the 1920x1080 image");
  app.add_option("--throughput", tput, "messages for the throughput run");
  app.add_option("--cpus", cpus, "parent and child CPU")->expected(2);
  app.add_flag("--quick", quick, "a short smoke run");
  app.add_option("--json", json_path, "also write the rows as JSON");
  CLI11_PARSE(app, argc, argv);
  if (quick) {
    rounds = 4000;
    blocks = 2;
    image_rounds = 10;
    tput = 100000;
  }
  hb::pin_to_cpu(cpus[0]);
  const hb::TscClock tsc;
  const int child_cpu = cpus[1];
  const std::uint64_t per_block = std::max<std::uint64_t>(500, rounds / static_cast<std::uint64_t>(blocks));

  std::vector<double> floor_all, cmd_all, kb_all;
  std::vector<double> cmd_ratio, kb_ratio;
  for (int b = 0; b < blocks; ++b) {
    auto f = floor_rounds(per_block, child_cpu, tsc);
    auto c = topic_rounds<horus::msg::CmdVel>(
        per_block, child_cpu, tsc,
        [](std::uint64_t k) {
          auto m = horus::msg::CmdVel::make(1.0f, 0.5f);
          m.stamp_nanos = k;
          return m;
        },
        [](const horus::msg::CmdVel& m) { return m.stamp_nanos; });
    auto k = topic_rounds<bench_msg::Kilobyte>(
        per_block, child_cpu, tsc,
        [](std::uint64_t i) {
          bench_msg::Kilobyte m;
          m.seq = i;
          return m;
        },
        [](const bench_msg::Kilobyte& m) { return m.seq; });
    const double fb = p50(f);
    cmd_ratio.push_back(p50(c) / fb);
    kb_ratio.push_back(p50(k) / fb);
    floor_all.insert(floor_all.end(), f.begin(), f.end());
    cmd_all.insert(cmd_all.end(), c.begin(), c.end());
    kb_all.insert(kb_all.end(), k.begin(), k.end());
  }
  const horus::msg::Image frame(1080, 1920, horus::msg::ImageEncoding::Rgb8);
  auto img = topic_rounds<horus::msg::Image>(
      image_rounds, child_cpu, tsc,
      [&](std::uint64_t k) {
        horus::msg::Image m = frame;
        m.set_timestamp_ns(k);
        return m;
      },
      [](const horus::msg::Image& m) { return m.timestamp_ns(); });
  const double rate = throughput_cmdvel(tput, child_cpu);

  auto median = [](std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v[v.size() / 2];
  };
  const auto pf = hb::percentiles(floor_all), pc = hb::percentiles(cmd_all), pk = hb::percentiles(kb_all),
             pi = hb::percentiles(img);
  fmt::print("horus cross-process latency, shared memory (CPUs {} and {}, {} round trips in {} blocks)\n\n", cpus[0],
             cpus[1], per_block * static_cast<std::uint64_t>(blocks), blocks);
  fmt::print("{:<44} {:>10} {:>10} {:>10} {:>10}\n", "one-way (RTT/2)", "p50 ns", "p99 ns", "p99.9 ns", "p50/floor*");
  fmt::print("{:<44} {:>10.1f} {:>10.1f} {:>10.1f} {:>10}\n", "floor: cache-line ping-pong between processes", pf.p50,
             pf.p99, pf.p999, "1.00x");
  fmt::print("{:<44} {:>10.1f} {:>10.1f} {:>10.1f} {:>9.2f}x\n", "horus Topic<CmdVel> (16 B)", pc.p50, pc.p99, pc.p999,
             median(cmd_ratio));
  fmt::print("{:<44} {:>10.1f} {:>10.1f} {:>10.1f} {:>9.2f}x\n", "horus 1 KiB message", pk.p50, pk.p99, pk.p999,
             median(kb_ratio));
  fmt::print("{:<44} {:>10.0f} {:>10.0f} {:>10.0f} {:>10}\n", "horus Image 1920x1080 RGB (serialized today)",
             pi.p50, pi.p99, pi.p999, "");
  fmt::print("\nthroughput, lossless: {:.1f} M CmdVel/s\n", rate / 1e6);
  fmt::print("* median over {} blocks of (p50 / floor p50 of the same block)\n", blocks);
  fmt::print("targets: CmdVel p50 <= 1.5x floor ({}), p99 <= 3x floor p99 ({}); throughput >= 20 M/s ({})\n",
             median(cmd_ratio) <= 1.5 ? "met" : "missed", pc.p99 <= 3.0 * pf.p99 ? "met" : "missed",
             rate >= 20e6 ? "met" : "missed");
  if (!json_path.empty()) {
    std::ofstream out(json_path);
    out << fmt::format(
        "{{\"floor\":{{\"p50\":{},\"p99\":{},\"p999\":{}}},\"cmdvel\":{{\"p50\":{},\"p99\":{},\"p999\":{},\"ratio\":{}}},"
        "\"kib\":{{\"p50\":{},\"p99\":{},\"p999\":{},\"ratio\":{}}},\"image\":{{\"p50\":{},\"p99\":{}}},"
        "\"throughput_msgs_per_s\":{}}}\n",
        pf.p50, pf.p99, pf.p999, pc.p50, pc.p99, pc.p999, median(cmd_ratio), pk.p50, pk.p99, pk.p999,
        median(kb_ratio), pi.p50, pi.p99, rate);
  }
  return 0;
}
