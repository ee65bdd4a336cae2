// horus topic list --ros2, and ROS 2 topics read by their ROS 2 name (ros2_cmd.hpp): the
// transport's discovery gives every endpoint of the domain (Transport::remote_endpoints), each
// ROS 2 one on a DDS topic "rt/<name>" of a type "<pkg>::msg::dds_::<Name>_"; the nodes come from
// ros_discovery_info (rmw_dds_common/msg/ParticipantEntitiesInfo), which every ROS 2 participant
// (and every horus process with a mapped topic) publishes: each node with the GIDs of its
// readers and writers.
#include "ros2_cmd.hpp"

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <chrono>
#include <cstdio>
#include <map>
#include <mutex>
#include <set>
#include <thread>
#include <vector>

#include "fleet_cmd.hpp"
#include "horus/network.hpp"
#include "horus/ros2/dynamic.hpp"
#include "horus/ros2/interface.hpp"
#include "horus/ros2/names.hpp"
#include "horus/transport_registry.hpp"

namespace horus::tools {

namespace {

using Clock = std::chrono::steady_clock;
constexpr const char* kGraphType = "rmw_dds_common/msg/ParticipantEntitiesInfo";

net::Guid gid_of(const nlohmann::json& gid) {
  net::Guid g{};
  const auto& data = gid.at("data");
  for (std::size_t i = 0; i < g.size() && i < data.size(); ++i) g[i] = data[i].get<std::uint8_t>();
  return g;
}

// The nodes of the domain as ros_discovery_info says, by participant.
class GraphReader final : public net::Listener {
 public:
  struct Node {
    std::string name;  // "/robot1/planner"
    std::set<net::Guid> readers, writers;
  };

  bool open(net::Transport& transport, std::string& error) {
    const auto& types = ros2::Interfaces::standard();
    net::EndpointSpec spec;
    spec.topic = spec.wire_topic = "ros_discovery_info";
    spec.type_name = ros2::parse_type_name(kGraphType)->dds();
    spec.user_data = ros2::user_data_of(types.type_hash(kGraphType).value_or(""));
    spec.qos.reliability = net::Reliability::Reliable;
    spec.qos.durability = net::Durability::TransientLocal;  // each participant's last state
    spec.qos.depth = 64;
    spec.send = false;
    auto ep = transport.open(spec, *this);
    if (!ep) {
      error = ep.error().message();
      return false;
    }
    endpoint_ = std::move(*ep);
    return true;
  }
  ~GraphReader() { endpoint_.reset(); }

  void on_sample(const net::Sample& s) override {
    auto j = ros2::decode_json(ros2::Interfaces::standard(), kGraphType, s.body, s.little_endian);
    if (!j) return;  // not what rmw_dds_common publishes: nothing to list
    try {
      std::vector<Node> nodes;
      for (const auto& n : (*j)["node_entities_info_seq"]) {
        Node node;
        const std::string ns = n["node_namespace"];
        node.name = (ns == "/" ? "" : ns) + "/" + n["node_name"].get<std::string>();
        for (const auto& g : n["reader_gid_seq"]) node.readers.insert(gid_of(g));
        for (const auto& g : n["writer_gid_seq"]) node.writers.insert(gid_of(g));
        nodes.push_back(std::move(node));
      }
      std::lock_guard lock(mutex_);
      by_participant_[gid_of((*j)["gid"])] = std::move(nodes);
    } catch (const std::exception&) {
    }
  }
  void on_error(std::string_view) override {}

  // The node holding endpoint `guid` (a writer when `publisher`), or empty.
  std::string node_of(const net::Guid& guid, bool publisher) const {
    std::lock_guard lock(mutex_);
    for (const auto& [participant, nodes] : by_participant_)
      for (const auto& n : nodes)
        if ((publisher ? n.writers : n.readers).contains(guid)) return n.name;
    return {};
  }

