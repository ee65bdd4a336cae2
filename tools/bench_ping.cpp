// horus bench ping (bench_cmd.hpp): the ping side of a run (the handshake, the warm-up, the
// measurement, the drain; bench_cmd.cpp describes the handshake); its outputs (the human
// summary, --json, --csv and --plot) are in bench_output.cpp.
#include <fmt/format.h>

#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <memory>
#include <optional>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "bench_cmd.hpp"
#include "bench_cmd_internal.hpp"
#include "bench_peer.hpp"
#include "bench_stats.hpp"
#include "horus/config.hpp"
#include "horus/detail/cache_floor.hpp"

namespace horus::tools::bench_detail {

// -- ping -------------------------------------------------------------------------------------

namespace {

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
           "only reaches this host),\n  multicast between the hosts (SPDP discovery on 239.255.0.1; on Wi-Fi "
           "that filters multicast, list the other hosts in HORUS_PEERS=10.0.0.2,robot-3 or network.peers on both),";
  msg += "\n  and that no firewall drops UDP between them";
  msg += remote ? "; pongs on this host do not count (--remote)." : ".";
  return msg;
}

// A run's end before its measurement: the exit code and the error.
struct PingFailure {
  int code;
  std::string what;
};

// What the phases of one run share.
struct PingContext {
  const BenchArgs& a;
  const std::atomic<bool>& stop;
  PingResult& r;
  Control& control;
  BenchPeer& peer;
  const std::string& run;
  const std::string& hostid;
  bool by_clock;
};

// The payload's type and the bench topics, checked against the configuration (one rule for all the
// bench topics; with --remote, a fleet scope): sets r's type, topics and where; nothing, with `error`, otherwise.
std::optional<TopicChoice> choose_topics(const BenchArgs& a, const std::optional<Backend>& backend,
                                         BenchPayload& payload, PingResult& r, std::string& error) {
  auto fail = [&](std::string what) {
    error = std::move(what);
    return std::optional<TopicChoice>();
  };
  if (payload.type.empty()) payload.type = a.size == 0 ? "Pose2D" : a.size < kPoolPayloadFrom ? "CompressedImage" : "Image";
  r.type = bench_type(payload, error);
  if (r.type.empty()) return std::nullopt;
  r.ping_topic = data_topic(a.prefix, "ping", r.type, a.size);
  r.pong_topic = data_topic(a.prefix, "pong", r.type, a.size);
  TopicOptions code;
  code.backend = backend;
  auto choice = choose(r.ping_topic, code);
  if (!choice) return fail(choice.error().message());
  auto control_choice = choose(a.prefix + ".control", code);
  if (!control_choice) return fail(control_choice.error().message());
  if (control_choice->backend != choice->backend)
    return fail(fmt::format("the configuration gives {}.control {} ({}) but {} {} ({}); give the bench "
                            "topics one rule ('{}.**')",
                            a.prefix, to_string(control_choice->backend), choice_origin(*control_choice),
                            r.ping_topic, to_string(choice->backend), choice_origin(*choice), a.prefix));
  r.where = where_text(choice->backend);
  if (a.remote && choice->backend.scope() != Scope::Fleet)
    return fail(fmt::format("--remote: the configuration keeps {} on this {} (scope {}, chosen by {}), so a "
                            "pong on another host cannot receive it. Make the bench topics fleet topics: "
                            "HORUS_BACKEND=cyclonedds (fastdds, lcm), or a rule in HORUS_CONFIG: topics: - "
                            "match: \"{}.**\" scope: fleet",
                            r.ping_topic, choice->backend.scope() == Scope::Process ? "process" : "host",
                            to_string(choice->backend.scope()), choice_origin(*choice), a.prefix));
  return std::move(*choice);
}

// Whatever happens after the first hello, the pongs that answered hear that the run is over.
// The chosen pong says it closed the session: until it does (at most 2 s), bye is repeated, so
// that the pong is free for the next ping on the same topics. A bye sent just before this
// process exits may never leave the host (its fleet bridge may be this process's, and end
// with it).
struct Bye {
  Control& c;
  std::string run;
  const PingResult& r;
  ~Bye() {
    const auto pid = r.pong_pid;
    const std::int64_t until = bench_now_ns() + (r.pong_host.empty() ? 0 : 2'000'000'000);
    for (int sent = 0;; ++sent) {
      c.send({{"op", "bye"}, {"run", run}});
      if (sent >= 2 && bench_now_ns() > until) return;
      (void)c.wait(std::chrono::milliseconds(100));
      while (auto f = c.recv())
        if (get(*f, "op") == "closed" && get(*f, "run") == run && get(*f, "pid") == pid &&
            get(*f, "host") == r.pong_host)
          return;
    }
  }
};

void note_refusal(std::vector<std::string>& refusals, const std::string& x) {
  if (std::find(refusals.begin(), refusals.end(), x) == refusals.end()) refusals.push_back(x);
}

// One answer to the hello: the first ready pong is chosen (with --remote, not one on this host);
// the others' refusals are noted for the handshake's error.
void on_hello_answer(const PingContext& c, const Fields& f, std::vector<std::string>& refusals) {
  if (get(f, "run") != c.run) return;
  const std::string op = get(f, "op"), who = fmt::format("{} (pid {})", get(f, "host"), get(f, "pid"));
  if (op == "ready") {
    if (c.a.remote && get(f, "hostid") == c.hostid) {
      note_refusal(refusals, fmt::format("pong on this host {} ignored (--remote)", who));
      return;
    }
    if (c.r.pong_host.empty()) {
      c.r.pong_host = get(f, "host");
      c.r.pong_pid = get(f, "pid");
      c.r.pong_hostid = get(f, "hostid");
    }
  } else if (op == "busy") {
    // That pong reads the same ping topic for another ping: it would echo our messages too.
    // Its session may be ending (a ping that just finished): the hello is repeated until the
    // handshake's deadline, which names this refusal if it lasts.
    note_refusal(refusals, fmt::format("pong {} is serving a ping from {} on {}: its echoes would mix with this "
                                       "run's; wait for it to end, or use another --topic-prefix on both sides",
                                       who, get(f, "serving"), c.r.ping_topic));
  } else if (op == "error") {
    note_refusal(refusals, fmt::format("pong {} could not open the topics: {}", who, get(f, "what")));
  }
}

// 1. Handshake: hello until a pong is ready.
std::optional<PingFailure> handshake(const PingContext& c, const std::string& pid, std::int64_t t0,
                                     std::int64_t warmup_ns, const TopicChoice& choice) {
  std::vector<std::string> refusals;
  std::int64_t last_hello = 0;
  while (c.r.pong_host.empty()) {
    const auto now = bench_now_ns();
    if (c.stop.load()) return PingFailure{130, "interrupted"};
    if (now - t0 > std::max(warmup_ns, static_cast<std::int64_t>(c.a.handshake * 1e9)))
      return PingFailure{3,
                         no_pong_error(c.r, c.a.prefix, choice.backend, choice_origin(choice), c.a.remote, refusals)};
    if (now - last_hello >= 250'000'000) {
      c.control.send({{"op", "hello"}, {"run", c.run}, {"type", c.r.type}, {"size", std::to_string(c.a.size)},
                      {"ping", c.r.ping_topic}, {"pong", c.r.pong_topic}, {"host", c.r.host}, {"hostid", c.hostid},
                      {"pid", pid}});
      last_hello = now;
    }
    (void)c.control.wait(std::chrono::milliseconds(50));
    while (auto f = c.control.recv()) on_hello_answer(c, *f, refusals);
  }
  return std::nullopt;
}

// 2. Traffic: warm-up (not measured), then the measurement, then the drain.
struct PingTraffic {
  PingTraffic(const PingContext& ctx, std::int64_t t0_, std::int64_t warmup, std::int64_t handshake_end)
      : c(ctx), t0(t0_), warmup_ns(warmup), handshake_done(handshake_end) {}

