// horus: the command line.
//
//   horus topic list [--json] [-v] [--local]  every topic on this host (HORUS_NAMESPACE) and, when
//                                         a network backend is configured (HORUS_BACKEND, the
//                                         file's network.backend, --backend), on the fleet's hosts
//   horus topic info NAME                 type, sizes, processes, counts, rate (or the hosts that
//                                         announce it)
//   horus topic echo NAME [--json] [-n N] print messages as they arrive: standard types through
//                                         the reflection; a topic of other hosts through the
//                                         type signature its host announced (any type)
//   horus topic hz NAME [--duration S]    live rate with min/max/std of the periods
//   horus topic bw NAME [--duration S]    bytes per second, mean and max message size
//   horus topic pub NAME TYPE JSON [--rate HZ] [--count N]  publish (standard types, JSON
//                                         through the reflection)
//   horus fleet [--json] [--once]         the fleet's hosts: state, heartbeat age, RTT, processes,
//                                         topics (live table; --once: one snapshot)
//   horus bench pong | ping | local       round trips between hosts through ordinary topics
//                                         (one-way latency, jitter, losses, throughput; JSON,
//                                         CSV, a plot), and the local paths beside the true
//                                         floor (bench_cmd.hpp)
//   horus clean                           remove segments whose processes are all gone
//   horus config check FILE               validate a configuration file (exit 1 naming the error)
//   horus config explain NAME [--file F]  which rule, scope, backend and QoS a topic gets, and
//                                         from where (code is not known here: environment,
//                                         file, default); the file is F or HORUS_CONFIG's
//
// list/info/clean read the segments without joining them; echo, hz and bw subscribe like any
// other process (they count as a subscriber while they run); the fleet commands join the fleet
// layer (horus/fleet.hpp) for as long as they run.
#include <CLI/CLI.hpp>
#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "horus/config.hpp"
#include "horus/discovery/registry.hpp"
#include "horus/fleet.hpp"
#include "horus/horus.hpp"
#include "horus/json.hpp"
#include "horus/msg/all.hpp"
#include "horus/shm/shm_segment.hpp"
#include "bench_cmd.hpp"
#include "record_cmd.hpp"
#include "remote_reader.hpp"
#include "typed_reader.hpp"

namespace {

std::atomic<bool> g_stop{false};
extern "C" void on_signal(int) { g_stop.store(true); }

using clock_type = std::chrono::steady_clock;

nlohmann::json entry_json(const horus::discovery::TopicEntry& e) {
  nlohmann::json j;
  j["topic"] = e.topic;
  j["type"] = e.type_name;
  j["type_hash"] = fmt::format("{:016x}", e.type_hash);
  j["message_size"] = e.message_size;
  j["serialized"] = e.serialized;
  j["capacity"] = e.capacity;
  if (e.pooled)
    j["pool"] = {{"slot_bytes", e.pool_slot_bytes},
                 {"slots_per_publisher", e.pool_slots_per_publisher},
                 {"pinned", e.pool_pinned},
                 {"reused", e.pool_reused},
                 {"exhausted", e.pool_exhausted}};
  j["segment"] = e.segment;
  j["segment_bytes"] = e.segment_bytes;
  j["publishers"] = e.publishers;
  j["subscribers"] = e.subscribers;
  j["messages_sent"] = e.messages_sent;
  j["dropped"] = e.dropped;
  if (e.rate_hz >= 0) j["rate_hz"] = e.rate_hz;
  j["stale"] = e.stale;
  j["scope"] = e.scope;
  if (e.scope == "fleet")
    j["bridge"] = {{"transport", e.transport},        {"pid", e.bridge_pid},
                   {"claims", e.bridge_claims},       {"exported", e.exported},
                   {"imported", e.imported},          {"dropped", e.bridge_dropped},
                   {"remote_publishers", e.remote_publishers}, {"remote_subscribers", e.remote_subscribers}};
  auto procs = nlohmann::json::array();
  for (const auto& p : e.processes)
    procs.push_back({{"pid", p.pid},
                     {"alive", p.alive},
                     {"publishers", p.publishers},
                     {"subscribers", p.subscribers},
                     {"bridge", p.bridge}});
  j["processes"] = procs;
  return j;
}

std::string processes_text(const horus::discovery::TopicEntry& e) {
  std::string out;
  for (const auto& p : e.processes) {
    if (!out.empty()) out += ", ";
    out += fmt::format("{}{} ({} pub, {} sub{})", p.pid, p.alive ? "" : " dead", p.publishers, p.subscribers,
                       p.bridge ? ", bridge" : "");
  }
  return out.empty() ? "none" : out;
}

std::string scope_text(const horus::discovery::TopicEntry& e) {
  return e.scope == "fleet" ? fmt::format("fleet ({})", e.transport) : e.scope;
}

std::string bridge_text(const horus::discovery::TopicEntry& e) {
  return fmt::format("{}; {} claim(s); exported {}, imported {}, dropped {}; remote: {} writer(s), {} reader(s)",
                     e.bridge_pid != 0 ? fmt::format("pid {}", e.bridge_pid) : std::string("none now"),
                     e.bridge_claims, e.exported, e.imported, e.bridge_dropped, e.remote_publishers,
                     e.remote_subscribers);
}

// -- the fleet ------------------------------------------------------------------------------

// Where the fleet commands look: --backend, else HORUS_BACKEND's network backend, else the file's
// network.backend; empty when none is configured (the commands then stay on this host).
std::string fleet_transport(const std::string& backend_flag) {
  if (!backend_flag.empty()) return backend_flag;
  auto s = horus::fleet_settings();
  return s ? s->transport : std::string();
}

std::unique_ptr<horus::Fleet> open_fleet(const std::string& transport, std::string& error) {
  horus::FleetOptions o;
  o.transport = transport;
  auto f = horus::Fleet::open(o);
  if (!f) {
    error = f.error().message();
    return nullptr;
  }
  return std::move(*f);
}

// Waits `wait` for the fleet's hosts to answer (open() asked each to announce itself), or
// less: once every host heard of has announced and a quarter of `wait` passed.
void settle(const horus::Fleet& fleet, std::chrono::milliseconds wait) {
  const auto start = clock_type::now();
  while (!g_stop.load() && clock_type::now() - start < wait) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    if (clock_type::now() - start < wait / 4) continue;
    const auto hosts = fleet.hosts();
    if (!hosts.empty() && std::all_of(hosts.begin(), hosts.end(), [](const auto& h) { return h.announced; })) return;
  }
}

