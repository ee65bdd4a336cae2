// horus bench local (bench_cmd.hpp): on this machine, the true floor (horus/detail/cache_floor.hpp)
// on the first two allowed CPUs, then in-process and cross-process round trips (a pong thread, or
// a pong child process) measured by the ping of bench_ping.cpp, each row beside the floor.
#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <sched.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdint>
#include <cstdio>
#include <memory>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "bench_cmd.hpp"
#include "bench_cmd_internal.hpp"
#include "bench_peer.hpp"
#include "bench_stats.hpp"
#include "horus/detail/cache_floor.hpp"

extern char** environ;

namespace horus::tools::bench_detail {

namespace {

using Clock = std::chrono::steady_clock;

struct FloorResult {
  std::uint64_t one_line = 0, two_lines = 0;
  std::uint64_t best() const { return std::min(one_line, two_lines); }
};

// The true floor between cpu_a and cpu_b: p50 of the one-way hand-over, both bounces.
FloorResult measure_floor(int cpu_a, int cpu_b, std::uint64_t n) {
  FloorResult out;
  auto lines = std::make_unique<bench::FloorLines>();
  for (auto mode : {bench::FloorMode::OneLine, bench::FloorMode::TwoLines}) {
    lines->reset();
    std::thread echo([&] {
      pin_to_cpu(cpu_b);
      bench::floor_echo(*lines, mode, n);
    });
    pin_to_cpu(cpu_a);
    LatencyHistogram h;
    for (std::uint64_t i = 0; i < n; ++i) {
      const auto t = bench_now_ns();
      bench::floor_ping(*lines, mode, i);
      h.add(static_cast<std::uint64_t>((bench_now_ns() - t) / 2));
    }
    echo.join();
    (mode == bench::FloorMode::OneLine ? out.one_line : out.two_lines) = h.quantile(0.5);
  }
  return out;
}

std::vector<int> allowed_cpus() {
  cpu_set_t set;
  std::vector<int> cpus;
  if (::sched_getaffinity(0, sizeof set, &set) == 0)
    for (int i = 0; i < CPU_SETSIZE; ++i)
      if (CPU_ISSET(i, &set)) cpus.push_back(i);
  return cpus;
}

// The floor's lines (measured when two CPUs are allowed) and the table's header.
FloorResult print_floor(std::FILE* out, bool pinned, int cpu_a, int cpu_b) {
  FloorResult floor;
  if (pinned) {
    floor = measure_floor(cpu_a, cpu_b, 200'000);
    fmt::print(out, "true floor (cache-line ping-pong with pause, p50 one-way): one line {}, two lines 256 B apart {} -> "
               "floor {}\n",
               format_ns(static_cast<double>(floor.one_line)), format_ns(static_cast<double>(floor.two_lines)),
               format_ns(static_cast<double>(floor.best())));
  } else {
    fmt::print(out, "true floor: not measured (it needs two CPUs; this process may use one)\n");
  }
  fmt::print(out, "{:<26} {:>10} {:>10} {:>10} {:>10} {:>14} {:>9}\n", "path", "p50", "p99", "p99.9", "max", "msg/s",
             "vs floor");
  std::fflush(out);
  return floor;
}

struct Row {
  const char* name;
  bool cross_process, spin, flood;
};

// The pong of a cross-process row: this program, `horus bench pong --once`, on cpu_b; -1 when it
// cannot start.
pid_t spawn_pong(const Row& row, const BenchArgs& r, int cpu_b) {
  pid_t child = -1;
  std::vector<std::string> cargs = {"/proc/self/exe", "bench", "pong", "--once", "--quiet", "--backend", "shm",
                                    "--topic-prefix", r.prefix, "--cpu", std::to_string(cpu_b)};
  if (row.spin) cargs.emplace_back("--spin");
  std::vector<char*> argv;
  for (auto& s : cargs) argv.push_back(s.data());
  argv.push_back(nullptr);
  if (::posix_spawn(&child, "/proc/self/exe", nullptr, nullptr, argv.data(), environ) != 0) child = -1;
  return child;
}

// Waits up to 5 s for the pong child to exit, then kills it.
void reap_pong(pid_t child) {
  int status = 0;
  const auto deadline = Clock::now() + std::chrono::seconds(5);
  while (::waitpid(child, &status, WNOHANG) == 0) {
    if (Clock::now() > deadline) {
      ::kill(child, SIGKILL);
      ::waitpid(child, &status, 0);
      break;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
}

// One row: its pong (a thread, or a child process), the ping on cpu_a, then the pong's end.
PingResult run_row(const BenchArgs& a, const Row& row, std::ptrdiff_t index, int cpu_a, int cpu_b,
                   const std::vector<int>& cpus, const std::atomic<bool>& stop) {
  BenchArgs r = a;
  r.spin = row.spin;
  r.prefix = fmt::format("{}.{}", a.prefix, index);
  r.flood = true;                // as fast as the echoes come back:
  if (!row.flood) r.window = 1;  // latency rows keep one message in flight
  std::atomic<bool> pong_stop{false}, pong_ready{false};
  std::thread pong_thread;
  pid_t child = -1;
  std::optional<Backend> backend = row.cross_process ? Backend::SharedMemory : Backend::InProcess;
  if (!row.cross_process) {
    BenchArgs p = r;
    p.cpu = cpu_b;
    pong_thread = std::thread([p, backend, &pong_stop, &pong_ready] { (void)run_pong(p, backend, pong_stop, &pong_ready); });
    while (!pong_ready.load() && !stop.load()) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  } else {
    child = spawn_pong(row, r, cpu_b);
  }
  pin_to_cpu(cpu_a);
  auto res = run_ping(r, backend, stop);
  // Back on every allowed CPU between rows.
  cpu_set_t set;
  CPU_ZERO(&set);
  for (int c : cpus) CPU_SET(c, &set);
  (void)::sched_setaffinity(0, sizeof set, &set);
  if (pong_thread.joinable()) {
    pong_stop.store(true);
    pong_thread.join();
  }
  if (child > 0) reap_pong(child);
  return res;
}

// A row's line of the table, and its JSON.
nlohmann::json print_row(std::FILE* out, const Row& row, const PingResult& res, const FloorResult& floor) {
  const auto& h = res.one_way;
  const double ratio = floor.best() && !row.flood ? static_cast<double>(h.quantile(0.5)) / static_cast<double>(floor.best()) : 0;
  fmt::print(out, "{:<26} {:>10} {:>10} {:>10} {:>10} {:>14.0f} {:>9}\n", row.name,
             format_ns(static_cast<double>(h.quantile(0.5))), format_ns(static_cast<double>(h.quantile(0.99))),
             format_ns(static_cast<double>(h.quantile(0.999))), format_ns(static_cast<double>(h.max())),
             msgs_per_s(res), ratio > 0 ? fmt::format("{:.2f}x", ratio) : std::string("-"));
  std::fflush(out);
  return {{"path", row.name},
          {"type", res.type},
          {"message_bytes", res.message_bytes},
          {"window", res.window},
          {"sent", res.sent},
          {"received", res.received},
          {"lost", res.lost},
          {"one_way_ns", {{"p50", h.quantile(0.5)}, {"p99", h.quantile(0.99)}, {"p99_9", h.quantile(0.999)}, {"max", h.max()}}},
          {"msgs_per_s", msgs_per_s(res)},
          {"vs_floor", ratio}};
}

}  // namespace

}  // namespace horus::tools::bench_detail

namespace horus::tools {

int cmd_bench_local(const BenchArgs& args, const std::atomic<bool>& stop) {
  using namespace bench_detail;  // the ping, the pong and the checks (bench_cmd_internal.hpp)
  BenchArgs a = args;
  if (!check_args(a, "local")) return 2;
  if (a.duration > 60) a.duration = 60;
  const auto cpus = allowed_cpus();
  const int cpu_a = cpus.empty() ? -1 : cpus[0];
  const int cpu_b = cpus.size() >= 2 ? cpus[1] : -1;
  const bool pinned = cpu_b >= 0;
  std::FILE* out = a.json == "-" ? stderr : stdout;  // the JSON alone on stdout
  a.prefix = fmt::format("{}.local_{}", a.prefix, ::getpid());
  a.quiet = true;
  a.warmup = 0.3;     // traffic before measuring
  a.handshake = 10;   // a child process starting on a loaded machine

  fmt::print(out, "horus bench local on {}: {} CPU(s) allowed{}\n", host_name(), cpus.size(),
             pinned ? fmt::format(", ping on CPU {}, pong on CPU {}", cpu_a, cpu_b) : std::string(" (not pinned: one CPU)"));
  std::fflush(out);
  const FloorResult floor = print_floor(out, pinned, cpu_a, cpu_b);

  const Row rows[] = {{"in-process, spinning", false, true, false},   {"in-process, blocking", false, false, false},
                      {"in-process, flood", false, false, true},       {"cross-process, spinning", true, true, false},
                      {"cross-process, blocking", true, false, false}, {"cross-process, flood", true, false, true}};
  int rc = 0;
  nlohmann::json json_rows = nlohmann::json::array();
  for (const auto& row : rows) {
    if (stop.load()) break;
    if (row.spin && !pinned) continue;  // two spinning threads on one CPU measure the scheduler
    const auto res = run_row(a, row, &row - rows, cpu_a, cpu_b, cpus, stop);
    if (!res.ok) {
      fmt::print(stderr, "horus bench local: {}: {}\n", row.name, res.error);
      rc = 1;
      continue;
    }
    json_rows.push_back(print_row(out, row, res, floor));
  }
  fmt::print(out, "one-way = round trip / 2 through two topics; spinning: recv() in a loop with pause (as the floor); "
             "blocking: recv_for (a futex wake-up each way); flood: {} in flight\n",
             a.window != 0 ? std::to_string(a.window) : std::string("half the ring"));
  if (!a.json.empty()) {
    std::string error;
    const nlohmann::json j = {{"tool", "horus bench local"},
                              {"host", host_name()},
                              {"cpus", pinned ? nlohmann::json::array({cpu_a, cpu_b}) : nlohmann::json::array()},
                              {"floor_ns", {{"one_line", floor.one_line}, {"two_lines", floor.two_lines}, {"best", floor.best()}}},
                              {"rows", json_rows}};
    if (!write_text(a.json, j.dump(2) + "\n", false, error)) {
      fmt::print(stderr, "horus bench local: {}\n", error);
      rc = 1;
    }
  }
  return rc;
}

}  // namespace horus::tools