  const PingContext& c;
  const std::int64_t t0, warmup_ns, handshake_done;
  const std::uint64_t modulus = c.peer.tag_modulus();
  const std::int64_t period = c.a.flood || c.a.rate <= 0 ? 0 : static_cast<std::int64_t>(1e9 / c.a.rate);
  const std::int64_t timeout_ns = static_cast<std::int64_t>(c.a.timeout * 1e9);
  const std::uint64_t max_out = c.a.flood ? c.r.window : Ledger::kSize / 2;
  std::unique_ptr<Ledger> ledger = std::make_unique<Ledger>();
  std::unique_ptr<LatencyHistogram> interval = std::make_unique<LatencyHistogram>();
  std::uint64_t seq = 0, measure_from = UINT64_MAX, max_seen = 0, echoes = 0;
  bool seen_any = false;
  std::int64_t next_send = bench_now_ns(), measure_start = 0, send_end = 0, last_progress = 0, last_echo = 0;
  std::uint64_t interval_received = 0, refused_seq = UINT64_MAX;
  bool refused_wait = false;
  const std::int64_t warm_end = std::max(t0 + warmup_ns, bench_now_ns() + 200'000'000);
  const bool is_tty = ::isatty(2) != 0;
  enum Phase { kWarm, kMeasure, kDrain } phase = kWarm;
  // 1.5 MB: fleet topics only
  std::unique_ptr<ClockSamples> clock = c.by_clock ? std::make_unique<ClockSamples>() : nullptr;
  const std::int64_t base = clock_base();
  std::int64_t last_control = 0;
  bool stamps_done = false;

