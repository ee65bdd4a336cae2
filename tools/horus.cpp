// horus: the command line.
//
//   horus topic list [--json] [-v]        every topic on this host (HORUS_NAMESPACE)
//   horus topic info NAME                 type, sizes, processes, counts, rate
//   horus topic echo NAME [--json] [-n N] print messages as they arrive (standard types)
//   horus topic hz NAME [--duration S]    live rate with min/max/std of the periods
//   horus clean                           remove segments whose processes are all gone
//   horus config check FILE               validate a configuration file (exit 1 naming the error)
//   horus config explain NAME [--file F]  which rule, scope, backend and QoS a topic gets, and
//                                         from where (code is not known here: environment,
//                                         file, default); the file is F or HORUS_CONFIG's
//
// list/info/clean read the segments without joining them; echo and hz subscribe like any
// other process (they count as a subscriber while they run).
#include <CLI/CLI.hpp>
#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <signal.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "horus/discovery/registry.hpp"
#include "horus/horus.hpp"
#include "horus/json.hpp"
#include "horus/msg/all.hpp"
#include "horus/shm/shm_segment.hpp"
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

int cmd_list(const std::string& ns, bool json, bool verbose) {
  const auto topics = horus::discovery::list_topics(ns, std::chrono::milliseconds(200));
  if (json) {
    auto arr = nlohmann::json::array();
    for (const auto& e : topics) arr.push_back(entry_json(e));
    fmt::print("{}\n", arr.dump(2));
    return 0;
  }
  if (topics.empty()) {
    fmt::print("no topics in namespace '{}'\n", ns);
    return 0;
  }
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
  return 0;
}

int cmd_info(const std::string& ns, const std::string& name) {
  auto e = horus::discovery::find_topic(ns, name, std::chrono::milliseconds(500));
  if (!e) {
    fmt::print(stderr, "horus topic info: {}\n", e.error());
    return 1;
  }
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

// Opens `name` as its standard type and runs body(reader); an error when it is not one.
template <class Body>
int with_topic(const std::string& ns, const std::string& name, const char* cmd, Body&& body) {
  auto e = horus::discovery::find_topic(ns, name);
  if (!e) {
    fmt::print(stderr, "horus topic {}: {}\n", cmd, e.error());
    return 1;
  }
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
               "horus topic {}: topic '{}' carries {}, which is not a standard horus message; this tool decodes "
               "the {} standard types (see messages/README.md)\n",
               cmd, name, e->type_name, horus::msg::AllMessages::size);
    return 1;
  }
  return body(*reader);
}

int cmd_echo(const std::string& ns, const std::string& name, bool json, long count, double timeout_s) {
  return with_topic(ns, name, "echo", [&](horus::tools::TypedReader& reader) {
    long printed = 0;
    const auto deadline = clock_type::now() + std::chrono::duration_cast<clock_type::duration>(
                                                  std::chrono::duration<double>(timeout_s > 0 ? timeout_s : 1e9));
    while (!g_stop.load() && (count <= 0 || printed < count) && clock_type::now() < deadline) {
      if (auto text = reader.recv_text(json)) {
        fmt::print("{}\n", *text);
        std::fflush(stdout);
        ++printed;
      } else {
        // Sleeps until a message comes (at most 100 ms, to see Ctrl-C and the deadline).
        reader.wait(std::min<clock_type::duration>(std::chrono::milliseconds(100), deadline - clock_type::now()));
      }
    }
    return (count > 0 && printed < count) ? 1 : 0;
  });
}

int cmd_hz(const std::string& ns, const std::string& name, double duration_s, double window_s) {
  return with_topic(ns, name, "hz", [&](horus::tools::TypedReader& reader) {
    const auto start = clock_type::now();
    const auto end = start + std::chrono::duration_cast<clock_type::duration>(
                                 std::chrono::duration<double>(duration_s > 0 ? duration_s : 1e9));
    auto next_report = start + std::chrono::duration_cast<clock_type::duration>(std::chrono::duration<double>(window_s));
    std::vector<double> periods;
    clock_type::time_point last{};
    bool have_last = false;
    std::uint64_t total = 0;
    while (!g_stop.load() && clock_type::now() < end) {
      bool got = false;
      while (reader.recv_any()) {
        const auto now = clock_type::now();
        if (have_last) periods.push_back(std::chrono::duration<double>(now - last).count());
        last = now;
        have_last = true;
        ++total;
        got = true;
      }
      if (!got) reader.wait(std::min<clock_type::duration>(std::chrono::milliseconds(100), next_report - clock_type::now()));
      if (clock_type::now() >= next_report) {
        next_report += std::chrono::duration_cast<clock_type::duration>(std::chrono::duration<double>(window_s));
        if (periods.empty()) {
          fmt::print("no new messages\n");
        } else {
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
          fmt::print("average rate: {:.3f} Hz\n\tmin: {:.6f}s max: {:.6f}s std dev: {:.6f}s window: {}\n", 1.0 / mean,
                     mn, mx, sd, periods.size() + 1);
          periods.clear();
        }
        std::fflush(stdout);
      }
    }
    fmt::print("received {} messages\n", total);
    return 0;
  });
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
  CLI::App app{"horus: topics on this host"};
  app.require_subcommand(1);
  auto* topic = app.add_subcommand("topic", "inspect topics");
  topic->require_subcommand(1);

  bool json = false, verbose = false;
  auto* list = topic->add_subcommand("list", "list every topic on this host");
  list->add_flag("--json", json, "print JSON");
  list->add_flag("-v,--verbose", verbose, "show the processes of each topic");

  std::string name;
  auto* info = topic->add_subcommand("info", "describe one topic");
  info->add_option("name", name, "topic name")->required();

  long count = 0;
  double timeout_s = 0;
  auto* echo = topic->add_subcommand("echo", "print a topic's messages");
  echo->add_option("name", name, "topic name")->required();
  echo->add_flag("--json", json, "one JSON object per line");
  echo->add_option("-n,--count", count, "stop after N messages (exit 1 if fewer arrive before --timeout)");
  echo->add_option("--timeout", timeout_s, "stop after S seconds");

  double duration_s = 0, window_s = 1.0;
  auto* hz = topic->add_subcommand("hz", "measure a topic's rate");
  hz->add_option("name", name, "topic name")->required();
  hz->add_option("--duration", duration_s, "stop after S seconds");
  hz->add_option("--window", window_s, "seconds between reports")->check(CLI::Range(0.05, 3600.0));

  auto* clean = app.add_subcommand("clean", "remove shared-memory segments whose processes are all gone");

  auto* config = app.add_subcommand("config", "check and explain the configuration file (HORUS_CONFIG)");
  config->require_subcommand(1);
  std::string config_file;
  auto* check = config->add_subcommand("check", "validate a configuration file");
  check->add_option("file", config_file, "the YAML file")->required();
  auto* explain = config->add_subcommand("explain", "what a topic name gets, and from where");
  explain->add_option("name", name, "topic name")->required();
  explain->add_option("--file", config_file, "the YAML file (default: HORUS_CONFIG's)");

  CLI11_PARSE(app, argc, argv);
  if (*check) return cmd_config_check(config_file);
  if (*explain) return cmd_config_explain(name, config_file);
  ::signal(SIGINT, on_signal);
  ::signal(SIGTERM, on_signal);

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
  if (*list) return cmd_list(*ns, json, verbose);
  if (*info) return cmd_info(*ns, name);
  if (*echo) return cmd_echo(*ns, name, json, count, timeout_s);
  if (*hz) return cmd_hz(*ns, name, duration_s, window_s);
  return 2;
}
