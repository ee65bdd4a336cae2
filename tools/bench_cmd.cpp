// horus bench: round trips through ordinary horus topics (bench_cmd.hpp). This file: the
// choices, the control topic, the argument checks and the pong side; the ping side is in
// bench_ping.cpp, `horus bench local` in bench_local.cpp (bench_cmd_internal.hpp joins them).
//
// The handshake, on PREFIX.control (GenericMessage, a MessagePack map of strings):
//   ping -> hello {run, type, size, ping, pong, host, pid}    every 250 ms until a pong is ready
//   pong -> ready {run, host, pid} | busy {run, host, pid, serving} | error {run, host, pid, what}
//   ping -> start {run, host, pid, stamps}                    the pong it measures with (stamps=1: note echo times)
//   pong -> stamps {run, t0, d, last}                         echo times, every 50 ms (bench_cmd_internal.hpp)
//   ping -> flush {run}                                       after the drain: the echo times left, last=1
//   ping -> bye {run}                                         the run is over (repeated until closed, 2 s at most)
//   pong -> closed {run, host, pid}                           the session is closed (to each bye of a run it served)
// A pong opens PREFIX.ping.TYPE and PREFIX.pong.TYPE for a hello's type and echoes what arrives
// on the first into the second, unchanged, until bye, a start naming another pong, or 10 s
// without traffic. The ping tags each message with its sequence number (bench_peer.hpp), keeps
// its send time, and takes one-way latency as half the round trip: one clock, no clock sync.
// On fleet topics it also prints each way apart (one-way by clock): the pong notes when it echoed
// a message on its host's clock, and the ping corrects that by the clock offset the fleet's
// heartbeats measured (horus::Fleet), or by none with --clocks-synced.
#include "bench_cmd.hpp"

#include <fmt/format.h>

#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <deque>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "bench_cmd_internal.hpp"
#include "bench_peer.hpp"
#include "horus/config.hpp"
#include "horus/detail/cache_floor.hpp"
#include "horus/fleet.hpp"
#include "horus/names.hpp"
#include "horus/transport_registry.hpp"
#ifdef HORUS_CLI_HAVE_LCM
#include "horus/lcm/transport.hpp"
#endif

