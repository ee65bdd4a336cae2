// horus bench ping (bench_cmd.hpp): the ping side of a run (the handshake, the warm-up, the
// measurement, the drain; bench_cmd.cpp describes the handshake) and its outputs: the human
// summary, --json, --csv and --plot.
#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
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

extern char** environ;

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
  } bye{*control, run, r};
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
          r.pong_hostid = get(*f, "hostid");
        }
      } else if (op == "busy") {
        // That pong reads the same ping topic for another ping: it would echo our messages too.
        // Its session may be ending (a ping that just finished): the hello is repeated until the
        // handshake's deadline, which names this refusal if it lasts.
        const auto x = fmt::format("pong {} is serving a ping from {} on {}: its echoes would mix with this "
                                   "run's; wait for it to end, or use another --topic-prefix on both sides",
                                   who, get(*f, "serving"), r.ping_topic);
        if (std::find(refusals.begin(), refusals.end(), x) == refusals.end()) refusals.push_back(x);
      } else if (op == "error") {
        const auto x = fmt::format("pong {} could not open the topics: {}", who, get(*f, "what"));
        if (std::find(refusals.begin(), refusals.end(), x) == refusals.end()) refusals.push_back(x);
      }
    }
  }
  // The chosen pong; the others close their side (sent three times: LCM may lose one).
  for (int i = 0; i < 3; ++i)
    control->send({{"op", "start"}, {"run", run}, {"host", r.pong_host}, {"pid", r.pong_pid}, {"stamps", by_clock ? "1" : "0"}});
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

  // The sequence number a tag stands for: the latest sent one congruent to it.
  auto seq_of = [&](std::uint64_t tag) -> std::optional<std::uint64_t> {
    const std::uint64_t back = (seq - 1 - tag % modulus) % modulus;
    if (seq == 0 || back >= seq) return std::nullopt;
    return seq - 1 - back;
  };
  auto clock = by_clock ? std::make_unique<ClockSamples>() : nullptr;  // 1.5 MB: fleet topics only
  const std::int64_t base = clock_base();
  std::int64_t last_control = 0;
  bool stamps_done = false;
  auto read_control = [&] {
    while (auto f = control->recv()) {
      if (get(*f, "run") != run || get(*f, "op") != "stamps") continue;
      if (auto stamps = parse_stamps(*f))
        for (const auto& st : *stamps)
          if (auto s = seq_of(st.tag); s && *s >= measure_from) clock->stamped(*s, st.at);
      if (get(*f, "last") == "1") stamps_done = true;
    }
  };

  auto on_echo = [&](std::uint64_t tag, std::int64_t now) {
    const auto resolved = seq_of(tag);
    if (!resolved) return;
    const std::uint64_t s = *resolved;
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
    if (by_clock) clock->echoed(s, t, now);
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
    now = bench_now_ns();
    if (by_clock && now - last_control >= 10'000'000) {
      read_control();
      last_control = now;
    }
    // Progress, once a second.
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
  if (by_clock) {
    // The pong's last echo times (it sends them every 50 ms; asked again while they do not come).
    const std::int64_t flush_start = bench_now_ns();
    for (std::int64_t asked = 0; !stamps_done && !stop.load();) {
      const auto now = bench_now_ns();
      if (now - flush_start > 1'000'000'000) break;
      if (now - asked >= 250'000'000) {
        control->send({{"op", "flush"}, {"run", run}});
        asked = now;
      }
      (void)control->wait(std::chrono::milliseconds(20));
      read_control();
    }
    choose_clock(a, hostid, fleet.get(), r);
    if (r.clock_source != "none") {
      if (clock->size() == 0) r.clock_why = "the pong sent no echo times (a pong older than this ping?)";
      clock->resolve(base, r.clock_offset_ns, r);
    }
  }
  r.sent = seq - measure_from;
  r.lost = r.sent - r.received;
  r.dropped = peer->dropped();
  const std::int64_t end = std::max(send_end, last_echo);
  r.measured_s = measure_start == 0 ? 0 : static_cast<double>(end - measure_start) / 1e9;
  r.ok = true;
  return r;
}

// -- output -----------------------------------------------------------------------------------

double msgs_per_s(const PingResult& r) {
  return r.measured_s > 0 ? static_cast<double>(r.received) / r.measured_s : 0;
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

namespace {

double mb_per_s(const PingResult& r) {
  return r.measured_s > 0 ? static_cast<double>(r.received) * static_cast<double>(r.message_bytes) / r.measured_s / 1e6 : 0;
}

nlohmann::json latency_json(const LatencyHistogram& h) {
  return {{"min", h.min()},
          {"p50", h.quantile(0.5)},
          {"p90", h.quantile(0.9)},
          {"p99", h.quantile(0.99)},
          {"p99_9", h.quantile(0.999)},
          {"max", h.max()},
          {"mean", h.mean()},
          {"stddev", h.stddev()},
          {"jitter", h.jitter()}};
}

nlohmann::json result_json(const BenchArgs& a, const PingResult& r) {
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
          {"one_way_ns", latency_json(r.one_way)},
          {"clock",
           {{"source", r.clock_source},
            {"why", r.clock_why},
            {"offset_ns", r.clock_offset_ns},
            {"uncertainty_ns", r.clock_uncertainty_ns}}},
          {"by_clock",
           {{"samples", r.forward.count()},
            {"below_zero", r.clock_below_zero},
            {"forward_ns", latency_json(r.forward)},
            {"return_ns", latency_json(r.back)}}},
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
  if (r.forward.count() > 0) {
    const std::string from =
        r.clock_source == "fleet"
            ? fmt::format("{}'s clock - ours: {:+.6f} s +- {}, from the fleet's heartbeats", r.pong_host,
                          static_cast<double>(r.clock_offset_ns) / 1e9, format_ns(static_cast<double>(r.clock_uncertainty_ns)))
        : r.clock_source == "synced" ? std::string("the clocks as they are (--clocks-synced)")
                                     : std::string("one clock: the pong runs on this host");
    fmt::print(out, "one-way latency by clock ({}), {} samples{}:\n", from, r.forward.count(),
               r.clock_below_zero ? fmt::format(", {} below 0 counted as 0 (the offset is off by more)", r.clock_below_zero)
                                  : std::string());
    for (const auto* way : {&r.forward, &r.back})
      fmt::print(out, "  {}  min {}   p50 {}   p99 {}   p99.9 {}   max {}\n", way == &r.forward ? "ping -> pong" : "pong -> ping",
                 f(way->min()), f(way->quantile(0.5)), f(way->quantile(0.99)), f(way->quantile(0.999)), f(way->max()));
  } else if (!r.clock_why.empty()) {
    fmt::print(out, "one-way latency by clock: not measured: {}\n", r.clock_why);
  }
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

}  // namespace

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
