// horus bench: round trips through ordinary horus topics (bench_cmd.hpp).
//
// The handshake, on PREFIX.control (GenericMessage, a MessagePack map of strings):
//   ping -> hello {run, type, size, ping, pong, host, pid}    every 250 ms until a pong is ready
//   pong -> ready {run, host, pid} | busy {run, host, pid, serving} | error {run, host, pid, what}
//   ping -> start {run, host, pid}                            the pong it measures with
//   ping -> bye {run}                                         the run is over
// A pong opens PREFIX.ping.TYPE and PREFIX.pong.TYPE for a hello's type and echoes what arrives
// on the first into the second, unchanged, until bye, a start naming another pong, or 10 s
// without traffic. The ping tags each message with its sequence number (bench_peer.hpp), keeps
// its send time, and takes one-way latency as half the round trip: one clock, no clock sync.
#include "bench_cmd.hpp"

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <sched.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <csignal>
#include <cstring>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <random>
#include <thread>
#include <vector>

#include "bench_common.hpp"
#include "bench_peer.hpp"
#include "bench_stats.hpp"
#include "floor.hpp"
#include "horus/config.hpp"
#include "horus/fleet.hpp"
#include "horus/msg/generic.hpp"
#include "horus/topic.hpp"
#include "horus/transport_registry.hpp"
#ifdef HORUS_CLI_HAVE_LCM
#include "horus/lcm/transport.hpp"
#endif

extern char** environ;

