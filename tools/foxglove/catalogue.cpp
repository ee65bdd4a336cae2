#include "catalogue.hpp"

#include <unistd.h>

#include <algorithm>

#include <fmt/format.h>

#include "../ros2_cmd.hpp"
#include "../typed_reader.hpp"
#include "horus/ros2/interface.hpp"
#include "horus/ros2/names.hpp"
#include "horus/fleet_messages.hpp"
#include "horus/idlgen/emit.hpp"
#include "horus/names.hpp"
#include "horus/transport_registry.hpp"
#include "horus/wire/dynamic.hpp"
#include "schemas.hpp"

namespace horus::tools::fox {
namespace {

using json = nlohmann::json;

std::string graph_id(const std::string& host, std::uint32_t pid) { return fmt::format("{}/pid {}", host, pid); }

// A fleet host's row on the status page.
json host_json(const FleetHost& h) {
  return {{"name", h.name},
          {"state", h.self ? "this host" : std::string(to_string(h.state))},
          {"self", h.self},
          {"age_ms", h.heartbeat_age.count()},
          {"rtt_us", h.rtt ? json(h.rtt->count()) : json(nullptr)},
          {"clock_offset_us", h.clock_offset ? json(h.clock_offset->count()) : json(nullptr)},
          {"loss", h.loss},
          {"topics", h.topics.size()},
          {"processes", h.processes.size()}};
}

}  // namespace

Catalogue::Catalogue(std::vector<std::string> patterns, const std::string& ns)
    : patterns_(std::move(patterns)), scanner_(ns), host_(fleet::host_name()) {}

bool Catalogue::wanted(const std::string& name) const {
  if (patterns_.empty()) return !horus::fleet::is_fleet_layer_topic(name);
  return std::any_of(patterns_.begin(), patterns_.end(), [&](const auto& p) { return topic_pattern_matches(p, name); });
}

// The channels of one topic: as it is, and converted when Foxglove draws its type.
void Catalogue::add_channels(std::map<std::string, Desc>& out, Desc d) {
  if (!standard_type(d.type).empty()) {
    d.remote_raw = false;
  } else if (!d.via.empty() && !d.signature.empty()) {
    d.remote_raw = true;
  } else {
    unserved_.insert(
        {d.horus_topic, d.type + (d.via.empty() ? " is not a standard message and the topic stays on this host (only "
                                                  "fleet topics are read through their signature)"
                                                : " announced no signature")});
    return;
  }
  const auto* info = d.via.empty() ? nullptr : net::find_transport(d.via);
  const bool lcm_raw = d.remote_raw && info != nullptr && info->format == net::WireFormat::Lcm;
  d.adv.topic = d.horus_topic;
  d.adv.schema_name = d.type;
  if (lcm_raw) {  // LCM's bytes are not CDR: served as JSON through the signature
    d.adv.encoding = "json";
    d.adv.schema_encoding = "jsonschema";
    d.adv.schema = json{{"title", d.type}, {"type", "object"}}.dump();
  } else {
    d.adv.encoding = "cdr";
    d.adv.schema_encoding = "omgidl";
    auto& idl = idl_cache_[d.type + "|" + d.signature];
    if (idl.empty()) {
      if (auto dyn = wire::parse_signature(d.signature, d.hash); dyn) {
        try {
          idl = idlgen::omgidl_schema(*dyn);
        } catch (const std::exception& e) {
          unserved_.insert({d.horus_topic, std::string("no OMG IDL for its type: ") + e.what()});
          return;
        }
      } else {
        unserved_.insert({d.horus_topic, "its type signature does not parse: " + dyn.error()});
        return;
      }
    }
    d.adv.schema = idl;
  }
  out[d.adv.topic] = d;
  if (const auto* fs = foxglove_schema_of(d.type); fs != nullptr && !d.remote_raw) {
    Desc c = d;
    c.converted = true;
    c.adv.topic = d.horus_topic + std::string(kConvertedSuffix);
    c.adv.schema_name = std::string(fs->name);
    c.adv.schema = std::string(fs->idl);
    c.adv.encoding = "cdr";
    c.adv.schema_encoding = "omgidl";
    out[c.adv.topic] = std::move(c);
  }
}

// The messages a topic sent per second since the last scan at least 0.9 s old (-1: not known
// yet); `counts` keeps the count and time the next scan measures from.
double Catalogue::rate_of(const discovery::TopicEntry& t, Clock::time_point now,
                          std::map<std::string, std::pair<std::uint64_t, Clock::time_point>>& counts) {
  double rate = -1;
  if (auto it = last_counts_.find(t.topic); it != last_counts_.end()) {
    const double dt = std::chrono::duration<double>(now - it->second.second).count();
    if (dt >= 0.9) {
      rate = static_cast<double>(t.messages_sent - std::min(t.messages_sent, it->second.first)) / dt;
      counts[t.topic] = {t.messages_sent, now};
      rates_[t.topic] = rate;
    } else {
      counts[t.topic] = it->second;
      rate = rates_.contains(t.topic) ? rates_[t.topic] : -1;
    }
  } else {
    counts[t.topic] = {t.messages_sent, now};
  }
  return rate;
}

// This host's topics that another process uses: channels, graph, status rows (`local_names`).
void Catalogue::scan_local(Scan& r, std::set<std::string>& local_names) {
  auto& graph = r.graph;
  const auto me = static_cast<std::uint32_t>(::getpid());
  std::map<std::string, std::pair<std::uint64_t, Clock::time_point>> counts;
  const auto now = Clock::now();
  for (const auto& t : scanner_.scan()) {
    std::vector<std::string> pubs, subs;
    bool others = false;
    for (const auto& p : t.processes) {
      if (!p.alive || static_cast<std::uint32_t>(p.pid) == me) continue;
      others = true;
      if (p.publishers) pubs.push_back(graph_id(host_, static_cast<std::uint32_t>(p.pid)));
      if (p.subscribers) subs.push_back(graph_id(host_, static_cast<std::uint32_t>(p.pid)));
    }
    if (!others || !wanted(t.topic)) continue;
    local_names.insert(t.topic);
    if (!pubs.empty()) graph.published.push_back({t.topic, pubs});
    if (!subs.empty()) graph.subscribed.push_back({t.topic, subs});
    Desc d;
    d.horus_topic = t.topic;
    d.type = t.type_name;
    d.hash = t.type_hash;
    d.signature = t.signature;
    add_channels(r.channels, std::move(d));
    // rate: the sent count since the last scan that is at least 0.9 s old
    const double rate = rate_of(t, now, counts);
    r.topics.push_back({{"name", t.topic},
                        {"type", t.type_name},
                        {"scope", t.scope},
                        {"hosts", {host_}},
                        {"publishers", t.publishers},
                        {"subscribers", t.subscribers},
                        {"rate_hz", rate},
                        {"message_bytes", t.message_size},
                        {"bandwidth_bps", rate < 0 ? -1.0 : rate * t.message_size},
                        {"dropped", t.dropped}});
  }
  last_counts_ = std::move(counts);
}

// The fleet's hosts, and the fleet topics of the other hosts: channels (those not on this host),
// graph, status rows (one per topic, merged into this host's row of the same name).
void Catalogue::scan_fleet(Scan& r, const Fleet& fleet, const std::set<std::string>& local_names) {
  auto& graph = r.graph;
  std::map<std::string, json> remote_topics;
  for (const auto& h : fleet.hosts()) {
    r.hosts.push_back(host_json(h));
    if (h.self || h.state == HostState::Lost) continue;
    for (const auto& t : h.topics) {
      if (t.scope != "fleet" || !wanted(t.name)) continue;
      if (t.publishers) graph.published.push_back({t.name, {h.name}});
      if (t.subscribers) graph.subscribed.push_back({t.name, {h.name}});
      auto& rt = remote_topics[t.name];
      if (rt.is_null())
        rt = {{"name", t.name},        {"type", t.type_name}, {"scope", "fleet"}, {"hosts", json::array()},
              {"publishers", 0},       {"subscribers", 0},    {"rate_hz", -1.0},  {"message_bytes", t.message_size},
              {"bandwidth_bps", -1.0}, {"dropped", 0}};
      rt["hosts"].push_back(h.name);
      rt["publishers"] = rt["publishers"].get<std::uint32_t>() + t.publishers;
      rt["subscribers"] = rt["subscribers"].get<std::uint32_t>() + t.subscribers;
      if (t.rate_hz >= 0 && t.publishers > 0) {
        rt["rate_hz"] = std::max(rt["rate_hz"].get<double>(), 0.0) + t.rate_hz;
        rt["bandwidth_bps"] = rt["rate_hz"].get<double>() * t.message_size;
      }
      if (local_names.contains(t.name) || r.channels.contains(t.name)) continue;
      Desc d;
      d.horus_topic = t.name;
      d.type = t.type_name;
      d.hash = t.type_hash;
      d.signature = t.signature;
      d.via = t.transport;
      add_channels(r.channels, std::move(d));
    }
  }
  for (auto& [name, rt] : remote_topics) {
    bool merged = false;
    for (auto& lt : r.topics)
      if (lt["name"] == name) {
        for (const auto& h : rt["hosts"]) lt["hosts"].push_back(h);
        merged = true;
      }
    if (!merged) r.topics.push_back(std::move(rt));
  }
}

// The domain's ROS 2 topics that have a publisher and a type of the common interfaces horus
// knows: each a channel under its ROS 2 name in its ROS 2 schema (ros2msg, as rosbag2 writes it),
// its samples passed on as they came (CDR). A horus topic mapped onto ROS 2 is also one of them:
// served twice, in horus's schema under its horus name and in ROS 2's under its ROS 2 name.
void Catalogue::scan_ros2(Scan& r, const net::Transport& transport) {
  const auto& types = ros2::Interfaces::standard();
  for (const auto& [name, t] : ros2_topics(transport)) {
    if (t.publishers == 0 || !(patterns_.empty() || wanted(ros2::horus_topic_of(name)))) continue;
    auto definition = types.message_definition(t.type);
    if (!definition) {
      unserved_.insert({name, "a ROS 2 topic of type " + t.type + ", which is not one of the ROS 2 interfaces horus "
                              "reads (docs/ROS2.md)"});
      continue;
    }
    Desc d;
    d.horus_topic = name;
    d.type = t.type;
    d.via = std::string(transport.name());
    d.ros2_type = t.type;
    d.adv.topic = name;
    d.adv.schema_name = t.type;
    d.adv.schema_encoding = "ros2msg";
    d.adv.schema = std::move(*definition);
    d.adv.encoding = "cdr";
    r.channels[name] = std::move(d);
    r.topics.push_back({{"name", name},       {"type", t.type},        {"scope", "ros2"},        {"hosts", json::array()},
                        {"publishers", t.publishers}, {"subscribers", t.subscribers}, {"rate_hz", -1.0},
                        {"message_bytes", 0}, {"bandwidth_bps", -1.0}, {"dropped", 0}});
  }
}

Scan Catalogue::scan(Fleet* fleet, net::Transport* ros2) {
  Scan r;
  std::set<std::string> local_names;
  scan_local(r, local_names);
  if (ros2 != nullptr) scan_ros2(r, *ros2);
  if (fleet) {
    scan_fleet(r, *fleet, local_names);
  } else {
    r.hosts.push_back({{"name", host_},
                       {"state", "this host"},
                       {"self", true},
                       {"age_ms", 0},
                       {"rtt_us", nullptr},
                       {"clock_offset_us", nullptr},
                       {"loss", -1},
                       {"topics", r.topics.size()},
                       {"processes", nullptr}});
  }
  std::sort(r.graph.published.begin(), r.graph.published.end(), [](auto& a, auto& b) { return a.name < b.name; });
  std::sort(r.graph.subscribed.begin(), r.graph.subscribed.end(), [](auto& a, auto& b) { return a.name < b.name; });

  return r;
}

}  // namespace horus::tools::fox