  // The sequence number a tag stands for: the latest sent one congruent to it.
  std::optional<std::uint64_t> seq_of(std::uint64_t tag) const {
    const std::uint64_t back = (seq - 1 - tag % modulus) % modulus;
    if (seq == 0 || back >= seq) return std::nullopt;
    return seq - 1 - back;
  }

  void read_control() {
    while (auto f = c.control.recv()) {
      if (get(*f, "run") != c.run || get(*f, "op") != "stamps") continue;
      if (auto stamps = parse_stamps(*f))
        for (const auto& st : *stamps)
          if (auto s = seq_of(st.tag); s && *s >= measure_from) clock->stamped(*s, st.at);
      if (get(*f, "last") == "1") stamps_done = true;
    }
  }

  void on_echo(std::uint64_t tag, std::int64_t now) {
    const auto resolved = seq_of(tag);
    if (!resolved) return;
    const std::uint64_t s = *resolved;
    std::int64_t t = 0;
    const auto kind = ledger->received(s, t);
    ++echoes;
    last_echo = now;
    if (s < measure_from || kind == Ledger::Echo::Unknown) return;  // a warm-up message
    if (kind == Ledger::Echo::Duplicate) {
      ++c.r.duplicates;
      return;
    }
    if (kind == Ledger::Echo::Late) {  // after --timeout: lost, as the help says
      ++c.r.late;
      return;
    }
    ++c.r.received;
    ++interval_received;
    if (seen_any && s < max_seen) ++c.r.reordered;
    max_seen = std::max(max_seen, s);
    seen_any = true;
    const auto one_way = static_cast<std::uint64_t>(std::max<std::int64_t>(0, now - t) / 2);
    c.r.one_way.add(one_way);
    interval->add(one_way);
    if (c.by_clock) clock->echoed(s, t, now);
  }

  void start_measuring(std::int64_t now) {
    phase = kMeasure;
    measure_from = seq;
    measure_start = now;
    c.r.start_unix_ns = std::chrono::duration_cast<std::chrono::nanoseconds>(
                            std::chrono::system_clock::now().time_since_epoch()).count();
    c.r.warmup_s = static_cast<double>(now - t0) / 1e9;
    last_progress = now;
    interval->clear();
    interval_received = 0;
    next_send = now;
  }

