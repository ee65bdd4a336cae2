// horus topic list / info / echo / hz / bw / pub (topic_cmd.hpp): this host's topics read from
// their segments (horus/discovery/registry.hpp) and, with a network backend configured, the
// topics other hosts announce (fleet_cmd.hpp); echo, hz and bw read a topic through its standard
// type (typed_reader.hpp) or, for a topic of other hosts only, its announced signature
// (remote_reader.hpp).
#include "topic_cmd.hpp"

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <stdlib.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "fleet_cmd.hpp"
#include "horus/discovery/registry.hpp"
#include "horus/fleet.hpp"
#include "horus/fleet_messages.hpp"
#include "horus/horus.hpp"
#include "horus/msg/all.hpp"
#include "remote_reader.hpp"
#include "ros2_cmd.hpp"
#include "typed_reader.hpp"

namespace horus::tools {

namespace {

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
                   {"budget_dropped", e.budget_dropped},
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
  return fmt::format("{}; {} claim(s); exported {}, imported {}, dropped {}{}; remote: {} writer(s), {} reader(s)",
                     e.bridge_pid != 0 ? fmt::format("pid {}", e.bridge_pid) : std::string("none now"),
                     e.bridge_claims, e.exported, e.imported, e.bridge_dropped,
                     e.budget_dropped != 0 ? fmt::format(", budget dropped {}", e.budget_dropped) : std::string(),
                     e.remote_publishers, e.remote_subscribers);
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

using TopicLookup = std::expected<horus::discovery::TopicEntry, std::string>;

// A reader of a topic of this host (its standard type); null, with the error printed, when it
// cannot be read.
std::unique_ptr<horus::tools::TypedReader> open_local_reader(const horus::discovery::TopicEntry& entry,
                                                             const std::string& name, const char* cmd) {
  std::string error;
  // A fleet topic is opened as one (a host topic of the same name would be a scope conflict);
  // this short-lived observer never bridges it (HORUS_BRIDGE=0).
  horus::Backend backend = horus::Backend::SharedMemory;
  if (entry.scope == "fleet") {
    backend = horus::Backend::network(entry.transport);
    ::setenv("HORUS_BRIDGE", "0", 1);
  }
  auto reader = horus::tools::open_reader(entry.type_name, name, backend, error);
  if (!reader && !error.empty()) {
    fmt::print(stderr, "horus topic {}: {}\n", cmd, error);
    return nullptr;
  }
  if (!reader) {
    fmt::print(stderr,
               "horus topic {}: topic '{}' carries {} (layout hash {:016x}, {} bytes), which is not a standard horus "
               "message; this tool decodes the {} standard types on this host, and any type of a fleet topic "
               "that another host announces\n",
               cmd, name, entry.type_name, entry.type_hash, entry.message_size, horus::msg::AllMessages::size);
    return nullptr;
  }
  return reader;
}

// Waits for `name` among other hosts' topics (or, asked to wait for it, on this host: then `e`
// holds it and nothing is returned).
std::optional<RemoteTopic> wait_for_remote(const horus::Fleet& fleet, const std::string& ns, const std::string& name,
                                           const Lookup& lookup, const std::atomic<bool>& stop, TopicLookup& e) {
  std::optional<RemoteTopic> found;
  const auto deadline =
      clock_type::now() + std::max<clock_type::duration>(std::chrono::milliseconds(lookup.wait_ms), lookup.appear_wait);
  while (!found && !stop.load() && clock_type::now() < deadline) {
    auto all = remote_topics(fleet);
    if (auto it = all.find(name); it != all.end()) {
      found = it->second;
    } else if (lookup.appear_wait.count() > 0 && (e = horus::discovery::find_topic(ns, name))) {
      return std::nullopt;
    } else {
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
  }
  return found;
}

// The error of a topic found nowhere, with the topics that exist here and on the fleet.
void print_no_topic(const horus::Fleet& fleet, const std::string& ns, const std::string& name,
                    const std::string& transport, const char* cmd) {
  std::string known;
  for (const auto& t : horus::discovery::list_topics(ns))
    if (!horus::fleet::is_fleet_layer_topic(t.topic)) known += (known.empty() ? "" : ", ") + t.topic;
  for (const auto& [n, r] : remote_topics(fleet)) known += (known.empty() ? "" : ", ") + n + " (" + join(r.hosts) + ")";
  fmt::print(stderr, "horus topic {}: no topic '{}' on this host nor on the {} host(s) of the fleet on {}{}\n", cmd,
             name, fleet.hosts().size(), transport, known.empty() ? " (no topics at all)" : "; topics: " + known);
}

// A reader of another host's fleet topic, through the type signature announced with it; null,
// with the error printed, when it cannot be read here.
std::unique_ptr<horus::tools::RemoteReader> open_remote_reader(const RemoteTopic& found, const std::string& name,
                                                               const char* cmd) {
  const auto& t = found.topic;
  if (t.scope != "fleet") {
    fmt::print(stderr, "horus topic {}: topic '{}' is a {} topic of {}: its messages never leave that host\n", cmd, name,
               t.scope, join(found.hosts));
    return nullptr;
  }
  if (t.signature.empty()) {
    fmt::print(stderr,
               "horus topic {}: cannot decode topic '{}': {} (layout hash {:016x}, {} bytes) was announced without "
               "its type signature\n",
               cmd, name, t.type_name, t.type_hash, t.message_size);
    return nullptr;
  }
  std::string error;
  auto reader = horus::tools::RemoteReader::open(name, t.transport, t.type_name, t.type_hash, t.signature, error);
  if (!reader) {
    fmt::print(stderr, "horus topic {}: topic '{}' ({}, layout hash {:016x}, {} bytes): {}\n", cmd, name, t.type_name,
               t.type_hash, t.message_size, error);
    return nullptr;
  }
  return reader;
}

// Opens `name` on this host (its standard type) or, when it is not here and a network backend
// is configured, where other hosts announce it; runs body(source). Errors name what exists.
template <class Body>
int with_topic(const std::string& ns, const std::string& name, const char* cmd, const Lookup& lookup,
               const std::atomic<bool>& stop, Body&& body) {
  // A ROS 2 name ("/scan"): the ROS 2 topic of the domain, whoever publishes it.
  if (name.starts_with('/')) {
    auto reader = open_ros2_topic(name, lookup, cmd, stop);
    if (!reader) return 1;
    RemoteSource src(std::move(reader));
    return body(static_cast<Source&>(src));
  }
  // A topic of this host: read through its segment.
  auto local = [&](const horus::discovery::TopicEntry& entry) -> int {
    auto reader = open_local_reader(entry, name, cmd);
    if (!reader) return 1;
    LocalSource src(std::move(reader));
    return body(static_cast<Source&>(src));
  };
  TopicLookup e = horus::discovery::find_topic(ns, name);
  if (e) return local(*e);
  // Asked to wait (--wait, or echo's --timeout): the topic may appear meanwhile, here or (with a
  // network backend) on another host.
  if (lookup.appear_wait.count() > 0)
    fmt::print(stderr, "horus topic {}: no topic '{}' yet; waiting up to {:.1f} s for it to appear\n", cmd, name,
               static_cast<double>(lookup.appear_wait.count()) / 1000.0);
  const std::string transport = fleet_transport(lookup.transport);
  if (transport.empty()) {
    for (const auto by = clock_type::now() + lookup.appear_wait; !e && !stop.load() && clock_type::now() < by;) {
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
      e = horus::discovery::find_topic(ns, name);
    }
    if (e) return local(*e);
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
  const auto found = wait_for_remote(*fleet, ns, name, lookup, stop, e);
  if (!found && e) {
    fleet.reset();
    return local(*e);
  }
  if (!found) {
    print_no_topic(*fleet, ns, name, transport, cmd);
    return 1;
  }
  auto reader = open_remote_reader(*found, name, cmd);
  if (!reader) return 1;
  fleet.reset();  // the reader has its own endpoint
  RemoteSource src(std::move(reader));
  return body(static_cast<Source&>(src));
}

clock_type::time_point deadline_after(double seconds) {
  return clock_type::now() + std::chrono::duration_cast<clock_type::duration>(
                                 std::chrono::duration<double>(seconds > 0 ? seconds : 1e9));
}

// Receives for `duration_s` and calls report(values, seconds) every `window_s` with what arrived
// in that window: each message's arrival time and size.
template <class Report>
int sample_topic(Source& src, double duration_s, double window_s, const std::atomic<bool>& stop, Report&& report) {
  const auto end = deadline_after(duration_s);
  const auto step = std::chrono::duration_cast<clock_type::duration>(std::chrono::duration<double>(window_s));
  auto next_report = clock_type::now() + step;
  std::vector<std::pair<clock_type::time_point, std::size_t>> window;
  std::uint64_t total = 0;
  while (!stop.load() && clock_type::now() < end) {
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

std::string human_bytes(double b) {
  if (b >= 1e6) return fmt::format("{:.2f} MB", b / 1e6);
  if (b >= 1e3) return fmt::format("{:.2f} KB", b / 1e3);
  return fmt::format("{:.0f} B", b);
}

// A topic of other hosts only: what they announce of it.
int info_remote(const std::string& name, const std::string& local_error, const Lookup& lookup,
                const std::atomic<bool>& stop) {
  const std::string transport = fleet_transport(lookup.transport);
  std::string error;
  auto fleet = transport.empty() ? nullptr : open_fleet(transport, error);
  if (!fleet) {
    fmt::print(stderr, "horus topic info: {}{}\n", local_error,
               error.empty() ? " (no network backend is configured, so other hosts were not asked)" : "; " + error);
    return 1;
  }
  settle(*fleet, std::chrono::milliseconds(lookup.wait_ms), stop);
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

}  // namespace

int cmd_echo(const std::string& ns, const std::string& name, const Lookup& lookup, bool json, long count,
             double timeout_s, const std::atomic<bool>& stop) {
  const auto deadline = deadline_after(timeout_s);  // from the start: waiting for the topic counts
  return with_topic(ns, name, "echo", lookup, stop, [&](Source& src) {
    long printed = 0;
    while (!stop.load() && (count <= 0 || printed < count) && clock_type::now() < deadline) {
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

int cmd_hz(const std::string& ns, const std::string& name, const Lookup& lookup, double duration_s, double window_s,
           const std::atomic<bool>& stop) {
  return with_topic(ns, name, "hz", lookup, stop, [&](Source& src) {
    std::optional<clock_type::time_point> last;
    return sample_topic(src, duration_s, window_s, stop, [&](auto& window, double) {
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

int cmd_bw(const std::string& ns, const std::string& name, const Lookup& lookup, double duration_s, double window_s,
           const std::atomic<bool>& stop) {
  return with_topic(ns, name, "bw", lookup, stop, [&](Source& src) {
    return sample_topic(src, duration_s, window_s, stop, [&](auto& window, double seconds) {
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
            const Lookup& lookup, double rate_hz, long count, const std::atomic<bool>& stop) {
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
      settle(*fleet, std::chrono::milliseconds(lookup.wait_ms), stop);
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
  while (!stop.load() && writer->sub_count() == 0 && clock_type::now() < matched_by)
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  const auto period = std::chrono::duration_cast<clock_type::duration>(std::chrono::duration<double>(rate_hz > 0 ? 1.0 / rate_hz : 0));
  auto next = clock_type::now();
  long sent = 0;
  while (!stop.load() && (count <= 0 || sent < count)) {
    if (auto err = writer->send_json(json); !err.empty()) {
      fmt::print(stderr, "horus topic pub: {}\n", err);
      return 2;
    }
    ++sent;
    if (rate_hz <= 0 && count <= 0) break;  // once, unless a rate or a count says more
    next += period;
    while (!stop.load() && clock_type::now() < next) std::this_thread::sleep_for(std::min<clock_type::duration>(next - clock_type::now(), std::chrono::milliseconds(50)));
  }
  fmt::print("published {} message{} on '{}' ({}, {})\n", sent, sent == 1 ? "" : "s", name, qualified, writer->backend());
  std::this_thread::sleep_for(std::chrono::milliseconds(500));  // reliable writers deliver before they go
  return 0;
}

int cmd_list(const std::string& ns, bool json, bool verbose, const Lookup& lookup, bool local_only, bool all,
             const std::atomic<bool>& stop) {
  auto topics = horus::discovery::list_topics(ns, lookup.rate_window);
  if (!all)  // the fleet layer's own topics (horus.fleet.*): shown with --all
    std::erase_if(topics, [](const auto& e) { return horus::fleet::is_fleet_layer_topic(e.topic); });
  std::map<std::string, RemoteTopic> remote;
  std::string fleet_error;
  const std::string transport = local_only ? std::string() : fleet_transport(lookup.transport);
  if (!transport.empty()) {
    if (auto fleet = open_fleet(transport, fleet_error)) {
      settle(*fleet, std::chrono::milliseconds(lookup.wait_ms), stop);
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
      fmt::print("{:<36} {:<34} {:<17} {:>9} {:>4} {:>4} {:>10} {:>7} {:>9}{}\n", e.topic, e.type_name, scope_text(e),
                 e.serialized ? fmt::format("<={}", e.message_size) : std::to_string(e.message_size), e.publishers,
                 e.subscribers, e.messages_sent, e.dropped,
                 e.rate_hz < 0 ? std::string("-") : fmt::format("{:.1f}", e.rate_hz),  // --window 0: not measured
                 e.stale ? "  (stale)" : "");
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

int cmd_info(const std::string& ns, const std::string& name, const Lookup& lookup, const std::atomic<bool>& stop) {
  auto e = horus::discovery::find_topic(ns, name, lookup.rate_window);
  if (!e) return info_remote(name, e.error(), lookup, stop);
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
  fmt::print("sent:         {}\ndropped:      {}\n", e->messages_sent, e->dropped);
  if (e->rate_hz >= 0) fmt::print("rate:         {:.1f} Hz\n", e->rate_hz);
  if (e->stale) fmt::print("stale:        every process is gone (horus clean removes it)\n");
  return 0;
}

}  // namespace horus::tools
