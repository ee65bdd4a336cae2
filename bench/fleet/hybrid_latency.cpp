// horus-fleet-hybrid: the hybrid promise of a fleet topic, measured as a user meets it. One
// publisher process sends Pose2D at a fixed rate on a fleet topic and, in the same tick, on a
// host topic; subscriber processes block in recv_for: a host-topic subscriber and a fleet-topic
// subscriber on the publisher's host, a fleet-topic subscriber on another host. Whichever process
// opened the fleet topic first holds the host's bridge: the publisher, the local subscriber, or a
// third process that only holds it (`hold`). bench/fleet/hybrid.sh starts them in that order on
// two namespace hosts and prints the table. Every message carries its send time on
// CLOCK_MONOTONIC (namespaces of one machine share it): each subscriber prints the one-way latency
// p50/p99/p99.9 of what it received.
//
//   horus-fleet-hybrid pub  --fleet T --host H [--count 1500] [--hz 1000] [--warmup 2] --go FILE
//   horus-fleet-hybrid sub  --topic T [--fleet] [--count 1500] [--label L]
//   horus-fleet-hybrid hold --topic T [--seconds 60]
// Each process prints `ready bridge=0|1` once its topic is open (bridge: it holds the host's
// bridge of the fleet topic). The publisher waits for FILE to exist before it sends: warmup
// messages first (x < 0: not counted; discovery and matching settle), then --count messages.
// A subscriber prints `LABEL p50_us p99_us p999_us received bridge=0|1 csw=N` and exits after
// --count messages or 5 s without one; the publisher ends with `sent N bridge=0|1 csw=N` (csw: the
// process's context switches, every thread's: what its wake-ups cost). The transport is HORUS_BACKEND's (cyclonedds, fastdds or lcm).
#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include <sys/resource.h>
#include <time.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <thread>
#include <vector>

#include "bench_common.hpp"
#include "horus/horus.hpp"

namespace hb = horus::bench;
using horus::msg::Pose2D;
using namespace std::chrono_literals;

