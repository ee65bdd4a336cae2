// horus-fleet-local: what a fleet topic costs its local users, against a host topic measured in
// the same run (interleaved rounds; the machine is shared and noisy).
//
//   * send(): the time of one send() of a CmdVel, with a subscriber in this process that
//     polls, for a host topic, a host topic whose subscriber sleeps in recv_for (each send
//     then wakes it), and a fleet topic (its bridge's thread sleeps on the doorbell and exports
//     every message, here with no remote reader);
//   * local latency: CmdVel ping-pong between two processes (one-way = RTT/2) on a host topic
//     and on a fleet topic (the bridge exports both directions meanwhile).
// p50/p99/p99.9 per round and the fleet/host ratio of the p50s. The transport (default
// cyclonedds) stays on this machine: DDS loopback only (HORUS_DDS_LOCALHOST=1), LCM ttl=0.
//
//   horus-fleet-local [--transport cyclonedds|fastdds|lcm] [--rounds 5] [--n 20000] [--quick]
#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cstdlib>
#include <string>
#include <thread>
#include <vector>

#include "bench_common.hpp"
#include "horus/horus.hpp"

extern char** environ;

namespace hb = horus::bench;
using horus::msg::CmdVel;
using namespace std::chrono_literals;

namespace {

horus::TopicOptions options_for(bool fleet, const std::string& transport) {
  horus::TopicOptions o;
  o.backend = fleet ? horus::Backend::network(transport) : horus::Backend::SharedMemory;
  return o;
}

// One round of send() timings on topic `name`; the subscriber polls or sleeps in recv_for.
std::vector<double> send_round(const hb::TscClock& tsc, const std::string& name, const horus::TopicOptions& o,
                               bool blocked_subscriber, int n) {
  auto pub = horus::Topic<CmdVel>::open(name, o).value();
  auto sub = horus::Topic<CmdVel>::open(name, o).value();
  std::atomic<bool> stop{false};
  std::atomic<std::uint64_t> got{0};
  std::thread receiver([&] {
    while (!stop.load(std::memory_order_relaxed)) {
      if (blocked_subscriber) {
        if (sub.recv_for(20ms)) got.fetch_add(1, std::memory_order_relaxed);
      } else if (sub.recv()) {
        got.fetch_add(1, std::memory_order_relaxed);
      } else {
        horus::shm::cpu_relax();
      }
    }
  });
  std::vector<double> ns;
  ns.reserve(static_cast<std::size_t>(n));
  const CmdVel m = CmdVel::make(1.0f, 0.5f);
  for (int i = 0; i < n; ++i) {
    const auto t0 = hb::TscClock::now();
    pub.send(m);
    const auto t1 = hb::TscClock::now();
    ns.push_back(tsc.to_ns(static_cast<double>(t1 - t0)));
    // A message every ~2 us: the subscriber (and the bridge) keep up, each send is a fresh one.
    const auto until = hb::TscClock::now() + static_cast<std::uint64_t>(2000.0 / tsc.to_ns(1.0));
    while (hb::TscClock::now() < until) horus::shm::cpu_relax();
  }
  stop = true;
  receiver.join();
  return ns;
}

// The echoing side of the ping-pong (another process): pong every ping until `n` were echoed.
int run_echo(const std::string& ping, const std::string& pong, bool fleet, const std::string& transport, int n) {
  const auto o = options_for(fleet, transport);
  auto in = horus::Topic<CmdVel>::open(ping, o);
  auto out = horus::Topic<CmdVel>::open(pong, o);
  if (!in || !out) return 3;
  std::printf("ready\n");
  std::fflush(stdout);
  for (int i = 0; i < n;) {
    if (auto m = in->recv()) {
      out->send(*m);
      ++i;
    } else {
      horus::shm::cpu_relax();
    }
  }
  std::this_thread::sleep_for(100ms);  // let the last pong out before the topic closes
  return 0;
}

// One ping-pong round against a spawned echo process; one-way latencies in ns.
std::vector<double> pingpong_round(const hb::TscClock& tsc, const char* self, int round, bool fleet,
                                   const std::string& transport, int n) {
  const std::string base = fmt::format("bench.fleetlocal.{}.{}.{}", ::getpid(), round, fleet ? "fleet" : "host");
  const auto o = options_for(fleet, transport);
  auto ping = horus::Topic<CmdVel>::open(base + ".ping", o).value();
  auto pong = horus::Topic<CmdVel>::open(base + ".pong", o).value();
  const int warmup = 200;
  std::vector<std::string> args = {self, "--echo", base + ".ping", base + ".pong", fleet ? "1" : "0", transport,
                                   std::to_string(n + warmup)};
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  pid_t child = -1;
  if (::posix_spawn(&child, self, nullptr, nullptr, argv.data(), environ) != 0) return {};
  std::vector<double> ns;
  ns.reserve(static_cast<std::size_t>(n));
  CmdVel m = CmdVel::make(0.0f, 0.0f);
  // Until the echo process has both topics open (its subscription exists), ping slowly.
  const auto give_up = std::chrono::steady_clock::now() + 20s;
  while (pong.sub_count() < 1 || ping.sub_count() < 2) {
    if (std::chrono::steady_clock::now() > give_up) break;
    std::this_thread::sleep_for(1ms);
  }
  for (int i = 0; i < n + warmup; ++i) {
    const auto t0 = hb::TscClock::now();
    ping.send(m);
    std::optional<CmdVel> r;
    while (!(r = pong.recv())) horus::shm::cpu_relax();
    const auto t1 = hb::TscClock::now();
    if (i >= warmup) ns.push_back(tsc.to_ns(static_cast<double>(t1 - t0)) / 2.0);
  }
  int status = 0;
  ::waitpid(child, &status, 0);
  return ns;
}

void print_row(const char* what, int round, hb::Percentiles p) {
  fmt::print("  {:<34} round {}  p50 {:>8.1f}  p99 {:>8.1f}  p99.9 {:>8.1f} ns\n", what, round, p.p50, p.p99, p.p999);
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0.0 : v[v.size() / 2];
}

}  // namespace