namespace horus::tools::bench_detail {

std::string host_name() { return fleet::host_name(); }
std::string host_id() { return fmt::format("{:016x}", fleet::host_id()); }

void pin_to_cpu(int cpu) {
  if (cpu >= 0) (void)bench::pin_to_cpu(cpu);
}

// -- choices ----------------------------------------------------------------------------------

namespace {

Result<std::optional<Backend>> parse_backend(const std::string& name) {
  if (name.empty()) return std::optional<Backend>();
  if (name == "inproc") return std::optional<Backend>(Backend::InProcess);
  if (name == "shm") return std::optional<Backend>(Backend::SharedMemory);
  if (const auto* t = net::find_transport(name)) return std::optional<Backend>(Backend::network(t->name));
  std::string known = "inproc, shm";
  for (const auto& n : net::transport_names()) known += ", " + n;
  return fail(Errc::Config, fmt::format("--backend '{}' is not a backend of this build; expected one of: {}", name, known));
}

std::string short_type(const std::string& qualified) {
  const auto p = qualified.rfind("::");
  return p == std::string::npos ? qualified : qualified.substr(p + 2);
}

}  // namespace

std::string data_topic(const std::string& prefix, const char* side, const std::string& qualified, std::uint64_t size) {
  return fmt::format("{}.{}.{}{}", prefix, side, short_type(qualified), size ? fmt::format("_{}", size) : "");
}

std::string where_text(const Backend& b) {
  if (b.scope() == Scope::Process) return "process (in-process ring)";
  if (b.scope() == Scope::Host) return "host (shared memory)";
  const std::string t(b.transport());
#ifdef HORUS_CLI_HAVE_LCM
  if (t == "lcm") {
    auto c = net::config_from_environment();
    auto url = c ? lcm::url_from(*c) : Result<std::string>(std::unexpected(c.error()));
    return fmt::format("fleet (lcm, {})", url ? *url : url.error().message());
  }
#endif
  if (t == "cyclonedds" || t == "fastdds") {
    auto c = net::config_from_environment();
    if (!c) return fmt::format("fleet ({}, {})", t, c.error().message());
    return fmt::format("fleet ({}, domain {}{})", t, c->domain_id, c->localhost_only ? ", loopback only" : "");
  }
  return fmt::format("fleet ({})", t);
}

std::string choice_origin(const TopicChoice& c) {
  if (c.backend_from == Source::Code) return "--backend";
  if (c.backend_from == Source::Environment) return "HORUS_BACKEND";
  if (c.backend_from == Source::File && c.rule != nullptr)
    return fmt::format("{}, line {}: rule '{}'", c.config->file(), c.rule->line, c.rule->match);
  return "the default (no HORUS_BACKEND, no rule in HORUS_CONFIG)";
}

// -- the control topic ------------------------------------------------------------------------

std::string get(const Fields& f, const std::string& k) {
  auto it = f.find(k);
  return it == f.end() ? std::string() : it->second;
}

// -- echo times -------------------------------------------------------------------------------

std::int64_t clock_base() {
  std::int64_t best_gap = INT64_MAX, base = 0;
  for (int i = 0; i < 5; ++i) {
    const std::int64_t a = bench_now_ns();
    const std::int64_t u = fleet::host_clock_unix_ns();
    const std::int64_t b = bench_now_ns();
    if (b - a < best_gap) {
      best_gap = b - a;
      base = u - a - (b - a) / 2;
    }
  }
  return base;
}

void send_stamps(Control& control, const std::string& run, const std::vector<BenchPeer::EchoStamp>& stamps, bool last) {
  std::size_t i = 0;
  do {
    const std::int64_t first = i < stamps.size() ? stamps[i].at : 0;
    std::string d;
    for (; i < stamps.size() && d.size() < kStampsPerMessageBytes; ++i)
      d += fmt::format("{}{:x}:{:x}", d.empty() ? "" : ",", stamps[i].tag, stamps[i].at - first);
    if (d.empty() && !last) return;
    control.send({{"op", "stamps"}, {"run", run}, {"t0", std::to_string(first)}, {"d", d},
                  {"last", last && i == stamps.size() ? "1" : "0"}});
  } while (i < stamps.size());
}

std::optional<std::vector<BenchPeer::EchoStamp>> parse_stamps(const Fields& f) {
  const std::string t0 = get(f, "t0"), d = get(f, "d");
  char* end = nullptr;
  errno = 0;
  const long long first = std::strtoll(t0.c_str(), &end, 10);
  if (t0.empty() || *end != '\0' || errno != 0) return std::nullopt;
  std::vector<BenchPeer::EchoStamp> out;
  const char* p = d.c_str();
  while (*p != '\0') {
    const unsigned long long tag = std::strtoull(p, &end, 16);
    if (end == p || *end != ':') return std::nullopt;
    p = end + 1;
    const long long dt = std::strtoll(p, &end, 16);
    if (end == p || (*end != ',' && *end != '\0') || dt < 0) return std::nullopt;
    out.push_back({tag, first + dt});
    p = *end == ',' ? end + 1 : end;
  }
  return out;
}

// -- arguments --------------------------------------------------------------------------------

bool check_args(const BenchArgs& a, const char* cmd, std::optional<Backend>* backend) {
  std::string bad;
  if (a.rate <= 0 && !a.flood) bad = fmt::format("--rate {} must be above 0 (or use --flood)", a.rate);
  else if (a.duration <= 0 && a.count == 0) bad = fmt::format("--duration {} must be above 0", a.duration);
  else if (a.warmup < 0.1) bad = fmt::format("--warmup {} must be at least 0.1 s (the pong must answer within it)", a.warmup);
  else if (a.timeout <= 0) bad = fmt::format("--timeout {} must be above 0", a.timeout);
  else if (auto ok = validate_topic_name(a.prefix + ".control"); !ok)
    bad = fmt::format("--topic-prefix '{}': {}", a.prefix, ok.error().message());
  else if (backend != nullptr) {
    if (auto b = parse_backend(a.backend)) *backend = *b;
    else bad = b.error().message();
  }
  if (bad.empty()) return true;
  fmt::print(stderr, "horus bench {}: {}\n", cmd, bad);
  return false;
}

// -- pong -------------------------------------------------------------------------------------

namespace {

struct PongSession {
  std::string run, peer;  // the ping's "host (pid)"
  std::string ping_topic;
  std::unique_ptr<BenchPeer> peer_endpoint;
  std::atomic<bool> stop{false};
  std::atomic<std::uint64_t> echoed{0};
  std::atomic<std::int64_t> last_ns{0};
  // The echo times the ping asked for (start with stamps=1), at most one per kStampEveryNs,
  // sent on the control topic every kStampFlushNs.
  std::atomic<bool> stamps{false};
  std::mutex stamp_mutex;
  std::vector<BenchPeer::EchoStamp> pending;
  std::int64_t clock_base = 0;  // clock_base(): this host's fleet clock minus bench_now_ns()
  std::int64_t last_flush = 0;
  std::thread thread;
};

constexpr std::int64_t kStampEveryNs = 1'000'000, kStampFlushNs = 50'000'000;
constexpr std::size_t kMaxPendingStamps = 4096;

void echo_loop(PongSession& s, bool spin, int cpu) {
  pin_to_cpu(cpu);
  std::int64_t last_stamp = 0;
  while (!s.stop.load(std::memory_order_relaxed)) {
    bool any = false;
    const bool stamps = s.stamps.load(std::memory_order_relaxed);
    BenchPeer::EchoStamp stamp;
    while (s.peer_endpoint->echo_one(stamps ? &stamp : nullptr)) {
      s.echoed.fetch_add(1, std::memory_order_relaxed);
      any = true;
      if (stamps && stamp.at - last_stamp >= kStampEveryNs) {
        last_stamp = stamp.at;
        std::lock_guard lock(s.stamp_mutex);
        if (s.pending.size() < kMaxPendingStamps) s.pending.push_back(stamp);
      }
    }
    if (any) s.last_ns.store(bench_now_ns(), std::memory_order_relaxed);
    if (spin) bench::spin_pause();
    else if (!any) (void)s.peer_endpoint->wait(std::chrono::milliseconds(50));
  }
}

constexpr std::int64_t kPongIdleNs = 10'000'000'000;

// Sends what the echo thread noted since the last flush (every kStampFlushNs, and at the end).
// `last`: the ping asked (flush), it waits for a message with last=1.
void flush_stamps(Control& control, PongSession& s, std::int64_t now, bool force, bool last = false) {
  if (!s.stamps.load() || (!force && now - s.last_flush < kStampFlushNs)) return;
  s.last_flush = now;
  std::vector<BenchPeer::EchoStamp> batch;
  {
    std::lock_guard lock(s.stamp_mutex);
    batch.swap(s.pending);
  }
  for (auto& b : batch) b.at += s.clock_base;
  send_stamps(control, s.run, batch, last);
}

// The pong's sessions, one per ping run it answers, and its answers on the control topic.
struct Pong {
  Pong(const BenchArgs& args, const std::optional<Backend>& b, Control& c) : a(args), backend(b), control(c) {}