  // Moves the phase on at `now`; true when the run ends (`failed` set when nothing came back).
  bool next_phase(std::int64_t now, std::optional<PingFailure>& failed) {
    if (c.stop.load() && phase != kDrain) {
      phase = kDrain;
      send_end = now;
    }
    if (phase == kWarm && now >= warm_end) {
      if (echoes == 0) {
        if (now - handshake_done > std::max<std::int64_t>(warmup_ns, 2'000'000'000)) {
          failed = PingFailure{3, fmt::format("pong {} (pid {}) answered on {}, but nothing came back on {} within the "
                                              "warm-up ({} sent on {}): the data topics are not connected ({})",
                                              c.r.pong_host, c.r.pong_pid, c.r.control_topic, c.r.pong_topic, seq,
                                              c.r.ping_topic, c.r.where)};
          return true;
        }
      } else {
        start_measuring(now);
      }
    }
    if (phase == kMeasure) {
      const bool by_count = c.a.count > 0 && seq - measure_from >= c.a.count;
      const bool by_time = c.a.count == 0 && now - measure_start >= static_cast<std::int64_t>(c.a.duration * 1e9);
      if (by_count || by_time) {
        phase = kDrain;
        send_end = now;
      }
    }
    if (phase == kDrain) {
      ledger->expire(seq, now, timeout_ns);
      if (ledger->outstanding() == 0 || now - send_end > timeout_ns) return true;
    }
    return false;
  }

  // Sends what is due (`now` moves on with a rate).
  void send_due(std::int64_t& now) {
    ledger->expire(seq, now, timeout_ns);
    while (ledger->outstanding() < max_out && (period == 0 || now >= next_send) &&
           !(phase == kMeasure && c.a.count > 0 && seq - measure_from >= c.a.count)) {
      std::int64_t t_send = 0;
      if (!c.peer.send(seq, t_send)) {
        // Counted once per message; then wait for an echo to give a slot back.
        if (refused_seq != seq) ++c.r.refused;
        refused_seq = seq;
        refused_wait = true;
        break;
      }
      refused_wait = false;
      ledger->sent(seq, t_send);
      ++seq;
      if (period == 0) {
        if (!c.a.flood) break;
        continue;
      }
      next_send += period;
      if (now - next_send > 100 * period) next_send = now;  // fell far behind: do not burst
      now = bench_now_ns();
    }
  }

  void receive(std::int64_t now) {
    if (c.a.spin) {
      // Poll as tightly as the floor does: the clock is read only when an echo arrives, and
      // every 256 polls to stop at the next send (or after 1 ms).
      const std::int64_t until = phase != kDrain && period != 0 ? next_send : now + 1'000'000;
      for (std::uint32_t polls = 1;; ++polls) {
        if (auto tag = c.peer.recv_tag()) {
          on_echo(*tag, bench_now_ns());
          while (auto more = c.peer.recv_tag()) on_echo(*more, bench_now_ns());
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
      if (wait > 0) (void)c.peer.wait(std::chrono::nanoseconds(wait));
      while (auto tag = c.peer.recv_tag()) on_echo(*tag, bench_now_ns());
    }
  }

  // Progress, once a second.
  void progress(std::int64_t now) {
    if (c.a.quiet || phase != kMeasure || now - last_progress < 1'000'000'000) return;
    const double el = static_cast<double>(now - measure_start) / 1e9;
    const double dt = static_cast<double>(now - last_progress) / 1e9;
    fmt::print(stderr, "{}[{:6.1f} s] sent {}  received {}  one-way p50 {}  p99 {}  max {}  {:.0f} msg/s{}",
               is_tty ? "\r" : "", el, seq - measure_from, c.r.received,
               format_ns(static_cast<double>(interval->quantile(0.5))),
               format_ns(static_cast<double>(interval->quantile(0.99))),
               format_ns(static_cast<double>(interval->max())), static_cast<double>(interval_received) / dt,
               is_tty ? "   " : "\n");
    std::fflush(stderr);
    last_progress = now;
    interval->clear();
    interval_received = 0;
  }

  // Until the drain ends, or nothing came back within the warm-up.
  std::optional<PingFailure> loop() {
    while (true) {
      auto now = bench_now_ns();
      std::optional<PingFailure> failed;
      if (next_phase(now, failed)) return failed;
      if (phase != kDrain) send_due(now);
      receive(now);
      now = bench_now_ns();
      if (c.by_clock && now - last_control >= 10'000'000) {
        read_control();
        last_control = now;
      }
      progress(now);
    }
  }

  // The pong's last echo times (it sends them every 50 ms; asked again while they do not come).
  void flush_stamps() {
    const std::int64_t flush_start = bench_now_ns();
    for (std::int64_t asked = 0; !stamps_done && !c.stop.load();) {
      const auto now = bench_now_ns();
      if (now - flush_start > 1'000'000'000) break;
      if (now - asked >= 250'000'000) {
        c.control.send({{"op", "flush"}, {"run", c.run}});
        asked = now;
      }
      (void)c.control.wait(std::chrono::milliseconds(20));
      read_control();
    }
  }
};

}  // namespace

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
  std::string error;
  const auto choice = choose_topics(a, backend, payload, r, error);
  if (!choice) return fail_with(2, error);
  // One-way by clock on fleet topics (on one host the round trip's half is as good).
  const bool by_clock = choice->backend.scope() == Scope::Fleet;
  std::unique_ptr<Fleet> fleet;
  if (by_clock && !a.clocks_synced) {
    FleetOptions fo;
    fo.transport = std::string(choice->backend.transport());
    if (auto f = Fleet::open(fo)) fleet = std::move(*f);
    else r.clock_why = "no fleet view: " + f.error().message();
  }
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
  Bye bye{*control, run, r};
  const std::string hostid = host_id();
  const PingContext ctx{a, stop, r, *control, *peer, run, hostid, by_clock};
  if (auto failed = handshake(ctx, pid, t0, warmup_ns, *choice))
    return fail_with(failed->code, std::move(failed->what));
  // The chosen pong; the others close their side (sent three times: LCM may lose one).
  for (int i = 0; i < 3; ++i)
    control->send({{"op", "start"}, {"run", run}, {"host", r.pong_host}, {"pid", r.pong_pid}, {"stamps", by_clock ? "1" : "0"}});
  PingTraffic traffic(ctx, t0, warmup_ns, bench_now_ns());
  if (auto failed = traffic.loop()) return fail_with(failed->code, std::move(failed->what));
  if (!a.quiet && traffic.is_tty) fmt::print(stderr, "\n");
  if (traffic.measure_from == UINT64_MAX) return fail_with(130, "interrupted during the warm-up; nothing was measured");
  if (by_clock) {
    traffic.flush_stamps();
    choose_clock(a, hostid, fleet.get(), r);
    if (r.clock_source != "none") {
      if (traffic.clock->size() == 0) r.clock_why = "the pong sent no echo times (a pong older than this ping?)";
      traffic.clock->resolve(traffic.base, r.clock_offset_ns, r);
    }
  }
  r.sent = traffic.seq - traffic.measure_from;
  r.lost = r.sent - r.received;
  r.dropped = peer->dropped();
  const std::int64_t end = std::max(traffic.send_end, traffic.last_echo);
  r.measured_s = traffic.measure_start == 0 ? 0 : static_cast<double>(end - traffic.measure_start) / 1e9;
  r.ok = true;
  return r;
}

}  // namespace horus::tools::bench_detail

namespace horus::tools {

int cmd_bench_ping(const BenchArgs& a, const std::atomic<bool>& stop) {
  std::optional<Backend> backend;
  if (!bench_detail::check_args(a, "ping", &backend)) return 2;
  auto r = bench_detail::run_ping(a, backend, stop);
  if (!r.ok) {
    fmt::print(stderr, "horus bench ping: {}\n", r.error);
    return r.exit_code;
  }
  bench_detail::print_result(a.json == "-" || a.csv == "-" ? stderr : stdout, a, r);
  std::fflush(stdout);
  if (!bench_detail::write_outputs(a, r)) return 1;
  if (r.received == 0) {
    fmt::print(stderr, "horus bench ping: none of the {} measured messages came back\n", r.sent);
    return 1;
  }
  return 0;
}

}  // namespace horus::tools