int main(int argc, char** argv) {
  if (argc >= 2 && std::string_view(argv[1]) == "--echo" && argc == 7)
    return run_echo(argv[2], argv[3], std::string_view(argv[4]) == "1", argv[5], std::atoi(argv[6]));
  CLI::App app{"horus-fleet-local: a fleet topic's local cost against a host topic"};
  std::string transport = "cyclonedds";
  int rounds = 5;
  int n = 20000;
  bool quick = false;
  app.add_option("--transport", transport, "cyclonedds, fastdds or lcm");
  app.add_option("--rounds", rounds, "interleaved rounds")->check(CLI::Range(1, 100));
  app.add_option("--n", n, "messages per round")->check(CLI::Range(100, 10'000'000));
  app.add_flag("--quick", quick, "1 round of 2000 (a smoke test)");
  CLI11_PARSE(app, argc, argv);
  if (quick) {
    rounds = 1;
    n = 2000;
  }
  if (!horus::backend_available(horus::Backend::network(transport))) {
    fmt::print("this build has no {} backend\n", transport);
    return 1;
  }
  // On this machine only: DDS on loopback, a domain and an LCM port of this run, ttl=0.
  ::setenv("HORUS_DDS_LOCALHOST", "1", 1);
  ::setenv("HORUS_DOMAIN_ID", std::to_string(1 + ::getpid() % 200).c_str(), 1);
  ::setenv("HORUS_LCM_URL", fmt::format("udpm://239.255.76.67:{}?ttl=0", 20000 + ::getpid() % 20000).c_str(), 1);
  ::unsetenv("HORUS_BACKEND");
  ::unsetenv("HORUS_CONFIG");
  const hb::TscClock tsc;
  fmt::print("fleet topic ({}) vs host topic, CmdVel, {} rounds of {}\n", transport, rounds, n);

  fmt::print("send(): one call, a subscriber in this process\n");
  std::vector<double> ratio_polled, ratio_blocked;
  for (int r = 0; r < rounds; ++r) {
    const std::string base = fmt::format("bench.fleetsend.{}.{}", ::getpid(), r);
    auto host = send_round(tsc, base + ".host", options_for(false, transport), false, n);
    auto host_b = send_round(tsc, base + ".hostb", options_for(false, transport), true, n);
    auto fleet = send_round(tsc, base + ".fleet", options_for(true, transport), false, n);
    const auto ph = hb::percentiles(host), pb = hb::percentiles(host_b), pf = hb::percentiles(fleet);
    print_row("host, subscriber polls", r, ph);
    print_row("host, subscriber in recv_for", r, pb);
    print_row("fleet, subscriber polls", r, pf);
    ratio_polled.push_back(pf.p50 / ph.p50);
    ratio_blocked.push_back(pf.p50 / pb.p50);
  }
  fmt::print("send() p50 fleet/host: {:.2f}x against a polling subscriber (rounds {:.2f}-{:.2f}), {:.2f}x against a "
             "subscriber in recv_for\n",
             median(ratio_polled), *std::min_element(ratio_polled.begin(), ratio_polled.end()),
             *std::max_element(ratio_polled.begin(), ratio_polled.end()), median(ratio_blocked));

  fmt::print("local latency: ping-pong between two processes, one-way\n");
  std::vector<double> ratio_pp;
  for (int r = 0; r < rounds; ++r) {
    auto host = pingpong_round(tsc, argv[0], r, false, transport, n / 4);
    auto fleet = pingpong_round(tsc, argv[0], r, true, transport, n / 4);
    if (host.empty() || fleet.empty()) {
      fmt::print("the echo process did not start\n");
      return 1;
    }
    const auto ph = hb::percentiles(host), pf = hb::percentiles(fleet);
    print_row("host topic", r, ph);
    print_row("fleet topic", r, pf);
    ratio_pp.push_back(pf.p50 / ph.p50);
  }
  fmt::print("local latency p50 fleet/host: {:.2f}x (rounds {:.2f}-{:.2f})\n", median(ratio_pp),
             *std::min_element(ratio_pp.begin(), ratio_pp.end()), *std::max_element(ratio_pp.begin(), ratio_pp.end()));
  return 0;
}