  const BenchArgs& a;
  const std::optional<Backend>& backend;
  Control& control;
  const std::string host = host_name(), hostid = host_id();
  const std::string pid = std::to_string(::getpid());
  std::map<std::string, std::unique_ptr<PongSession>> sessions;
  std::deque<std::string> closed;  // the runs closed last
  int finished = 0;

  void close(const std::string& run, const char* why) {
    auto it = sessions.find(run);
    if (it == sessions.end()) return;
    auto& s = *it->second;
    s.stop.store(true);
    if (s.thread.joinable()) s.thread.join();
    if (!a.quiet)
      fmt::print("run {} from {}: echoed {} message(s) on {}, {} lost on the way in (dropped_count) ({})\n", run,
                 s.peer, s.echoed.load(), s.ping_topic, s.peer_endpoint->dropped(), why);
    std::fflush(stdout);
    sessions.erase(it);
    ++finished;
    closed.push_back(run);  // a repeated bye is answered too
    if (closed.size() > 16) closed.pop_front();
  }

  // A ping's hello: ready (a new session and its echo thread), busy (another ping reads the same
  // ping topic here) or error (the topics do not open).
  void on_hello(const Fields& f, const std::string& run) {
    auto it = sessions.find(run);
    if (it != sessions.end()) {  // a repeated hello: answer again
      control.send({{"op", "ready"}, {"run", run}, {"host", host}, {"hostid", hostid}, {"pid", pid}});
      return;
    }
    const std::string ping_topic = get(f, "ping");
    const PongSession* other = nullptr;
    for (const auto& [r, s] : sessions)
      if (s->ping_topic == ping_topic) other = s.get();
    if (other != nullptr) {
      control.send({{"op", "busy"}, {"run", run}, {"host", host}, {"pid", pid}, {"serving", other->peer}});
      return;
    }
    BenchPayload payload{get(f, "type"), std::strtoull(get(f, "size").c_str(), nullptr, 10)};
    std::string error;
    auto peer = open_bench_peer(payload, BenchEndpoints{ping_topic, get(f, "pong"), backend}, error);
    if (!peer) {
      control.send({{"op", "error"}, {"run", run}, {"host", host}, {"pid", pid}, {"what", error}});
      if (!a.quiet) fmt::print(stderr, "horus bench pong: run {}: {}\n", run, error);
      return;
    }
    auto s = std::make_unique<PongSession>();
    s->run = run;
    s->peer = fmt::format("{} (pid {})", get(f, "host"), get(f, "pid"));
    s->ping_topic = ping_topic;
    s->peer_endpoint = std::move(peer);
    s->last_ns.store(bench_now_ns());
    s->clock_base = clock_base();
    auto* raw = s.get();
    s->thread = std::thread([raw, spin = a.spin, cpu = a.cpu] { echo_loop(*raw, spin, cpu); });
    if (!a.quiet)
      fmt::print("run {} from {}: {} on {} -> {}\n", run, s->peer, s->peer_endpoint->describe(), ping_topic,
                 get(f, "pong"));
    std::fflush(stdout);
    sessions.emplace(run, std::move(s));
    control.send({{"op", "ready"}, {"run", run}, {"host", host}, {"hostid", hostid}, {"pid", pid}});
  }