nlohmann::json fleet_topic_json(const horus::FleetTopic& t) {
  nlohmann::json j = {{"topic", t.name},
                      {"type", t.type_name},
                      {"type_hash", fmt::format("{:016x}", t.type_hash)},
                      {"scope", t.scope},
                      {"publishers", t.publishers},
                      {"subscribers", t.subscribers},
                      {"messages", t.messages},
                      {"dropped", t.dropped},
                      {"message_size", t.message_size},
                      {"decodable", !t.signature.empty()}};
  if (t.scope == "fleet") j["transport"] = t.transport;
  if (t.rate_hz >= 0) j["rate_hz"] = t.rate_hz;
  return j;
}

nlohmann::json fleet_json(const horus::Fleet& fleet) {
  auto hosts = nlohmann::json::array();
  for (const auto& h : fleet.hosts()) {
    auto procs = nlohmann::json::array();
    for (const auto& p : h.processes) procs.push_back({{"pid", p.pid}, {"name", p.name}, {"start_unix_ns", p.start_unix_ns}});
    auto topics = nlohmann::json::array();
    for (const auto& t : h.topics) topics.push_back(fleet_topic_json(t));
    nlohmann::json j = {{"host", h.name},
                        {"id", fmt::format("{:016x}", h.id)},
                        {"state", h.state == horus::HostState::Lost ? "lost" : "alive"},
                        {"rejoined", h.state == horus::HostState::Rejoined},
                        {"rejoins", h.rejoins},
                        {"self", h.self},
                        {"age_ms", h.heartbeat_age.count()},
                        {"period_ms", h.period.count()},
                        {"heartbeats", h.heartbeats},
                        {"announced", h.announced},
                        {"namespace", h.shm_namespace},
                        {"processes", procs},
                        {"topics", topics}};
    j["rtt_us"] = h.rtt ? nlohmann::json(h.rtt->count()) : nlohmann::json(nullptr);
    hosts.push_back(std::move(j));
  }
  return {{"transport", fleet.transport()}, {"malformed", fleet.malformed()}, {"hosts", hosts}};
}

void print_fleet_table(const horus::Fleet& fleet) {
  const auto hosts = fleet.hosts();
  fmt::print("fleet on {}: {} host{}\n", fleet.transport(), hosts.size(), hosts.size() == 1 ? "" : "s");
  fmt::print("{:<24} {:<9} {:>8} {:>9} {:>6} {:>7} {:>7}\n", "host", "state", "age ms", "rtt us", "procs", "fleet", "topics");
  for (const auto& h : hosts) {
    std::size_t fleet_topics = 0;
    for (const auto& t : h.topics) fleet_topics += t.scope == "fleet" ? 1 : 0;
    std::string state(horus::to_string(h.state));
    if (h.rejoins > 0) state += fmt::format(" ({}x)", h.rejoins);
    fmt::print("{:<24} {:<9} {:>8} {:>9} {:>6} {:>7} {:>7}\n", h.name + (h.self ? " *" : ""), state,
               h.heartbeat_age.count(), h.rtt ? std::to_string(h.rtt->count()) : "-",
               h.announced ? std::to_string(h.processes.size()) : "?", h.announced ? std::to_string(fleet_topics) : "?",
               h.announced ? std::to_string(h.topics.size()) : "?");
  }
  if (const auto bad = fleet.malformed(); bad != 0) fmt::print("{} malformed announcement(s) ignored\n", bad);
}