 private:
  std::unique_ptr<net::Endpoint> endpoint_;
  mutable std::mutex mutex_;
  std::map<net::Guid, std::vector<Node>> by_participant_;
};

// The domain's ROS 2 topics ("rt/..."), by ROS 2 name, with their nodes when `graph` is given.
std::map<std::string, Ros2TopicInfo> topics_with_nodes(const net::Transport& transport, const GraphReader* graph) {
  std::map<std::string, Ros2TopicInfo> rows;
  for (const auto& r : transport.remote_endpoints()) {
    if (!r.wire_topic.starts_with("rt/")) continue;
    Ros2TopicInfo& row = rows[r.wire_topic.substr(2)];
    row.dds_type = r.type_name;
    row.type = ros2::ros_type_of_dds(r.type_name);
    if (row.type.empty()) row.type = r.type_name;
    if (!r.type_hash.empty()) row.type_hash = r.type_hash;
    ++(r.publisher ? row.publishers : row.subscribers);
    if (graph == nullptr) continue;
    if (auto node = graph->node_of(r.guid, r.publisher); !node.empty())
      (r.publisher ? row.publishing_nodes : row.subscribing_nodes).insert(node);
  }
  return rows;
}

std::string joined(const std::set<std::string>& names) {
  std::string out;
  for (const auto& n : names) out += (out.empty() ? "" : ", ") + n;
  return out;
}

void print_rows(const std::map<std::string, Ros2TopicInfo>& rows, bool json) {
  if (json) {
    auto topics = nlohmann::json::array();
    for (const auto& [name, r] : rows)
      topics.push_back({{"name", name},
                        {"type", r.type},
                        {"dds_type", r.dds_type},
                        {"type_hash", r.type_hash},
                        {"publishers", r.publishers},
                        {"subscribers", r.subscribers},
                        {"publishing_nodes", r.publishing_nodes},
                        {"subscribing_nodes", r.subscribing_nodes}});
    fmt::print("{}\n", nlohmann::json{{"topics", topics}}.dump(2));
    return;
  }
  if (rows.empty()) {
    fmt::print("no ROS 2 topics on this domain\n");
    return;
  }
  fmt::print("{:<40} {:<40} {:>4} {:>4}  {}\n", "TOPIC", "TYPE", "PUB", "SUB", "NODES");
  for (const auto& [name, r] : rows) {
    std::set<std::string> nodes = r.publishing_nodes;
    nodes.insert(r.subscribing_nodes.begin(), r.subscribing_nodes.end());
    fmt::print("{:<40} {:<40} {:>4} {:>4}  {}\n", name, r.type, r.publishers, r.subscribers,
               nodes.empty() ? "-" : joined(nodes));
  }
}

}  // namespace

Result<std::shared_ptr<net::Transport>> open_ros2_transport(const std::string& name) {
  const auto* info = net::find_transport(name);
  if (info == nullptr || info->format != net::WireFormat::Xcdr1)
    return fail(Errc::InvalidArgument, info == nullptr ? "this build of horus has no " + name + " backend"
                                                       : "ROS 2 topics are on DDS (cyclonedds or fastdds), not " + name);
  auto config = net::config_from_environment();
  if (!config) return std::unexpected(config.error());
  return info->open(*config);
}

std::map<std::string, Ros2TopicInfo> ros2_topics(const net::Transport& transport) {
  return topics_with_nodes(transport, nullptr);
}

std::string ros2_transport(const std::string& backend_flag) {
  const std::string configured = fleet_transport(backend_flag);
  if (configured == "cyclonedds" || configured == "fastdds" || !backend_flag.empty()) return configured;
  return net::find_transport("cyclonedds") != nullptr ? "cyclonedds" : "fastdds";
}

int cmd_list_ros2(bool json, const Lookup& lookup, const std::atomic<bool>& stop) {
  const std::string name = ros2_transport(lookup.transport);
  auto transport = open_ros2_transport(name);
  if (!transport) {
    fmt::print(stderr, "horus topic list --ros2: {}\n", transport.error().message());
    return 1;
  }
  GraphReader graph;
  std::string error;
  if (!graph.open(**transport, error))
    fmt::print(stderr, "horus topic list --ros2: the nodes are not listed: ros_discovery_info: {}\n", error);
  // Discovery and the participants' transient-local graph states arrive within the wait.
  for (const auto end = Clock::now() + std::chrono::milliseconds(lookup.wait_ms); !stop.load() && Clock::now() < end;)
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  print_rows(topics_with_nodes(**transport, &graph), json);
  return 0;
}

std::unique_ptr<RemoteReader> open_ros2_topic(const std::string& name, const Lookup& lookup, const char* cmd,
                                              const std::atomic<bool>& stop) {
  auto checked = ros2::topic_name(name);
  if (!checked) {
    fmt::print(stderr, "horus topic {}: {}\n", cmd, checked.error().message());
    return nullptr;
  }
  const std::string transport_name = ros2_transport(lookup.transport);
  auto transport = open_ros2_transport(transport_name);
  if (!transport) {
    fmt::print(stderr, "horus topic {}: {}\n", cmd, transport.error().message());
    return nullptr;
  }
  const auto end = Clock::now() + std::max<Clock::duration>(std::chrono::milliseconds(lookup.wait_ms), lookup.appear_wait);
  std::string dds_type;
  for (; dds_type.empty() && !stop.load() && Clock::now() < end; std::this_thread::sleep_for(std::chrono::milliseconds(20)))
    for (const auto& r : (*transport)->remote_endpoints())
      if (r.publisher && r.wire_topic == ros2::dds_topic(*checked)) dds_type = r.type_name;
  if (dds_type.empty()) {
    std::string known;
    for (const auto& [n, r] : ros2_topics(**transport)) known += (known.empty() ? "" : ", ") + n;
    fmt::print(stderr, "horus topic {}: no ROS 2 publisher of '{}' on {} (domain HORUS_DOMAIN_ID) within {:.1f} s{}\n",
               cmd, *checked, transport_name,
               std::chrono::duration<double>(std::max<Clock::duration>(std::chrono::milliseconds(lookup.wait_ms),
                                                                       lookup.appear_wait))
                   .count(),
               known.empty() ? " (no ROS 2 topics at all)" : "; ROS 2 topics: " + known);
    return nullptr;
  }
  const std::string type = ros2::ros_type_of_dds(dds_type);
  if (type.empty() || ros2::Interfaces::standard().find(type) == nullptr) {
    fmt::print(stderr,
               "horus topic {}: '{}' carries {}, which is not one of the ROS 2 interfaces horus reads (those of "
               "docs/ROS2.md); a horus_msgs type is read by its horus topic name\n",
               cmd, *checked, type.empty() ? dds_type : type);
    return nullptr;
  }
  std::string error;
  auto reader = RemoteReader::open_ros2(*checked, transport_name, type, error);
  if (!reader) fmt::print(stderr, "horus topic {}: '{}' ({}): {}\n", cmd, *checked, type, error);
  return reader;
}

}  // namespace horus::tools