  void on_message(const Fields& f) {
    const std::string op = get(f, "op"), run = get(f, "run");
    if (op == "hello") {
      on_hello(f, run);
    } else if (op == "start") {
      if (get(f, "host") != host || get(f, "pid") != pid) close(run, "the ping chose another pong");
      else if (auto it = sessions.find(run); it != sessions.end() && get(f, "stamps") == "1")
        it->second->stamps.store(true);
    } else if (op == "flush") {
      if (auto it = sessions.find(run); it != sessions.end()) flush_stamps(control, *it->second, bench_now_ns(), true, true);
    } else if (op == "bye") {
      if (sessions.contains(run) || std::find(closed.begin(), closed.end(), run) != closed.end())
        control.send({{"op", "closed"}, {"run", run}, {"host", host}, {"pid", pid}});
      close(run, "done");
    }
  }

  // The sessions' echo times, and the end of those idle for kPongIdleNs.
  void tick(std::int64_t now) {
    std::vector<std::string> idle;
    for (const auto& [r, s] : sessions) {
      flush_stamps(control, *s, now, false);
      if (now - s->last_ns.load() > kPongIdleNs) idle.push_back(r);
    }
    for (const auto& r : idle) close(r, "no traffic for 10 s");
  }
};

}  // namespace

int run_pong(const BenchArgs& a, const std::optional<Backend>& backend, const std::atomic<bool>& stop,
             std::atomic<bool>* ready_flag) {
  auto control = Control::open(a.prefix, backend);
  if (!control) {
    fmt::print(stderr, "horus bench pong: {}\n", control.error().message());
    if (ready_flag != nullptr) ready_flag->store(true);  // horus bench local's ping then fails with the reason
    return 2;
  }
  Pong pong(a, backend, *control);
  if (!a.quiet)
    fmt::print("horus bench pong: answering on {} ({}) on host {}, pid {}; Ctrl-C stops\n", control->name(),
               where_text(control->backend()), pong.host, pong.pid);
  std::fflush(stdout);
  if (ready_flag != nullptr) ready_flag->store(true);
  while (!stop.load()) {
    (void)control->wait(std::chrono::milliseconds(pong.sessions.empty() ? 100 : 20));
    while (auto f = control->recv()) pong.on_message(*f);
    pong.tick(bench_now_ns());
    if (a.once && pong.finished > 0 && pong.sessions.empty()) break;
  }
  while (!pong.sessions.empty()) pong.close(pong.sessions.begin()->first, "stopped");
  return 0;
}

}  // namespace horus::tools::bench_detail

namespace horus::tools {

int cmd_bench_pong(const BenchArgs& a, const std::atomic<bool>& stop) {
  std::optional<Backend> backend;
  if (!bench_detail::check_args(a, "pong", &backend)) return 2;
  return bench_detail::run_pong(a, backend, stop, nullptr);
}

}  // namespace horus::tools