int cmd_fleet(const std::string& backend, bool json, bool once, int wait_ms, double duration_s) {
  const std::string transport = fleet_transport(backend);
  if (transport.empty()) {
    fmt::print(stderr, "horus fleet: no network backend to watch the fleet on; set HORUS_BACKEND=cyclonedds|fastdds|lcm, "
                       "network.backend in the configuration file (HORUS_CONFIG), or --backend\n");
    return 2;
  }
  std::string error;
  auto fleet = open_fleet(transport, error);
  if (!fleet) {
    fmt::print(stderr, "horus fleet: {}\n", error);
    return 2;
  }
  settle(*fleet, std::chrono::milliseconds(wait_ms));
  if (once) {
    if (json) fmt::print("{}\n", fleet_json(*fleet).dump(2));
    else print_fleet_table(*fleet);
    return 0;
  }
  const auto end = clock_type::now() + std::chrono::duration_cast<clock_type::duration>(
                                           std::chrono::duration<double>(duration_s > 0 ? duration_s : 1e9));
  const bool tty = ::isatty(1) != 0;
  while (!g_stop.load() && clock_type::now() < end) {
    if (json) {
      fmt::print("{}\n", fleet_json(*fleet).dump());
    } else {
      if (tty) fmt::print("\033[H\033[2J");
      print_fleet_table(*fleet);
      if (!tty) fmt::print("\n");
    }
    std::fflush(stdout);
    const auto next = clock_type::now() + std::chrono::seconds(1);
    while (!g_stop.load() && clock_type::now() < std::min(next, end)) std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  return 0;
}

// The topics of other hosts (not this one), by name: each with the hosts that announce it.
struct RemoteTopic {
  horus::FleetTopic topic;
  std::vector<std::string> hosts;
};
std::map<std::string, RemoteTopic> remote_topics(const horus::Fleet& fleet) {
  std::map<std::string, RemoteTopic> out;
  for (const auto& h : fleet.hosts()) {
    if (h.self || h.state == horus::HostState::Lost) continue;
    for (const auto& t : h.topics) {
      auto& r = out[t.name];
      if (r.hosts.empty()) r.topic = t;
      else {
        r.topic.publishers += t.publishers;
        r.topic.subscribers += t.subscribers;
        if (r.topic.signature.empty()) r.topic.signature = t.signature;
      }
      r.hosts.push_back(h.name);
    }
  }
  return out;
}

std::string join(const std::vector<std::string>& v) {
  std::string out;
  for (const auto& s : v) out += (out.empty() ? "" : ",") + s;
  return out;
}

// -- reading a topic ---------------------------------------------------------------------------

// What echo, hz and bw read from: a topic of this host (its standard type), or one of other
// hosts only (through its announced signature).
class Source {
 public:
  virtual ~Source() = default;
  virtual std::optional<std::string> text(bool json) = 0;
  virtual std::optional<std::size_t> size() = 0;
  virtual bool wait(std::chrono::nanoseconds timeout) = 0;
};

class LocalSource final : public Source {
 public:
  explicit LocalSource(std::unique_ptr<horus::tools::TypedReader> r) : r_(std::move(r)) {}
  std::optional<std::string> text(bool json) override { return r_->recv_text(json); }
  std::optional<std::size_t> size() override { return r_->recv_size(); }
  bool wait(std::chrono::nanoseconds t) override { return r_->wait(t); }

 private:
  std::unique_ptr<horus::tools::TypedReader> r_;
};

class RemoteSource final : public Source {
 public:
  explicit RemoteSource(std::unique_ptr<horus::tools::RemoteReader> r) : r_(std::move(r)) {}
  std::optional<std::string> text(bool json) override {
    auto s = r_->recv(true);
    if (!s) return std::nullopt;
    if (!s->error.empty()) return "# a sample that does not decode (" + std::to_string(s->bytes) + " bytes): " + s->error;
    return json ? s->value.dump() : s->value.dump(2);
  }
  std::optional<std::size_t> size() override {
    auto s = r_->recv(false);
    if (!s) return std::nullopt;
    return s->bytes;
  }
  bool wait(std::chrono::nanoseconds t) override { return r_->wait(t); }

 private:
  std::unique_ptr<horus::tools::RemoteReader> r_;
};

struct Lookup {
  std::string transport;  // --backend, for the fleet
  int wait_ms = 1500;
};

// Opens `name` on this host (its standard type) or, when it is not here and a network backend
// is configured, where other hosts announce it; runs body(source). Errors name what exists.
template <class Body>
int with_topic(const std::string& ns, const std::string& name, const char* cmd, const Lookup& lookup, Body&& body) {
  auto e = horus::discovery::find_topic(ns, name);
  if (e) {
    std::string error;
    // A fleet topic is opened as one (a host topic of the same name would be a scope conflict);
    // this short-lived observer never bridges it (HORUS_BRIDGE=0).
    horus::Backend backend = horus::Backend::SharedMemory;
    if (e->scope == "fleet") {
      backend = horus::Backend::network(e->transport);
      ::setenv("HORUS_BRIDGE", "0", 1);
    }
    auto reader = horus::tools::open_reader(e->type_name, name, backend, error);
    if (!reader && !error.empty()) {
      fmt::print(stderr, "horus topic {}: {}\n", cmd, error);
      return 1;
    }
    if (!reader) {
      fmt::print(stderr,
                 "horus topic {}: topic '{}' carries {} (layout hash {:016x}, {} bytes), which is not a standard horus "
                 "message; this tool decodes the {} standard types on this host, and any type of a fleet topic "
                 "that another host announces\n",
                 cmd, name, e->type_name, e->type_hash, e->message_size, horus::msg::AllMessages::size);
      return 1;
    }
    LocalSource src(std::move(reader));
    return body(static_cast<Source&>(src));
  }
  const std::string transport = fleet_transport(lookup.transport);
  if (transport.empty()) {
    fmt::print(stderr, "horus topic {}: {} (no network backend is configured, so other hosts were not asked)\n", cmd,
               e.error());
    return 1;
  }
  std::string error;
  auto fleet = open_fleet(transport, error);
  if (!fleet) {
    fmt::print(stderr, "horus topic {}: {}\n", cmd, error);
    return 1;
  }
  std::optional<RemoteTopic> found;
  const auto deadline = clock_type::now() + std::chrono::milliseconds(lookup.wait_ms);
  while (!found && !g_stop.load() && clock_type::now() < deadline) {
    auto all = remote_topics(*fleet);
    if (auto it = all.find(name); it != all.end()) found = it->second;
    else std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  if (!found) {
    std::string known;
    for (const auto& t : horus::discovery::list_topics(ns))
      if (!t.topic.starts_with("horus.fleet.")) known += (known.empty() ? "" : ", ") + t.topic;
    for (const auto& [n, r] : remote_topics(*fleet)) known += (known.empty() ? "" : ", ") + n + " (" + join(r.hosts) + ")";
    fmt::print(stderr, "horus topic {}: no topic '{}' on this host nor on the {} host(s) of the fleet on {}{}\n", cmd,
               name, fleet->hosts().size(), transport, known.empty() ? " (no topics at all)" : "; topics: " + known);
    return 1;
  }
  const auto& t = found->topic;
  if (t.scope != "fleet") {
    fmt::print(stderr, "horus topic {}: topic '{}' is a {} topic of {}: its messages never leave that host\n", cmd, name,
               t.scope, join(found->hosts));
    return 1;
  }
  if (t.signature.empty()) {
    fmt::print(stderr,
               "horus topic {}: cannot decode topic '{}': {} (layout hash {:016x}, {} bytes) was announced without "
               "its type signature\n",
               cmd, name, t.type_name, t.type_hash, t.message_size);
    return 1;
  }
  auto reader = horus::tools::RemoteReader::open(name, t.transport, t.type_name, t.type_hash, t.signature, error);
  if (!reader) {
    fmt::print(stderr, "horus topic {}: topic '{}' ({}, layout hash {:016x}, {} bytes): {}\n", cmd, name, t.type_name,
               t.type_hash, t.message_size, error);
    return 1;
  }
  fleet.reset();  // the reader has its own endpoint
  RemoteSource src(std::move(reader));
  return body(static_cast<Source&>(src));
}

clock_type::time_point deadline_after(double seconds) {
  return clock_type::now() + std::chrono::duration_cast<clock_type::duration>(
                                 std::chrono::duration<double>(seconds > 0 ? seconds : 1e9));
}

int cmd_echo(const std::string& ns, const std::string& name, const Lookup& lookup, bool json, long count,
             double timeout_s) {
  return with_topic(ns, name, "echo", lookup, [&](Source& src) {
    long printed = 0;
    const auto deadline = deadline_after(timeout_s);
    while (!g_stop.load() && (count <= 0 || printed < count) && clock_type::now() < deadline) {
      if (auto text = src.text(json)) {
        fmt::print("{}\n", *text);
        std::fflush(stdout);
        ++printed;
      } else {
        // Sleeps until a message comes (at most 100 ms, to see Ctrl-C and the deadline).
        src.wait(std::min<clock_type::duration>(std::chrono::milliseconds(100), deadline - clock_type::now()));
      }
    }
    return (count > 0 && printed < count) ? 1 : 0;
  });
}

// Receives for `duration_s` and calls report(values, seconds) every `window_s` with what arrived
// in that window: each message's arrival time and size.
template <class Report>
int sample_topic(Source& src, double duration_s, double window_s, Report&& report) {
  const auto end = deadline_after(duration_s);
  const auto step = std::chrono::duration_cast<clock_type::duration>(std::chrono::duration<double>(window_s));
  auto next_report = clock_type::now() + step;
  std::vector<std::pair<clock_type::time_point, std::size_t>> window;
  std::uint64_t total = 0;
  while (!g_stop.load() && clock_type::now() < end) {
    bool got = false;
    while (auto n = src.size()) {
      window.emplace_back(clock_type::now(), *n);
      ++total;
      got = true;
    }
    if (!got) src.wait(std::min<clock_type::duration>(std::chrono::milliseconds(100), next_report - clock_type::now()));
    if (clock_type::now() >= next_report) {
      next_report += step;
      report(window, window_s);
      std::fflush(stdout);
    }
  }
  fmt::print("received {} messages\n", total);
  return 0;
}

int cmd_hz(const std::string& ns, const std::string& name, const Lookup& lookup, double duration_s, double window_s) {
  return with_topic(ns, name, "hz", lookup, [&](Source& src) {
    std::optional<clock_type::time_point> last;
    return sample_topic(src, duration_s, window_s, [&](auto& window, double) {
      std::vector<double> periods;
      for (const auto& [t, n] : window) {
        if (last) periods.push_back(std::chrono::duration<double>(t - *last).count());
        last = t;
      }
      window.clear();
      if (periods.empty()) {
        fmt::print("no new messages\n");
        return;
      }
      double sum = 0, mn = periods[0], mx = periods[0];
      for (double p : periods) {
        sum += p;
        mn = std::min(mn, p);
        mx = std::max(mx, p);
      }
      const double mean = sum / static_cast<double>(periods.size());
      double var = 0;
      for (double p : periods) var += (p - mean) * (p - mean);
      const double sd = std::sqrt(var / static_cast<double>(periods.size()));
      fmt::print("average rate: {:.3f} Hz\n\tmin: {:.6f}s max: {:.6f}s std dev: {:.6f}s window: {}\n", 1.0 / mean, mn,
                 mx, sd, periods.size() + 1);
    });
  });
}

std::string human_bytes(double b) {
  if (b >= 1e6) return fmt::format("{:.2f} MB", b / 1e6);
  if (b >= 1e3) return fmt::format("{:.2f} KB", b / 1e3);
  return fmt::format("{:.0f} B", b);
}

int cmd_bw(const std::string& ns, const std::string& name, const Lookup& lookup, double duration_s, double window_s) {
  return with_topic(ns, name, "bw", lookup, [&](Source& src) {
    return sample_topic(src, duration_s, window_s, [&](auto& window, double seconds) {
      if (window.empty()) {
        fmt::print("no new messages\n");
        return;
      }
      double sum = 0;
      std::size_t mx = 0, mn = window.front().second;
      for (const auto& [t, n] : window) {
        sum += static_cast<double>(n);
        mx = std::max(mx, n);
        mn = std::min(mn, n);
      }
      fmt::print("{}/s from {} messages\n\tmean: {} min: {} max: {}\n", human_bytes(sum / seconds), window.size(),
                 human_bytes(sum / static_cast<double>(window.size())), human_bytes(static_cast<double>(mn)),
                 human_bytes(static_cast<double>(mx)));
      window.clear();
    });
  });
}

int cmd_pub(const std::string& ns, const std::string& name, const std::string& type, const std::string& text,
            const Lookup& lookup, double rate_hz, long count) {
  nlohmann::json json;
  try {
    json = nlohmann::json::parse(text);
  } catch (const nlohmann::json::parse_error& e) {
    fmt::print(stderr, "horus topic pub: the message is not valid JSON: {}\n", e.what());
    return 2;
  }
  const std::string qualified = horus::tools::standard_type(type);
  if (qualified.empty()) {
    fmt::print(stderr, "horus topic pub: '{}' is not a standard horus message; expected one of the {} standard types "
                       "(e.g. Pose2D or horus::msg::Pose2D)\n",
               type, horus::msg::AllMessages::size);
    return 2;
  }
  // The topic's scope where it exists: on this host, else as other hosts announce it; else what
  // the environment and the configuration file choose.
  std::optional<horus::Backend> backend;
  if (auto e = horus::discovery::find_topic(ns, name)) {
    if (e->type_name != qualified) {
      fmt::print(stderr, "horus topic pub: topic '{}' carries {} (layout hash {:016x}); cannot publish {} on it\n", name,
                 e->type_name, e->type_hash, qualified);
      return 1;
    }
    backend = e->scope == "fleet" ? horus::Backend::network(e->transport) : horus::Backend::SharedMemory;
  } else if (const std::string transport = fleet_transport(lookup.transport); !transport.empty()) {
    std::string error;
    if (auto fleet = open_fleet(transport, error)) {
      settle(*fleet, std::chrono::milliseconds(lookup.wait_ms));
      auto all = remote_topics(*fleet);
      if (auto it = all.find(name); it != all.end() && it->second.topic.scope == "fleet")
        backend = horus::Backend::network(it->second.topic.transport);
    }
  }
  std::string error;
  auto writer = horus::tools::open_writer(qualified, name, backend, error);
  if (!writer) {
    fmt::print(stderr, "horus topic pub: {}\n", error);
    return 1;
  }
  // Give discovery a moment: a message sent before anyone matched would reach nobody.
  const auto matched_by = clock_type::now() + std::chrono::seconds(2);
  while (!g_stop.load() && writer->sub_count() == 0 && clock_type::now() < matched_by)
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  const auto period = std::chrono::duration_cast<clock_type::duration>(std::chrono::duration<double>(rate_hz > 0 ? 1.0 / rate_hz : 0));
  auto next = clock_type::now();
  long sent = 0;
  while (!g_stop.load() && (count <= 0 || sent < count)) {
    if (auto err = writer->send_json(json); !err.empty()) {
      fmt::print(stderr, "horus topic pub: {}\n", err);
      return 2;
    }
    ++sent;
    if (rate_hz <= 0 && count <= 0) break;  // once, unless a rate or a count says more
    next += period;
    while (!g_stop.load() && clock_type::now() < next) std::this_thread::sleep_for(std::min<clock_type::duration>(next - clock_type::now(), std::chrono::milliseconds(50)));
  }
  fmt::print("published {} message{} on '{}' ({}, {})\n", sent, sent == 1 ? "" : "s", name, qualified, writer->backend());
  std::this_thread::sleep_for(std::chrono::milliseconds(500));  // reliable writers deliver before they go
  return 0;
}

int cmd_list(const std::string& ns, bool json, bool verbose, const Lookup& lookup, bool local_only, bool all) {
  auto topics = horus::discovery::list_topics(ns, std::chrono::milliseconds(200));
  if (!all)  // the fleet layer's own topics (horus.fleet.*): shown with --all
    std::erase_if(topics, [](const auto& e) { return e.topic.starts_with("horus.fleet."); });
  std::map<std::string, RemoteTopic> remote;
  std::string fleet_error;
  const std::string transport = local_only ? std::string() : fleet_transport(lookup.transport);
  if (!transport.empty()) {
    if (auto fleet = open_fleet(transport, fleet_error)) {
      settle(*fleet, std::chrono::milliseconds(lookup.wait_ms));
      remote = remote_topics(*fleet);
    }
  }
  if (json) {
    auto arr = nlohmann::json::array();
    const std::string self = horus::fleet::host_name();
    for (const auto& e : topics) {
      auto j = entry_json(e);
      j["host"] = self;
      arr.push_back(std::move(j));
    }
    for (const auto& [n, r] : remote) {
      auto j = fleet_topic_json(r.topic);
      j["hosts"] = r.hosts;
      j["remote"] = true;
      arr.push_back(std::move(j));
    }
    fmt::print("{}\n", arr.dump(2));
    return 0;
  }
  if (!fleet_error.empty()) fmt::print(stderr, "horus topic list: other hosts not asked: {}\n", fleet_error);
  if (topics.empty()) {
    fmt::print("no topics in namespace '{}'\n", ns);
  } else {
    fmt::print("{:<36} {:<34} {:<17} {:>9} {:>4} {:>4} {:>10} {:>7} {:>9}\n", "topic", "type", "scope", "size", "pubs",
               "subs", "sent", "drops", "rate Hz");
    for (const auto& e : topics) {
      fmt::print("{:<36} {:<34} {:<17} {:>9} {:>4} {:>4} {:>10} {:>7} {:>9.1f}{}\n", e.topic, e.type_name,
                 scope_text(e), e.serialized ? fmt::format("<={}", e.message_size) : std::to_string(e.message_size),
                 e.publishers, e.subscribers, e.messages_sent, e.dropped, e.rate_hz, e.stale ? "  (stale)" : "");
      if (verbose) {
        fmt::print("    processes: {}\n", processes_text(e));
        if (e.scope == "fleet") fmt::print("    bridge:    {}\n", bridge_text(e));
      }
    }
  }
  if (!remote.empty()) {
    fmt::print("\non other hosts ({}):\n", transport);
    fmt::print("{:<36} {:<34} {:<17} {:>9} {:>4} {:>4} {:>9}  {}\n", "topic", "type", "scope", "size", "pubs", "subs",
               "rate Hz", "hosts");
    for (const auto& [n, r] : remote) {
      const auto& t = r.topic;
      fmt::print("{:<36} {:<34} {:<17} {:>9} {:>4} {:>4} {:>9}  {}\n", n, t.type_name,
                 t.scope == "fleet" ? fmt::format("fleet ({})", t.transport) : t.scope, t.message_size, t.publishers,
                 t.subscribers, t.rate_hz < 0 ? std::string("-") : fmt::format("{:.1f}", t.rate_hz), join(r.hosts));
    }
  }
  return 0;
}

// A topic of other hosts only: what they announce of it.
int info_remote(const std::string& name, const std::string& local_error, const Lookup& lookup) {
  const std::string transport = fleet_transport(lookup.transport);
  std::string error;
  auto fleet = transport.empty() ? nullptr : open_fleet(transport, error);
  if (!fleet) {
    fmt::print(stderr, "horus topic info: {}{}\n", local_error,
               error.empty() ? " (no network backend is configured, so other hosts were not asked)" : "; " + error);
    return 1;
  }
  settle(*fleet, std::chrono::milliseconds(lookup.wait_ms));
  auto all = remote_topics(*fleet);
  auto it = all.find(name);
  if (it == all.end()) {
    std::string known;
    for (const auto& [n, r] : all) known += (known.empty() ? "" : ", ") + n;
    fmt::print(stderr, "horus topic info: {}; nor on the {} other host(s) of the fleet on {}{}\n", local_error,
               fleet->hosts().size(), transport, known.empty() ? "" : " (their topics: " + known + ")");
    return 1;
  }
  const auto& t = it->second.topic;
  fmt::print("topic:        {}\n", name);
  fmt::print("type:         {} (layout hash {:016x})\n", t.type_name, t.type_hash);
  fmt::print("message:      at most {} bytes\n", t.message_size);
  fmt::print("scope:        {}\n", t.scope == "fleet" ? fmt::format("fleet ({})", t.transport) : t.scope);
  fmt::print("hosts:        {}\n", join(it->second.hosts));
  fmt::print("publishers:   {}\nsubscribers:  {}\n", t.publishers, t.subscribers);
  fmt::print("sent:         {}\ndropped:      {}\n", t.messages, t.dropped);
  if (t.rate_hz >= 0) fmt::print("rate:         {:.1f} Hz\n", t.rate_hz);
  fmt::print("signature:    {}\n", t.signature.empty() ? std::string("not announced (cannot be decoded here)") : t.signature);
  return 0;
}

int cmd_info(const std::string& ns, const std::string& name, const Lookup& lookup) {
  auto e = horus::discovery::find_topic(ns, name, std::chrono::milliseconds(500));
  if (!e) return info_remote(name, e.error(), lookup);
  fmt::print("topic:        {}\n", e->topic);
  fmt::print("type:         {} (layout hash {:016x})\n", e->type_name, e->type_hash);
  if (e->pooled)
    fmt::print("message:      large data: a {}-byte descriptor, the bytes in a pool slot of at most {} bytes\n",
               e->message_size, e->pool_slot_bytes);
  else
    fmt::print("message:      {}\n", e->serialized ? fmt::format("serialized, at most {} bytes", e->message_size)
                                                    : fmt::format("{} bytes, fixed size", e->message_size));
  fmt::print("scope:        {}\n", scope_text(*e));
  if (e->scope == "fleet") fmt::print("bridge:       {}\n", bridge_text(*e));
  fmt::print("capacity:     {} slots per publisher\n", e->capacity);
  if (e->pooled)
    fmt::print("pool:         {} slots per publisher, {} pinned now; {} unread messages lost to slot reuse, {} "
               "sends refused (every slot pinned)\n",
               e->pool_slots_per_publisher, e->pool_pinned, e->pool_reused, e->pool_exhausted);
  fmt::print("segment:      /dev/shm/{} ({} bytes)\n", e->segment, e->segment_bytes);
  fmt::print("publishers:   {}\nsubscribers:  {}\n", e->publishers, e->subscribers);
  fmt::print("processes:    {}\n", processes_text(*e));
  fmt::print("sent:         {}\ndropped:      {}\nrate:         {:.1f} Hz\n", e->messages_sent, e->dropped, e->rate_hz);
  if (e->stale) fmt::print("stale:        every process is gone (horus clean removes it)\n");
  return 0;
}

int cmd_config_check(const std::string& file) {
  auto c = horus::Config::load(file);
  if (!c) {
    fmt::print(stderr, "horus config check: {}\n", c.error().message());
    return 1;
  }
  fmt::print("{}: valid; {} rule{}\n", file, c->rules().size(), c->rules().size() == 1 ? "" : "s");
  return 0;
}

std::string from_where(horus::Source s, const horus::TopicChoice& c) {
  if (s == horus::Source::File && c.rule != nullptr)
    return fmt::format("file {}, line {}: rule '{}'", c.config->file(), c.rule->line, c.rule->match);
  if (s == horus::Source::Environment) return "environment (HORUS_BACKEND)";
  if (s == horus::Source::Default) return "default";
  return std::string(horus::to_string(s));
}

int cmd_config_explain(const std::string& topic, const std::string& file) {
  if (auto ok = horus::validate_topic_name(topic); !ok) {
    fmt::print(stderr, "horus config explain: {}\n", ok.error().message());
    return 2;
  }
  std::optional<horus::Config> own;
  const horus::Config* config = nullptr;
  if (!file.empty()) {
    auto c = horus::Config::load(file);
    if (!c) {
      fmt::print(stderr, "horus config explain: {}\n", c.error().message());
      return 1;
    }
    own = std::move(*c);
    config = &*own;
  } else {
    auto c = horus::config_from_environment();
    if (!c) {
      fmt::print(stderr, "horus config explain: {}\n", c.error().message());
      return 1;
    }
    config = *c;
  }
  auto choice = horus::choose(topic, horus::TopicOptions{}, config);
  if (!choice) {
    fmt::print(stderr, "horus config explain: {}\n", choice.error().message());
    return 1;
  }
  const auto& c = *choice;
  fmt::print("topic '{}'{}\n", topic, config != nullptr ? fmt::format(" (configuration file {})", config->file()) : "");
  if (c.rule != nullptr) fmt::print("  rule        '{}' (line {})\n", c.rule->match, c.rule->line);
  else fmt::print("  rule        none matches\n");
  fmt::print("  scope       {:<16} {}\n", horus::to_string(c.backend.scope()), from_where(c.backend_from, c));
  if (horus::is_network(c.backend)) {
    fmt::print("  backend     {:<16} {}\n", c.backend.transport(), from_where(c.backend_from, c));
    if (auto wire = horus::wire_name(c.backend, topic)) fmt::print("  wire name   {}\n", *wire);
  }
  fmt::print("  capacity    {:<16} {}\n", c.capacity ? std::to_string(*c.capacity) : "type default",
             from_where(c.capacity_from, c));
  fmt::print("  reliability {:<16} {}\n", c.reliability ? std::string(horus::net::to_string(*c.reliability)) : "type default",
             from_where(c.reliability_from, c));
  fmt::print("  durability  {:<16} {}\n", c.durability ? std::string(horus::net::to_string(*c.durability)) : "type default",
             from_where(c.durability_from, c));
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"horus: topics on this host and the fleet"};
  app.require_subcommand(1);
  auto* topic = app.add_subcommand("topic", "inspect and publish topics");
  topic->require_subcommand(1);
  Lookup lookup;
  auto fleet_flags = [&](CLI::App* c) {
    c->add_option("--backend", lookup.transport, "network backend of the fleet (default: HORUS_BACKEND's, else the "
                                                 "configuration file's network.backend)");
    c->add_option("--wait", lookup.wait_ms, "milliseconds to wait for other hosts' announcements")
        ->check(CLI::Range(0, 60000));
  };

  bool json = false, verbose = false, local_only = false, all = false;
  auto* list = topic->add_subcommand("list", "list every topic on this host and the fleet's");
  list->add_flag("--json", json, "print JSON");
  list->add_flag("-v,--verbose", verbose, "show the processes of each topic");
  list->add_flag("--local", local_only, "this host's topics only");
  list->add_flag("--all", all, "also the fleet layer's own topics (horus.fleet.*)");
  fleet_flags(list);

  std::string name;
  auto* info = topic->add_subcommand("info", "describe one topic");
  info->add_option("name", name, "topic name")->required();
  fleet_flags(info);

  long count = 0;
  double timeout_s = 0;
  auto* echo = topic->add_subcommand("echo", "print a topic's messages");
  echo->add_option("name", name, "topic name")->required();
  echo->add_flag("--json", json, "one JSON object per line");
  echo->add_option("-n,--count", count, "stop after N messages (exit 1 if fewer arrive before --timeout)");
  echo->add_option("--timeout", timeout_s, "stop after S seconds");
  fleet_flags(echo);

  double duration_s = 0, window_s = 1.0;
  auto* hz = topic->add_subcommand("hz", "measure a topic's rate");
  hz->add_option("name", name, "topic name")->required();
  hz->add_option("--duration", duration_s, "stop after S seconds");
  hz->add_option("--window", window_s, "seconds between reports")->check(CLI::Range(0.05, 3600.0));
  fleet_flags(hz);

  auto* bw = topic->add_subcommand("bw", "measure a topic's bandwidth and message sizes");
  bw->add_option("name", name, "topic name")->required();
  bw->add_option("--duration", duration_s, "stop after S seconds");
  bw->add_option("--window", window_s, "seconds between reports")->check(CLI::Range(0.05, 3600.0));
  fleet_flags(bw);

  std::string type, message;
  double rate_hz = 0;
  auto* pub = topic->add_subcommand("pub", "publish messages (a standard type, given as JSON)");
  pub->add_option("name", name, "topic name")->required();
  pub->add_option("type", type, "message type (Pose2D or horus::msg::Pose2D)")->required();
  pub->add_option("json", message, "the message as JSON, e.g. '{\"x\": 1.5}' (missing fields keep their defaults)")
      ->required();
  pub->add_option("-r,--rate", rate_hz, "messages per second (default: once)")->check(CLI::Range(0.0, 1e6));
  pub->add_option("-n,--count", count, "messages to send (default: 1, or until Ctrl-C with --rate)");
  fleet_flags(pub);

  bool once = false;
  int fleet_wait_ms = 1000;
  auto* fleet = app.add_subcommand("fleet", "the fleet's hosts: state, heartbeat age, RTT, processes, topics");
  fleet->add_flag("--json", json, "print JSON");
  fleet->add_flag("--once", once, "print one snapshot and exit");
  fleet->add_option("--backend", lookup.transport, "network backend (default: HORUS_BACKEND's, else the file's)");
  fleet->add_option("--wait", fleet_wait_ms, "milliseconds to listen before the first snapshot")->check(CLI::Range(0, 60000));
  fleet->add_option("--duration", duration_s, "stop after S seconds");

  auto* clean = app.add_subcommand("clean", "remove shared-memory segments whose processes are all gone");

  auto* config = app.add_subcommand("config", "check and explain the configuration file (HORUS_CONFIG)");
  config->require_subcommand(1);
  std::string config_file;
  auto* check = config->add_subcommand("check", "validate a configuration file");
  check->add_option("file", config_file, "the YAML file")->required();
  auto* explain = config->add_subcommand("explain", "what a topic name gets, and from where");
  explain->add_option("name", name, "topic name")->required();
  explain->add_option("--file", config_file, "the YAML file (default: HORUS_CONFIG's)");

  horus::tools::RecordArgs rec;
  auto* record = app.add_subcommand("record", "record topics into an MCAP file (or an LCM log)");
  record->require_subcommand(0, 1);
  record->add_option("-o,--output", rec.output, "the file to write (FILE.mcap; with --split-size, FILE_1.mcap, ...)");
  record->add_option("--topics", rec.topics, "topic patterns to record ('*' one segment, '**' any): 'robot.**'");
  record->add_flag("--all", rec.all, "record every topic (not the fleet layer's own horus.fleet.*)");
  record->add_option("--duration", rec.duration_s, "stop after S seconds");
  record->add_option("--split-size", rec.split_mb, "start a new file every N MB");
  record->add_option("--compression", rec.compression, "MCAP chunk compression: zstd (default), lz4 or none");
  record->add_option("--format", rec.format, "mcap (default) or lcm (an LCM event log, as lcm-logger writes)");
  record->add_option("--backend", rec.backend, "network backend of the fleet (default: the configuration's)");
  std::string record_file, recover_out;
  auto* record_info = record->add_subcommand("info", "topics, types, counts, duration and size of a recording");
  record_info->add_option("file", record_file, "an MCAP file or an LCM log")->required();
  record_info->add_flag("--json", json, "print JSON");
  auto* recover = record->add_subcommand("recover", "copy what a killed recorder left into a whole file");
  recover->add_option("file", record_file, "the MCAP file or LCM log")->required();
  recover->add_option("-o,--output", recover_out, "the new file (default: FILE.recovered.mcap)");

  horus::tools::PlayArgs play_args;
  auto* play = app.add_subcommand("play", "publish a recording into horus topics with its timing");
  play->add_option("file", play_args.file, "an MCAP file or an LCM log (lcm-logger's too)")->required();
  play->add_option("--rate", play_args.rate, "speed factor (2: twice as fast; 0: as fast as possible)")
      ->check(CLI::Range(0.0, 1e6));
  play->add_option("--start", play_args.start_s, "skip the first S seconds")->check(CLI::Range(0.0, 1e9));
  play->add_flag("--loop", play_args.loop, "start over at the end, until Ctrl-C");
  play->add_option("--topics", play_args.topics, "topic patterns to play (default: all)");
  play->add_option("--remap", play_args.remap, "publish recorded topic OLD into topic NEW (OLD=NEW)");

  horus::tools::BenchArgs bench_args;
  auto* bench = app.add_subcommand("bench", "measure latency and throughput between hosts (ping/pong) or on this one (local)");
  bench->require_subcommand(1);
  auto common_bench = [&](CLI::App* c) {
    c->add_option("--topic-prefix", bench_args.prefix, "topics PREFIX.control, PREFIX.ping.TYPE, PREFIX.pong.TYPE (default bench)");
    c->add_option("--backend", bench_args.backend, "inproc, shm or a network backend (default: what HORUS_BACKEND and HORUS_CONFIG choose)");
    c->add_flag("--spin", bench_args.spin, "poll with pause instead of sleeping in recv_for");
    c->add_flag("-q,--quiet", bench_args.quiet, "no progress line");
  };
  auto payload_bench = [&](CLI::App* c) {
    c->add_option("--type", bench_args.type, "a standard message type (Pose2D, CmdVel, Imu, Image, ...; default Pose2D)");
    c->add_option("--size", bench_args.size, "payload bytes: CompressedImage below 64 KiB, Image (the pool) from 64 KiB; with --type, that type's payload");
  };
  auto* bench_pong = bench->add_subcommand("pong", "answer pings (run it on the other host)");
  common_bench(bench_pong);
  bench_pong->add_flag("--once", bench_args.once, "exit after one ping's run");
  bench_pong->add_option("--cpu", bench_args.cpu, "pin the echo threads to this CPU");
  auto* bench_ping = bench->add_subcommand("ping", "measure round trips to a pong: one-way latency, jitter, losses, throughput");
  common_bench(bench_ping);
  payload_bench(bench_ping);
  bench_ping->add_option("--rate", bench_args.rate, "messages per second (default 1000)");
  bench_ping->add_flag("--flood", bench_args.flood, "send as fast as the window allows");
  bench_ping->add_option("--window", bench_args.window, "messages in flight with --flood (default: half the ring, at most 256)");
  bench_ping->add_option("--duration", bench_args.duration, "seconds measured (default 5)");
  bench_ping->add_option("--count", bench_args.count, "messages measured (instead of --duration)");
  bench_ping->add_option("--warmup", bench_args.warmup, "seconds before measuring; the pong must answer within them (default 2)");
  bench_ping->add_option("--timeout", bench_args.timeout, "an echo later than this many seconds counts as lost (default 1)");
  bench_ping->add_flag("--remote", bench_args.remote, "the pong must be on another host (fail at once if the configuration keeps the topics here)");
  bench_ping->add_option("--json", bench_args.json, "write the summary as JSON to FILE ('-': stdout)");
  bench_ping->add_option("--csv", bench_args.csv, "append the summary as a CSV row to FILE (a header first in a new file; '-': stdout)");
  bench_ping->add_option("--plot", bench_args.plot, "draw the latency histogram and CDF into FILE.png (gnuplot)");
  auto* bench_local = bench->add_subcommand("local", "in-process and cross-process latency and throughput beside this machine's true floor");
  payload_bench(bench_local);
  bench_local->add_option("--duration", bench_args.duration, "seconds per path (default 1)");
  bench_local->add_option("--window", bench_args.window, "messages in flight in the flood rows (default: half the ring)");
  bench_local->add_option("--json", bench_args.json, "write the table as JSON to FILE ('-': stdout)");

  CLI11_PARSE(app, argc, argv);
  if (*record_info) return horus::tools::cmd_record_info(record_file, json);
  if (*recover) return horus::tools::cmd_record_recover(record_file, recover_out);
  if (*check) return cmd_config_check(config_file);
  if (*explain) return cmd_config_explain(name, config_file);
  ::signal(SIGINT, on_signal);
  ::signal(SIGTERM, on_signal);
  if (*fleet) return cmd_fleet(lookup.transport, json, once, fleet_wait_ms, duration_s);
  if (*play) return horus::tools::cmd_play(play_args, g_stop);
  if (*bench_pong) return horus::tools::cmd_bench_pong(bench_args, g_stop);
  if (*bench_ping) return horus::tools::cmd_bench_ping(bench_args, g_stop);
  if (*bench_local) {
    if (bench_local->count("--duration") == 0) bench_args.duration = 1;
    return horus::tools::cmd_bench_local(bench_args, g_stop);
  }

  auto ns = horus::shm::shm_namespace();
  if (!ns) {
    fmt::print(stderr, "horus: {}\n", ns.error().message);
    return 2;
  }
  if (*clean) {
    const auto removed = horus::discovery::clean(*ns);
    for (const auto& t : removed) fmt::print("removed stale topic {} (/dev/shm/horus.{}.{})\n", t, *ns, t);
    fmt::print("{} stale segment{} removed from namespace '{}'\n", removed.size(), removed.size() == 1 ? "" : "s", *ns);
    return 0;
  }
  if (*record) {
    if (rec.output.empty()) {
      fmt::print(stderr, "horus record: name the file to write with -o FILE.mcap\n");
      return 2;
    }
    rec.ns = *ns;
    return horus::tools::cmd_record(rec, g_stop);
  }
  if (*list) return cmd_list(*ns, json, verbose, lookup, local_only, all);
  if (*info) return cmd_info(*ns, name, lookup);
  if (*echo) return cmd_echo(*ns, name, lookup, json, count, timeout_s);
  if (*hz) return cmd_hz(*ns, name, lookup, duration_s, window_s);
  if (*bw) return cmd_bw(*ns, name, lookup, duration_s, window_s);
  if (*pub) return cmd_pub(*ns, name, type, message, lookup, rate_hz, count);
  return 2;
}