namespace {

std::uint64_t mono_ns() {
  timespec ts{};
  ::clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<std::uint64_t>(ts.tv_sec) * 1'000'000'000ULL + static_cast<std::uint64_t>(ts.tv_nsec);
}

// Backend keeps a view of the transport's name: a string that lives as long as the process.
const std::string& transport() {
  static const std::string name = [] {
    const char* b = std::getenv("HORUS_BACKEND");
    return std::string(b != nullptr && *b != '\0' ? b : "cyclonedds");
  }();
  return name;
}

horus::TopicOptions options(bool fleet) {
  horus::TopicOptions o;
  o.backend = fleet ? horus::Backend::network(transport()) : horus::Backend::SharedMemory;
  o.capacity = 1024;
  return o;
}

// The process's context switches so far (every thread's, voluntary and not): what its wake-ups cost.
long context_switches() {
  rusage u{};
  ::getrusage(RUSAGE_SELF, &u);
  return u.ru_nvcsw + u.ru_nivcsw;
}

void ready(const horus::Topic<Pose2D>& t) {
  fmt::print("ready bridge={}\n", t.is_bridge() ? 1 : 0);
  std::fflush(stdout);
}

int run_pub(const std::string& fleet_name, const std::string& host_name, int count, double hz, double warmup_s,
            const std::string& go) {
  auto fleet = horus::Topic<Pose2D>::open(fleet_name, options(true));
  auto host = horus::Topic<Pose2D>::open(host_name, options(false));
  if (!fleet || !host) {
    fmt::print(stderr, "horus-fleet-hybrid pub: {}\n", (!fleet ? fleet.error() : host.error()).message());
    return 1;
  }
  ready(*fleet);
  const auto until_go = std::chrono::steady_clock::now() + 60s;
  while (::access(go.c_str(), F_OK) != 0) {
    if (std::chrono::steady_clock::now() > until_go) {
      fmt::print(stderr, "horus-fleet-hybrid pub: {} did not appear within 60 s\n", go);
      return 1;
    }
    std::this_thread::sleep_for(5ms);
  }
  const auto period = std::chrono::nanoseconds(static_cast<std::int64_t>(1e9 / hz));
  const int warmup = static_cast<int>(warmup_s * hz);
  // The host topic's message half a period after the fleet topic's: each topic at `hz`, neither
  // send (nor a wake-up it causes) on top of the other's.
  auto next = std::chrono::steady_clock::now();
  for (int i = -warmup; i < count; ++i) {
    next += period;
    std::this_thread::sleep_until(next);
    fleet->send(Pose2D{static_cast<double>(i), 0.0, 0.0, mono_ns()});
    std::this_thread::sleep_until(next + period / 2);
    host->send(Pose2D{static_cast<double>(i), 0.0, 0.0, mono_ns()});
  }
  // The last messages reach the network before the bridge (if this process holds it) closes.
  std::this_thread::sleep_for(500ms);
  fmt::print("sent {} bridge={} csw={}\n", count, fleet->is_bridge() ? 1 : 0, context_switches());
  return 0;
}

int run_sub(const std::string& name, bool fleet_scope, int count, const std::string& label) {
  auto t = horus::Topic<Pose2D>::open(name, options(fleet_scope));
  if (!t) {
    fmt::print(stderr, "horus-fleet-hybrid sub: {}\n", t.error().message());
    return 1;
  }
  ready(*t);
  std::vector<double> us;
  us.reserve(static_cast<std::size_t>(count));
  bool started = false;
  const auto first_deadline = std::chrono::steady_clock::now() + 90s;
  while (static_cast<int>(us.size()) < count) {
    auto m = t->recv_for(started ? 5s : 1s);
    const std::uint64_t now = mono_ns();
    if (!m) {
      if (started || std::chrono::steady_clock::now() > first_deadline) break;
      continue;
    }
    started = true;
    if (m->x < 0) continue;  // warmup
    us.push_back(static_cast<double>(now - m->timestamp_ns) / 1e3);
  }
  const bool bridge = t->is_bridge();
  const auto n = us.size();
  if (n == 0) {
    fmt::print("{} - - - 0 bridge={}\n", label, bridge ? 1 : 0);
    return 0;
  }
  const auto p = hb::percentiles(us);
  fmt::print("{} {:.1f} {:.1f} {:.1f} {} bridge={} csw={}\n", label, p.p50, p.p99, p.p999, n, bridge ? 1 : 0,
             context_switches());
  return 0;
}

int run_hold(const std::string& name, double seconds) {
  auto t = horus::Topic<Pose2D>::open(name, options(true));
  if (!t) {
    fmt::print(stderr, "horus-fleet-hybrid hold: {}\n", t.error().message());
    return 1;
  }
  ready(*t);
  // Holds the bridge; receives nothing (its handle's entry drops what it does not read).
  std::this_thread::sleep_for(std::chrono::duration<double>(seconds));
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"horus-fleet-hybrid: a fleet topic's local and remote latency against a host topic"};
  app.require_subcommand(1);
  std::string fleet_name, host_name, go, topic, label = "sub";
  int count = 1500;
  double hz = 1000, warmup = 2, seconds = 60;
  bool fleet = false;
  auto* pub = app.add_subcommand("pub", "publish on the fleet and the host topic");
  pub->add_option("--fleet", fleet_name)->required();
  pub->add_option("--host", host_name)->required();
  pub->add_option("--count", count);
  pub->add_option("--hz", hz)->check(CLI::Range(1.0, 100000.0));
  pub->add_option("--warmup", warmup);
  pub->add_option("--go", go)->required();
  auto* sub = app.add_subcommand("sub", "receive in recv_for and print the latency");
  sub->add_option("--topic", topic)->required();
  sub->add_flag("--fleet", fleet);
  sub->add_option("--count", count);
  sub->add_option("--label", label);
  auto* hold = app.add_subcommand("hold", "open the fleet topic (first: hold the bridge) and wait");
  hold->add_option("--topic", topic)->required();
  hold->add_option("--seconds", seconds);
  CLI11_PARSE(app, argc, argv);
  if (*pub) return run_pub(fleet_name, host_name, count, hz, warmup, go);
  if (*sub) return run_sub(topic, fleet, count, label);
  return run_hold(topic, seconds);
}