namespace horus::tools {

namespace {

using Clock = std::chrono::steady_clock;
using Fields = std::map<std::string, std::string>;

// The host as the fleet layer names and tells it apart (hostname, boot, /dev/shm, namespace):
// a namespace host is a host of its own, and robots cloned from one image with one hostname differ.
std::string host_name() { return fleet::host_name(); }
std::string host_id() { return fmt::format("{:016x}", fleet::host_id()); }

void pin_to_cpu(int cpu) {
  if (cpu >= 0) (void)bench::pin_to_cpu(cpu);
}

// -- choices ----------------------------------------------------------------------------------

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

std::string data_topic(const std::string& prefix, const char* side, const std::string& qualified, std::uint64_t size) {
  return fmt::format("{}.{}.{}{}", prefix, side, short_type(qualified), size ? fmt::format("_{}", size) : "");
}

// Where a topic's messages go, in words: "fleet (cyclonedds, domain 3)", "host (shared memory)".
std::string where_text(const Backend& b) {
  if (b.scope() == Scope::Process) return "process (in-process ring)";
  if (b.scope() == Scope::Host) return "host (shared memory)";
  const std::string t(b.transport());
#ifdef HORUS_CLI_HAVE_LCM
  if (t == "lcm") {
    auto url = lcm::url_from_environment();
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

// Where the choice of a topic's backend came from, for errors.
std::string choice_origin(const TopicChoice& c) {
  if (c.backend_from == Source::Code) return "--backend";
  if (c.backend_from == Source::Environment) return "HORUS_BACKEND";
  if (c.backend_from == Source::File && c.rule != nullptr)
    return fmt::format("{}, line {}: rule '{}'", c.config->file(), c.rule->line, c.rule->match);
  return "the default (no HORUS_BACKEND, no rule in HORUS_CONFIG)";
}

// -- the control topic -----------------------------------------------------------------------

class Control {
 public:
  static Result<Control> open(const std::string& prefix, const std::optional<Backend>& backend) {
    TopicOptions o;
    o.backend = backend;
    auto t = Topic<msg::GenericMessage>::open(prefix + ".control", o);
    if (!t) return std::unexpected(t.error());
    return Control(std::move(*t));
  }
  void send(const Fields& f) {
    auto m = msg::GenericMessage::from_value(f);
    if (m) topic_.send(*m);
  }
  // The next well-formed control message (others are skipped: another tool's traffic).
  std::optional<Fields> recv() {
    while (auto m = topic_.recv()) {
      auto f = static_cast<const msg::GenericMessage&>(*m).to_value<Fields>();
      if (f && f->contains("op") && f->contains("run")) return *f;
    }
    return std::nullopt;
  }
  bool wait(std::chrono::nanoseconds t) { return topic_.wait_for(t); }
  Backend backend() const { return topic_.backend(); }
  std::string name() const { return std::string(topic_.name()); }

 private:
  explicit Control(Topic<msg::GenericMessage> t) : topic_(std::move(t)) {}
  Topic<msg::GenericMessage> topic_;
};

std::string get(const Fields& f, const std::string& k) {
  auto it = f.find(k);
  return it == f.end() ? std::string() : it->second;
}

// -- pong -------------------------------------------------------------------------------------

struct PongSession {
  std::string run, peer;  // the ping's "host (pid)"
  std::string ping_topic;
  std::unique_ptr<BenchPeer> peer_endpoint;
  std::atomic<bool> stop{false};
  std::atomic<std::uint64_t> echoed{0};
  std::atomic<std::int64_t> last_ns{0};
  std::thread thread;
};

void echo_loop(PongSession& s, bool spin, int cpu) {
  pin_to_cpu(cpu);
  while (!s.stop.load(std::memory_order_relaxed)) {
    bool any = false;
    while (s.peer_endpoint->echo_one()) {
      s.echoed.fetch_add(1, std::memory_order_relaxed);
      any = true;
    }
    if (any) s.last_ns.store(bench_now_ns(), std::memory_order_relaxed);
    if (spin) bench::spin_pause();
    else if (!any) (void)s.peer_endpoint->wait(std::chrono::milliseconds(50));
  }
}

constexpr std::int64_t kPongIdleNs = 10'000'000'000;

int run_pong(const BenchArgs& a, const std::optional<Backend>& backend, const std::atomic<bool>& stop,
             std::atomic<bool>* ready_flag) {
  auto control = Control::open(a.prefix, backend);
  if (!control) {
    fmt::print(stderr, "horus bench pong: {}\n", control.error().message());
    if (ready_flag != nullptr) ready_flag->store(true);  // horus bench local's ping then fails with the reason
    return 2;
  }
  const std::string host = host_name(), hostid = host_id();
  const std::string pid = std::to_string(::getpid());
  if (!a.quiet)
    fmt::print("horus bench pong: answering on {} ({}) on host {}, pid {}; Ctrl-C stops\n", control->name(),
               where_text(control->backend()), host, pid);
  std::fflush(stdout);
  if (ready_flag != nullptr) ready_flag->store(true);
  std::map<std::string, std::unique_ptr<PongSession>> sessions;
  int finished = 0;
  auto close = [&](const std::string& run, const char* why) {
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
  };
  while (!stop.load()) {
    (void)control->wait(std::chrono::milliseconds(100));
    while (auto f = control->recv()) {
      const std::string op = get(*f, "op"), run = get(*f, "run");
      if (op == "hello") {
        auto it = sessions.find(run);
        if (it != sessions.end()) {  // a repeated hello: answer again
          control->send({{"op", "ready"}, {"run", run}, {"host", host}, {"hostid", hostid}, {"pid", pid}});
          continue;
        }
        const std::string ping_topic = get(*f, "ping");
        const PongSession* other = nullptr;
        for (const auto& [r, s] : sessions)
          if (s->ping_topic == ping_topic) other = s.get();
        if (other != nullptr) {
          control->send({{"op", "busy"}, {"run", run}, {"host", host}, {"pid", pid}, {"serving", other->peer}});
          continue;
        }
        BenchPayload payload{get(*f, "type"), std::strtoull(get(*f, "size").c_str(), nullptr, 10)};
        std::string error;
        auto peer = open_bench_peer(payload, BenchEndpoints{ping_topic, get(*f, "pong"), backend}, error);
        if (!peer) {
          control->send({{"op", "error"}, {"run", run}, {"host", host}, {"pid", pid}, {"what", error}});
          if (!a.quiet) fmt::print(stderr, "horus bench pong: run {}: {}\n", run, error);
          continue;
        }
        auto s = std::make_unique<PongSession>();
        s->run = run;
        s->peer = fmt::format("{} (pid {})", get(*f, "host"), get(*f, "pid"));
        s->ping_topic = ping_topic;
        s->peer_endpoint = std::move(peer);
        s->last_ns.store(bench_now_ns());
        auto* raw = s.get();
        s->thread = std::thread([raw, spin = a.spin, cpu = a.cpu] { echo_loop(*raw, spin, cpu); });
        if (!a.quiet)
          fmt::print("run {} from {}: {} on {} -> {}\n", run, s->peer, s->peer_endpoint->describe(), ping_topic,
                     get(*f, "pong"));
        std::fflush(stdout);
        sessions.emplace(run, std::move(s));
        control->send({{"op", "ready"}, {"run", run}, {"host", host}, {"hostid", hostid}, {"pid", pid}});
      } else if (op == "start") {
        if (get(*f, "host") != host || get(*f, "pid") != pid) close(run, "the ping chose another pong");
      } else if (op == "bye") {
        close(run, "done");
      }
    }
    const auto now = bench_now_ns();
    std::vector<std::string> idle;
    for (const auto& [r, s] : sessions)
      if (now - s->last_ns.load() > kPongIdleNs) idle.push_back(r);
    for (const auto& r : idle) close(r, "no traffic for 10 s");
    if (a.once && finished > 0 && sessions.empty()) break;
  }
  while (!sessions.empty()) close(sessions.begin()->first, "stopped");
  return 0;
}

// -- ping -------------------------------------------------------------------------------------

struct PingResult {
  bool ok = false;
  int exit_code = 0;
  std::string error;
  std::string type, payload, tag, ping_topic, pong_topic, control_topic, where, backend;
  std::string host, pong_host, pong_pid;
  std::uint64_t message_bytes = 0;
  std::uint64_t sent = 0, received = 0, lost = 0, late = 0, reordered = 0, duplicates = 0, refused = 0, dropped = 0;
  double measured_s = 0, warmup_s = 0;
  std::uint32_t window = 0;
  LatencyHistogram one_way;
  std::int64_t start_unix_ns = 0;
};

// The ping's book of messages in flight, indexed by sequence number modulo its size.
class Ledger {
 public:
  static constexpr std::size_t kSize = std::size_t{1} << 20;
  Ledger() : slots_(kSize) {}
  void sent(std::uint64_t seq, std::int64_t t) {
    auto& s = slots_[seq & (kSize - 1)];
    if (s.state == kOut) --outstanding_;  // overwritten while still out: it is lost
    s = Slot{seq, t, kOut};
    ++outstanding_;
  }
  enum class Echo { OnTime, Late, Duplicate, Unknown };
  // Marks seq received; `sent_at` is its send time when it came back within the timeout.
  Echo received(std::uint64_t seq, std::int64_t& sent_at) {
    auto& s = slots_[seq & (kSize - 1)];
    if (s.seq != seq || s.state == kNone) return Echo::Unknown;
    if (s.state == kDone) return Echo::Duplicate;
    const bool late = s.state == kLate;
    if (s.state == kOut) --outstanding_;
    s.state = kDone;
    sent_at = s.t;
    return late ? Echo::Late : Echo::OnTime;
  }
  // Messages out longer than `timeout` stop counting against the window.
  void expire(std::uint64_t next_seq, std::int64_t now, std::int64_t timeout) {
    while (oldest_ < next_seq) {
      auto& s = slots_[oldest_ & (kSize - 1)];
      if (s.seq == oldest_ && s.state == kOut) {
        if (now - s.t <= timeout) break;
        s.state = kLate;
        --outstanding_;
      }
      ++oldest_;
    }
  }
  std::uint64_t outstanding() const { return outstanding_; }

 private:
  enum State : std::uint8_t { kNone, kOut, kLate, kDone };
  struct Slot {
    std::uint64_t seq = 0;
    std::int64_t t = 0;
    State state = kNone;
  };
  std::vector<Slot> slots_;
  std::uint64_t oldest_ = 0, outstanding_ = 0;
};

std::string no_pong_error(const PingResult& r, const std::string& prefix, const Backend& b, const std::string& origin,
                          bool remote, const std::vector<std::string>& refusals) {
  std::string msg = fmt::format("no pong answered on {} within the warm-up ({}).\n", r.control_topic, r.where);
  for (const auto& x : refusals) msg += "  " + x + "\n";
  if (b.scope() != Scope::Fleet) {
    msg += fmt::format(
        "  The bench topics stay on this {} (chosen by {}): only a pong {} can answer, and none runs.\n"
        "  Start `horus bench pong` here, or make the bench topics fleet topics to reach another host:\n"
        "  HORUS_BACKEND=cyclonedds (fastdds, lcm) on both hosts, or in HORUS_CONFIG:\n"
        "    topics:\n      - match: \"{}.**\"\n        scope: fleet\n",
        b.scope() == Scope::Process ? "process" : "host", origin,
        b.scope() == Scope::Process ? "in this process" : "on this host", prefix);
    return msg;
  }
  msg += fmt::format("  Check that `horus bench pong{}` runs on the other host with the same backend ({}, chosen by {})",
                     prefix == "bench" ? std::string() : " --topic-prefix " + prefix,
                     b.transport(), origin);
  if (b.transport() == "lcm")
    msg += ",\n  the same LCM URL (the default udpm://239.255.76.67:7667?ttl=0 never leaves this host: set "
           "HORUS_LCM_URL=udpm://239.255.76.67:7667?ttl=1 on both),\n  a multicast route on both hosts (ip route "
           "show 224.0.0.0/4),";
  else
    msg += ",\n  the same DDS domain (HORUS_DOMAIN_ID or network.domain_id), HORUS_DDS_LOCALHOST unset (loopback "
           "only reaches this host),\n  multicast between the hosts (SPDP discovery on 239.255.0.1),";
  msg += "\n  and that no firewall drops UDP between them";
  msg += remote ? "; pongs on this host do not count (--remote)." : ".";
  return msg;
}

PingResult run_ping(const BenchArgs& a, const std::optional<Backend>& backend, const std::atomic<bool>& stop) {
  PingResult r;
  r.host = host_name();
  const std::string pid = std::to_string(::getpid());
  auto fail_with = [&](int code, std::string what) {
    r.exit_code = code;
    r.error = std::move(what);
    return std::move(r);
  };
  BenchPayload payload{a.type, a.size};
  if (payload.type.empty()) payload.type = a.size == 0 ? "Pose2D" : a.size < kPoolPayloadFrom ? "CompressedImage" : "Image";
  std::string error;
  r.type = bench_type(payload, error);
  if (r.type.empty()) return fail_with(2, error);
  r.ping_topic = data_topic(a.prefix, "ping", r.type, a.size);
  r.pong_topic = data_topic(a.prefix, "pong", r.type, a.size);
  TopicOptions code;
  code.backend = backend;
  auto choice = choose(r.ping_topic, code);
  if (!choice) return fail_with(2, choice.error().message());
  auto control_choice = choose(a.prefix + ".control", code);
  if (!control_choice) return fail_with(2, control_choice.error().message());
  if (control_choice->backend != choice->backend)
    return fail_with(2, fmt::format("the configuration gives {}.control {} ({}) but {} {} ({}); give the bench "
                                    "topics one rule ('{}.**')",
                                    a.prefix, to_string(control_choice->backend), choice_origin(*control_choice),
                                    r.ping_topic, to_string(choice->backend), choice_origin(*choice), a.prefix));
  r.where = where_text(choice->backend);
  if (a.remote && choice->backend.scope() != Scope::Fleet)
    return fail_with(2, fmt::format("--remote: the configuration keeps {} on this {} (scope {}, chosen by {}), so a "
                                    "pong on another host cannot receive it. Make the bench topics fleet topics: "
                                    "HORUS_BACKEND=cyclonedds (fastdds, lcm), or a rule in HORUS_CONFIG: topics: - "
                                    "match: \"{}.**\" scope: fleet",
                                    r.ping_topic, choice->backend.scope() == Scope::Process ? "process" : "host",
                                    to_string(choice->backend.scope()), choice_origin(*choice), a.prefix));
  auto control = Control::open(a.prefix, backend);
  if (!control) return fail_with(2, control.error().message());
  r.control_topic = control->name();
  auto peer = open_bench_peer(payload, BenchEndpoints{r.pong_topic, r.ping_topic, backend}, error);
  if (!peer) return fail_with(2, error);
  r.payload = peer->describe();
  r.tag = peer->tag_carrier();
  r.message_bytes = peer->message_bytes();
  r.backend = peer->backend();
  r.window = a.flood ? (a.window != 0 ? a.window : std::max<std::uint32_t>(1, std::min<std::uint32_t>(peer->capacity() / 2, 256)))
                     : 0;
  std::mt19937_64 rng(std::random_device{}() ^ static_cast<std::uint64_t>(bench_now_ns()));
  const std::string run = fmt::format("{:016x}", rng());
  const std::int64_t t0 = bench_now_ns();
  const auto warmup_ns = static_cast<std::int64_t>(a.warmup * 1e9);

  // Whatever happens after the first hello, the pongs that answered hear that the run is over.
  struct Bye {
    Control& c;
    std::string run;
    ~Bye() {
      for (int i = 0; i < 3; ++i) c.send({{"op", "bye"}, {"run", run}});
    }
  } bye{*control, run};
  const std::string hostid = host_id();

  // 1. Handshake: hello until a pong is ready.
  std::vector<std::string> refusals;
  std::int64_t last_hello = 0;
  while (r.pong_host.empty()) {
    const auto now = bench_now_ns();
    if (stop.load()) return fail_with(130, "interrupted");
    if (now - t0 > std::max(warmup_ns, static_cast<std::int64_t>(a.handshake * 1e9)))
      return fail_with(3, no_pong_error(r, a.prefix, choice->backend, choice_origin(*choice), a.remote, refusals));
    if (now - last_hello >= 250'000'000) {
      control->send({{"op", "hello"}, {"run", run}, {"type", r.type}, {"size", std::to_string(a.size)},
                     {"ping", r.ping_topic}, {"pong", r.pong_topic}, {"host", r.host}, {"hostid", hostid}, {"pid", pid}});
      last_hello = now;
    }
    (void)control->wait(std::chrono::milliseconds(50));
    while (auto f = control->recv()) {
      if (get(*f, "run") != run) continue;
      const std::string op = get(*f, "op"), who = fmt::format("{} (pid {})", get(*f, "host"), get(*f, "pid"));
      if (op == "ready") {
        if (a.remote && get(*f, "hostid") == hostid) {
          const auto x = fmt::format("pong on this host {} ignored (--remote)", who);
          if (std::find(refusals.begin(), refusals.end(), x) == refusals.end()) refusals.push_back(x);
          continue;
        }
        if (r.pong_host.empty()) {
          r.pong_host = get(*f, "host");
          r.pong_pid = get(*f, "pid");
        }
      } else if (op == "busy") {
        // That pong reads the same ping topic for another ping: it would echo our messages too.
        return fail_with(3, fmt::format("pong {} is serving a ping from {} on {}: its echoes would mix with this "
                                        "run's; wait for it to end, or use another --topic-prefix on both sides",
                                        who, get(*f, "serving"), r.ping_topic));
      } else if (op == "error") {
        const auto x = fmt::format("pong {} could not open the topics: {}", who, get(*f, "what"));
        if (std::find(refusals.begin(), refusals.end(), x) == refusals.end()) refusals.push_back(x);
      }
    }
  }
  // The chosen pong; the others close their side (sent three times: LCM may lose one).
  for (int i = 0; i < 3; ++i)
    control->send({{"op", "start"}, {"run", run}, {"host", r.pong_host}, {"pid", r.pong_pid}});
  const std::int64_t handshake_done = bench_now_ns();

  // 2. Traffic: warm-up (not measured), then the measurement, then the drain.
  const auto modulus = peer->tag_modulus();
  const std::int64_t period = a.flood || a.rate <= 0 ? 0 : static_cast<std::int64_t>(1e9 / a.rate);
  const auto timeout_ns = static_cast<std::int64_t>(a.timeout * 1e9);
  const std::uint64_t max_out = a.flood ? r.window : Ledger::kSize / 2;
  auto ledger = std::make_unique<Ledger>();
  auto interval = std::make_unique<LatencyHistogram>();
  std::uint64_t seq = 0, measure_from = UINT64_MAX, max_seen = 0, echoes = 0;
  bool seen_any = false;
  std::int64_t next_send = bench_now_ns(), measure_start = 0, send_end = 0, last_progress = 0, last_echo = 0;
  std::uint64_t interval_received = 0, refused_seq = UINT64_MAX;
  bool refused_wait = false;
  const std::int64_t warm_end = std::max(t0 + warmup_ns, bench_now_ns() + 200'000'000);
  const bool is_tty = ::isatty(2) != 0;
  enum Phase { kWarm, kMeasure, kDrain } phase = kWarm;

  auto on_echo = [&](std::uint64_t tag, std::int64_t now) {
    // The sequence number this tag stands for: the latest sent one congruent to it.
    const std::uint64_t back = (seq - 1 - tag % modulus) % modulus;
    if (seq == 0 || back >= seq) return;
    const std::uint64_t s = seq - 1 - back;
    std::int64_t t = 0;
    const auto kind = ledger->received(s, t);
    ++echoes;
    last_echo = now;
    if (s < measure_from || kind == Ledger::Echo::Unknown) return;  // a warm-up message
    if (kind == Ledger::Echo::Duplicate) {
      ++r.duplicates;
      return;
    }
    if (kind == Ledger::Echo::Late) {  // after --timeout: lost, as the help says
      ++r.late;
      return;
    }
    ++r.received;
    ++interval_received;
    if (seen_any && s < max_seen) ++r.reordered;
    max_seen = std::max(max_seen, s);
    seen_any = true;
    const auto one_way = static_cast<std::uint64_t>(std::max<std::int64_t>(0, now - t) / 2);
    r.one_way.add(one_way);
    interval->add(one_way);
  };

  while (true) {
    auto now = bench_now_ns();
    if (stop.load() && phase != kDrain) {
      phase = kDrain;
      send_end = now;
    }
    if (phase == kWarm && now >= warm_end) {
      if (echoes == 0) {
        if (now - handshake_done > std::max<std::int64_t>(warmup_ns, 2'000'000'000))
          return fail_with(3, fmt::format("pong {} (pid {}) answered on {}, but nothing came back on {} within the "
                                          "warm-up ({} sent on {}): the data topics are not connected ({})",
                                          r.pong_host, r.pong_pid, r.control_topic, r.pong_topic, seq, r.ping_topic, r.where));
      } else {
        phase = kMeasure;
        measure_from = seq;
        measure_start = now;
        r.start_unix_ns = std::chrono::duration_cast<std::chrono::nanoseconds>(
                              std::chrono::system_clock::now().time_since_epoch()).count();
        r.warmup_s = static_cast<double>(now - t0) / 1e9;
        last_progress = now;
        interval->clear();
        interval_received = 0;
        next_send = now;
      }
    }
    if (phase == kMeasure) {
      const bool by_count = a.count > 0 && seq - measure_from >= a.count;
      const bool by_time = a.count == 0 && now - measure_start >= static_cast<std::int64_t>(a.duration * 1e9);
      if (by_count || by_time) {
        phase = kDrain;
        send_end = now;
      }
    }
    if (phase == kDrain) {
      ledger->expire(seq, now, timeout_ns);
      if (ledger->outstanding() == 0 || now - send_end > timeout_ns) break;
    }
    // Send what is due.
    if (phase != kDrain) {
      ledger->expire(seq, now, timeout_ns);
      while (ledger->outstanding() < max_out && (period == 0 || now >= next_send) &&
             !(phase == kMeasure && a.count > 0 && seq - measure_from >= a.count)) {
        std::int64_t t_send = 0;
        if (!peer->send(seq, t_send)) {
          // Counted once per message; then wait for an echo to give a slot back.
          if (refused_seq != seq) ++r.refused;
          refused_seq = seq;
          refused_wait = true;
          break;
        }
        refused_wait = false;
        ledger->sent(seq, t_send);
        ++seq;
        if (period == 0) {
          if (!a.flood) break;
          continue;
        }
        next_send += period;
        if (now - next_send > 100 * period) next_send = now;  // fell far behind: do not burst
        now = bench_now_ns();
      }
    }
    // Receive.
    if (a.spin) {
      // Poll as tightly as the floor does: the clock is read only when an echo arrives, and
      // every 256 polls to stop at the next send (or after 1 ms).
      const std::int64_t until = phase != kDrain && period != 0 ? next_send : now + 1'000'000;
      for (std::uint32_t polls = 1;; ++polls) {
        if (auto tag = peer->recv_tag()) {
          on_echo(*tag, bench_now_ns());
          while (auto more = peer->recv_tag()) on_echo(*more, bench_now_ns());
          break;
        }
        if (phase != kDrain && period == 0 && ledger->outstanding() < max_out && !refused_wait) break;
        bench::spin_pause();
        if (polls % 256 == 0 && bench_now_ns() >= until) break;
      }
    } else {
      std::int64_t wait = 100'000'000;
      if (phase != kDrain && period != 0) wait = std::max<std::int64_t>(0, next_send - bench_now_ns());
      if (phase != kDrain && period == 0 && ledger->outstanding() < max_out) wait = 0;
      if (refused_wait) wait = std::max<std::int64_t>(wait, 1'000'000);
      if (wait > 0) (void)peer->wait(std::chrono::nanoseconds(wait));
      while (auto tag = peer->recv_tag()) on_echo(*tag, bench_now_ns());
    }
    // Progress, once a second.
    now = bench_now_ns();
    if (!a.quiet && phase == kMeasure && now - last_progress >= 1'000'000'000) {
      const double el = static_cast<double>(now - measure_start) / 1e9;
      const double dt = static_cast<double>(now - last_progress) / 1e9;
      fmt::print(stderr, "{}[{:6.1f} s] sent {}  received {}  one-way p50 {}  p99 {}  max {}  {:.0f} msg/s{}",
                 is_tty ? "\r" : "", el, seq - measure_from, r.received, format_ns(static_cast<double>(interval->quantile(0.5))),
                 format_ns(static_cast<double>(interval->quantile(0.99))), format_ns(static_cast<double>(interval->max())),
                 static_cast<double>(interval_received) / dt, is_tty ? "   " : "\n");
      std::fflush(stderr);
      last_progress = now;
      interval->clear();
      interval_received = 0;
    }
  }
  if (!a.quiet && is_tty) fmt::print(stderr, "\n");
  if (measure_from == UINT64_MAX) return fail_with(130, "interrupted during the warm-up; nothing was measured");
  r.sent = seq - measure_from;
  r.lost = r.sent - r.received;
  r.dropped = peer->dropped();
  const std::int64_t end = std::max(send_end, last_echo);
  r.measured_s = measure_start == 0 ? 0 : static_cast<double>(end - measure_start) / 1e9;
  r.ok = true;
  return r;
}

// -- output -----------------------------------------------------------------------------------

double mb_per_s(const PingResult& r) {
  return r.measured_s > 0 ? static_cast<double>(r.received) * static_cast<double>(r.message_bytes) / r.measured_s / 1e6 : 0;
}
double msgs_per_s(const PingResult& r) {
  return r.measured_s > 0 ? static_cast<double>(r.received) / r.measured_s : 0;
}

nlohmann::json result_json(const BenchArgs& a, const PingResult& r) {
  const auto& h = r.one_way;
  return {{"tool", "horus bench ping"},
          {"type", r.type},
          {"payload", r.payload},
          {"message_bytes", r.message_bytes},
          {"tag", r.tag},
          {"topics", {{"control", r.control_topic}, {"ping", r.ping_topic}, {"pong", r.pong_topic}}},
          {"backend", r.backend},
          {"where", r.where},
          {"host", r.host},
          {"pong_host", r.pong_host},
          {"pong_pid", r.pong_pid},
          {"mode", a.flood ? "flood" : "rate"},
          {"rate_hz", a.flood ? 0.0 : a.rate},
          {"window", r.window},
          {"spin", a.spin},
          {"warmup_s", r.warmup_s},
          {"duration_s", r.measured_s},
          {"start_unix_ns", r.start_unix_ns},
          {"sent", r.sent},
          {"received", r.received},
          {"lost", r.lost},
          {"late", r.late},
          {"reordered", r.reordered},
          {"duplicates", r.duplicates},
          {"refused", r.refused},
          {"dropped", r.dropped},
          {"one_way_ns",
           {{"min", h.min()},
            {"p50", h.quantile(0.5)},
            {"p90", h.quantile(0.9)},
            {"p99", h.quantile(0.99)},
            {"p99_9", h.quantile(0.999)},
            {"max", h.max()},
            {"mean", h.mean()},
            {"stddev", h.stddev()},
            {"jitter", h.jitter()}}},
          {"throughput", {{"msgs_per_s", msgs_per_s(r)}, {"mb_per_s", mb_per_s(r)}}}};
}

// The JSON's scalars, flattened ("one_way_ns.p50"), in a stable order.
void flatten(const nlohmann::json& j, const std::string& prefix, std::vector<std::pair<std::string, std::string>>& out) {
  for (auto it = j.begin(); it != j.end(); ++it) {
    const std::string key = prefix.empty() ? it.key() : prefix + "." + it.key();
    if (it->is_object()) flatten(*it, key, out);
    else out.emplace_back(key, it->is_string() ? it->get<std::string>() : it->dump());
  }
}

bool write_text(const std::string& file, const std::string& text, bool append, std::string& error) {
  if (file == "-") {
    fmt::print("{}", text);
    return true;
  }
  std::ofstream f(file, append ? std::ios::app : std::ios::trunc);
  if (f) f << text;
  if (!f) error = fmt::format("cannot write {}: {}", file, std::strerror(errno));
  return static_cast<bool>(f);
}

std::string csv_field(const std::string& v) {
  if (v.find_first_of(",\"\n") == std::string::npos) return v;
  std::string q = "\"";
  for (char c : v) q += c == '"' ? std::string("\"\"") : std::string(1, c);
  return q + "\"";
}

// Appends a row to FILE (a header first when the file is new or empty).
bool write_csv(const std::string& file, const nlohmann::json& j, std::string& error) {
  std::vector<std::pair<std::string, std::string>> kv;
  flatten(j, "", kv);
  std::string header, row;
  for (const auto& [k, v] : kv) {
    header += (header.empty() ? "" : ",") + k;
    row += (row.empty() ? "" : ",") + csv_field(v);
  }
  std::error_code ec;
  const bool fresh = file == "-" || !std::filesystem::exists(file, ec) || std::filesystem::file_size(file, ec) == 0;
  return write_text(file, (fresh ? header + "\n" : std::string()) + row + "\n", true, error);
}

std::string find_in_path(const std::string& exe) {
  const char* path = std::getenv("PATH");
  std::string p = path ? path : "/usr/bin:/bin";
  std::size_t start = 0;
  while (start <= p.size()) {
    const auto end = p.find(':', start);
    const std::string dir = p.substr(start, end == std::string::npos ? std::string::npos : end - start);
    const std::string full = (dir.empty() ? "." : dir) + "/" + exe;
    if (::access(full.c_str(), X_OK) == 0) return full;
    if (end == std::string::npos) break;
    start = end + 1;
  }
  return {};
}

// The one-way latency histogram (top) and CDF (bottom) as a PNG, drawn by gnuplot.
bool write_plot(const std::string& file, const PingResult& r, std::string& error) {
  const std::string gnuplot = find_in_path("gnuplot");
  if (gnuplot.empty()) {
    error = "--plot needs gnuplot, which is not on PATH (Debian: apt-get install gnuplot-nox)";
    return false;
  }
  if (r.one_way.count() == 0) {
    error = "--plot: no samples to draw";
    return false;
  }
  std::string script = (std::filesystem::temp_directory_path() / "horus_bench_XXXXXX.gp").string();
  const int fd = ::mkstemps(script.data(), 3);
  if (fd < 0) {
    error = fmt::format("--plot: cannot create a temporary file for gnuplot's script: {}", std::strerror(errno));
    return false;
  }
  ::close(fd);
  std::string text = fmt::format(
      "set terminal pngcairo size 1000,800 font 'sans,10'\nset output '{}'\nset multiplot layout 2,1 title "
      "\"horus bench ping: {} over {}\\n{} -> {}, {} samples\"\nset logscale x\nset grid\nset xlabel 'one-way "
      "latency (us)'\n",
      file, r.type, r.where, r.host, r.pong_host, r.one_way.count());
  text += "$hist << EOD\n";
  {  // 20 bins per decade (the x axis is logarithmic): messages per bin
    std::map<int, std::uint64_t> bins;
    for (const auto& b : r.one_way.buckets())
      bins[static_cast<int>(std::floor(20.0 * std::log10(std::max(1.0, static_cast<double>(b.lo)))))] += b.count;
    for (const auto& [bin, n] : bins)
      text += fmt::format("{} {} {}\n", std::pow(10.0, bin / 20.0) / 1e3, std::pow(10.0, (bin + 1) / 20.0) / 1e3, n);
  }
  text += "EOD\n$cdf << EOD\n";
  std::uint64_t seen = 0;
  for (const auto& b : r.one_way.buckets()) {
    seen += b.count;
    text += fmt::format("{} {}\n", static_cast<double>(b.hi) / 1e3, static_cast<double>(seen) / static_cast<double>(r.one_way.count()));
  }
  text += "EOD\n";
  const double p50 = static_cast<double>(r.one_way.quantile(0.5)) / 1e3, p99 = static_cast<double>(r.one_way.quantile(0.99)) / 1e3;
  text += fmt::format(
      "set ylabel 'messages'\nset style fill solid 0.5\nplot $hist using (sqrt($1*$2)):3:1:2:(0):3 with "
      "boxxyerror title 'histogram (20 bins per decade)'\nset ylabel 'fraction at or below'\nset yrange [0:1.02]\nset arrow 1 from {0},0 to {0},1.02 "
      "nohead dt 2\nset arrow 2 from {1},0 to {1},1.02 nohead dt 3\nplot $cdf using 1:2 with steps lw 2 title "
      "'CDF (p50 {2}, p99 {3})'\nunset multiplot\n",
      p50, p99, format_ns(p50 * 1e3), format_ns(p99 * 1e3));
  if (!write_text(script, text, false, error)) return false;
  std::vector<std::string> args = {gnuplot, script};
  std::vector<char*> argv;
  for (auto& s : args) argv.push_back(s.data());
  argv.push_back(nullptr);
  pid_t child = -1;
  int status = 0;
  if (::posix_spawn(&child, gnuplot.c_str(), nullptr, nullptr, argv.data(), environ) != 0 ||
      ::waitpid(child, &status, 0) < 0 || !WIFEXITED(status) || WEXITSTATUS(status) != 0) {
    error = fmt::format("gnuplot failed to draw {} (script kept: {})", file, script);
    return false;
  }
  std::filesystem::remove(script);
  return true;
}

// The human summary, on `out` (stderr when the JSON or CSV goes to stdout).
void print_result(std::FILE* out, const BenchArgs& a, const PingResult& r) {
  const auto& h = r.one_way;
  fmt::print(out, "horus bench ping: {}, tag in {}\n", r.payload, r.tag);
  fmt::print(out, "  topics      {} -> {} ({})\n", r.ping_topic, r.pong_topic, r.where);
  fmt::print(out, "  hosts       {} (pid {}) -> {} (pid {})\n", r.host, ::getpid(), r.pong_host, r.pong_pid);
  if (a.flood) fmt::print(out, "  traffic     flood, {} in flight, {:.3f} s after {:.2f} s warm-up\n", r.window, r.measured_s, r.warmup_s);
  else fmt::print(out, "  traffic     {} Hz, {:.3f} s after {:.2f} s warm-up\n", a.rate, r.measured_s, r.warmup_s);
  fmt::print(out, "one-way latency (round trip / 2), {} samples{}:\n", h.count(), a.spin ? ", spinning" : "");
  auto f = [](std::uint64_t v) { return format_ns(static_cast<double>(v)); };
  fmt::print(out, "  min {}   p50 {}   p90 {}   p99 {}   p99.9 {}   max {}\n", f(h.min()), f(h.quantile(0.5)),
             f(h.quantile(0.9)), f(h.quantile(0.99)), f(h.quantile(0.999)), f(h.max()));
  fmt::print(out, "  mean {}   stddev {}   jitter {} (mean change between consecutive messages)\n", format_ns(h.mean()),
             format_ns(h.stddev()), format_ns(h.jitter()));
  fmt::print(out, "messages: sent {}, received {}, lost {} ({:.3f} %{}), reordered {}, duplicates {}{}\n", r.sent,
             r.received, r.lost, r.sent ? 100.0 * static_cast<double>(r.lost) / static_cast<double>(r.sent) : 0.0,
             r.late ? fmt::format(", {} of them came back after --timeout", r.late) : std::string(), r.reordered,
             r.duplicates, r.refused ? fmt::format(", refused by the topic {}", r.refused) : std::string());
  fmt::print(out, "throughput: {:.1f} msg/s, {:.3f} MB/s each way ({} bytes per message)\n", msgs_per_s(r), mb_per_s(r),
             r.message_bytes);
  if (r.lost == 0) return;
  // Where losses come from, per backend.
  fmt::print(out, "lost: {} message(s) did not come back within --timeout {} s; this side's {} counted {} dropped on "
                  "the way back over the whole run, warm-up included (dropped_count; the pong prints its own)\n",
             r.lost, a.timeout, r.pong_topic, r.dropped);
  if (r.backend == "lcm")
    fmt::print(out, "  LCM is best effort over UDP and a {}-byte message is about {} datagram(s): losses are usually a full "
                    "receive buffer;\n  add recv_buf_size=BYTES to the LCM URL on both hosts (the kernel caps it at "
                    "net.core.rmem_max), or lower --rate\n",
               r.message_bytes, (r.message_bytes + 65000) / 65000);
  else if (r.backend == "cyclonedds" || r.backend == "fastdds")
    fmt::print(out, "  a best-effort topic loses what the network drops; a reliable one only what its history "
                    "(capacity) overwrites: see `horus config explain {}`\n",
               r.ping_topic);
  else
    fmt::print(out, "  on one host a message is lost only when a ring overwrites it: a slow pong, or --window above "
                    "the ring's capacity\n");
}

bool write_outputs(const BenchArgs& a, const PingResult& r) {
  std::string error;
  bool ok = true;
  const auto j = result_json(a, r);
  if (!a.json.empty() && !write_text(a.json, j.dump(2) + "\n", false, error)) ok = false;
  if (ok && !a.csv.empty() && !write_csv(a.csv, j, error)) ok = false;
  if (ok && !a.plot.empty() && !write_plot(a.plot, r, error)) ok = false;
  if (!ok) fmt::print(stderr, "horus bench ping: {}\n", error);
  return ok;
}

// Checks the arguments and, when `backend` is given, parses --backend into it; prints what is
// wrong and returns false otherwise.
bool check_args(const BenchArgs& a, const char* cmd, std::optional<Backend>* backend = nullptr) {
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

}  // namespace

int cmd_bench_pong(const BenchArgs& a, const std::atomic<bool>& stop) {
  std::optional<Backend> backend;
  if (!check_args(a, "pong", &backend)) return 2;
  return run_pong(a, backend, stop, nullptr);
}

int cmd_bench_ping(const BenchArgs& a, const std::atomic<bool>& stop) {
  std::optional<Backend> backend;
  if (!check_args(a, "ping", &backend)) return 2;
  auto r = run_ping(a, backend, stop);
  if (!r.ok) {
    fmt::print(stderr, "horus bench ping: {}\n", r.error);
    return r.exit_code;
  }
  print_result(a.json == "-" || a.csv == "-" ? stderr : stdout, a, r);
  std::fflush(stdout);
  if (!write_outputs(a, r)) return 1;
  if (r.received == 0) {
    fmt::print(stderr, "horus bench ping: none of the {} measured messages came back\n", r.sent);
    return 1;
  }
  return 0;
}

// -- local ------------------------------------------------------------------------------------

namespace {

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

}  // namespace

int cmd_bench_local(const BenchArgs& args, const std::atomic<bool>& stop) {
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

  struct Row {
    const char* name;
    bool cross_process, spin, flood;
  };
  const Row rows[] = {{"in-process, spinning", false, true, false},   {"in-process, blocking", false, false, false},
                      {"in-process, flood", false, false, true},       {"cross-process, spinning", true, true, false},
                      {"cross-process, blocking", true, false, false}, {"cross-process, flood", true, false, true}};
  int rc = 0;
  nlohmann::json json_rows = nlohmann::json::array();
  for (const auto& row : rows) {
    if (stop.load()) break;
    if (row.spin && !pinned) continue;  // two spinning threads on one CPU measure the scheduler
    BenchArgs r = a;
    r.spin = row.spin;
    r.prefix = fmt::format("{}.{}", a.prefix, &row - rows);
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
      std::vector<std::string> cargs = {"/proc/self/exe", "bench", "pong", "--once", "--quiet", "--backend", "shm",
                                        "--topic-prefix", r.prefix, "--cpu", std::to_string(cpu_b)};
      if (row.spin) cargs.emplace_back("--spin");
      std::vector<char*> argv;
      for (auto& s : cargs) argv.push_back(s.data());
      argv.push_back(nullptr);
      if (::posix_spawn(&child, "/proc/self/exe", nullptr, nullptr, argv.data(), environ) != 0) child = -1;
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
    if (child > 0) {
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
    if (!res.ok) {
      fmt::print(stderr, "horus bench local: {}: {}\n", row.name, res.error);
      rc = 1;
      continue;
    }
    const auto& h = res.one_way;
    const double ratio = floor.best() && !row.flood ? static_cast<double>(h.quantile(0.5)) / static_cast<double>(floor.best()) : 0;
    fmt::print(out, "{:<26} {:>10} {:>10} {:>10} {:>10} {:>14.0f} {:>9}\n", row.name,
               format_ns(static_cast<double>(h.quantile(0.5))), format_ns(static_cast<double>(h.quantile(0.99))),
               format_ns(static_cast<double>(h.quantile(0.999))), format_ns(static_cast<double>(h.max())),
               msgs_per_s(res), ratio > 0 ? fmt::format("{:.2f}x", ratio) : std::string("-"));
    std::fflush(out);
    json_rows.push_back({{"path", row.name},
                         {"type", res.type},
                         {"message_bytes", res.message_bytes},
                         {"window", res.window},
                         {"sent", res.sent},
                         {"received", res.received},
                         {"lost", res.lost},
                         {"one_way_ns", {{"p50", h.quantile(0.5)}, {"p99", h.quantile(0.99)}, {"p99_9", h.quantile(0.999)}, {"max", h.max()}}},
                         {"msgs_per_s", msgs_per_s(res)},
                         {"vs_floor", ratio}});
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
