// The ROS 2 graph of this process (ros2_graph.hpp).
#include "ros2_graph.hpp"

#include <fmt/format.h>

#include <errno.h>  // program_invocation_short_name

#include <cctype>
#include <cstring>

#include <nlohmann/json.hpp>

#include "horus/config.hpp"
#include "horus/detail/process.hpp"
#include "horus/log.hpp"
#include "horus/ros2/dynamic.hpp"
#include "horus/ros2/interface.hpp"
#include "horus/ros2/names.hpp"

namespace horus::fleet::detail {

using horus::detail::log;

namespace {

constexpr std::string_view kTopic = "ros_discovery_info";
constexpr std::string_view kType = "rmw_dds_common/msg/ParticipantEntitiesInfo";

struct Graphs {
  static constexpr horus::detail::PartSpec kPart{"ROS 2 graphs", horus::detail::PartLifetime::Process,
                                                 "a bridge may close during static destruction"};
  std::mutex mutex;
  std::map<const net::Transport*, std::weak_ptr<Ros2Graph>> graphs;
};

nlohmann::json gid_json(const net::Guid& g) { return nlohmann::json(std::vector<int>(g.begin(), g.end())); }

}  // namespace

std::string ros2_node_name_of(std::string_view program) {
  std::string out;
  for (char c : program) out += std::isalnum(static_cast<unsigned char>(c)) != 0 ? c : '_';
  if (out.empty()) return "horus";
  if (std::isdigit(static_cast<unsigned char>(out.front())) != 0) out = "horus_" + out;
  return out;
}

Result<Ros2Node> ros2_node_of(const Settings& settings) {
  auto from = [](std::string_view text, std::string_view where) -> Result<Ros2Node> {
    auto n = ros2::node_name(text);
    if (!n) return fail(Errc::Config, fmt::format("{}: {}", where, n.error().message()));
    return Ros2Node{n->name_space, n->name};
  };
  if (!settings.env().ros2_node.empty()) return from(settings.env().ros2_node, "environment variable HORUS_ROS2_NODE");
  if (settings.file != nullptr && settings.file->ros2().node)
    return from(*settings.file->ros2().node, fmt::format("configuration file '{}', line {}, key 'ros2.node'",
                                                         settings.file->file(), settings.file->ros2().line));
  return Ros2Node{"/", ros2_node_name_of(program_invocation_short_name)};
}

Result<std::shared_ptr<Ros2Graph>> Ros2Graph::of(const std::shared_ptr<net::Transport>& transport, const Ros2Node& node) {
  auto& all = horus::detail::Process::part<Graphs>();
  std::lock_guard lock(all.mutex);
  if (auto g = all.graphs[transport.get()].lock()) return g;
  auto g = std::make_shared<Ros2Graph>(transport, node);
  if (auto ok = g->open(); !ok) return std::unexpected(ok.error());
  all.graphs[transport.get()] = g;
  return g;
}

Result<void> Ros2Graph::open() {
  if (!transport_->participant_guid())
    return fail(Errc::Config, fmt::format("the {} transport has no participant GUID: it cannot join the ROS 2 graph",
                                          transport_->name()));
  net::EndpointSpec spec;
  spec.topic = kTopic;
  spec.wire_topic = kTopic;
  spec.type_name = ros2::parse_type_name(kType)->dds();
  spec.qos.reliability = net::Reliability::Reliable;
  spec.qos.durability = net::Durability::TransientLocal;
  spec.qos.depth = 1;
  spec.user_data = ros2::user_data_of(ros2::Interfaces::standard().type_hash(kType).value());
  spec.receive = false;
  auto e = transport_->open(spec, *this);
  if (!e) return std::unexpected(e.error());
  endpoint_ = std::move(*e);
  return {};
}

Ros2Graph::~Ros2Graph() {
  std::lock_guard lock(mutex_);
  endpoint_.reset();  // no callback after this
}

void Ros2Graph::on_error(std::string_view message) { log().warn("the ROS 2 graph ({}): {}", kTopic, message); }

void Ros2Graph::add(const void* key, const net::Endpoint& endpoint) {
  std::lock_guard lock(mutex_);
  entities_[key] = {endpoint.writer_guid(), endpoint.reader_guid()};
  publish_locked();
}

void Ros2Graph::remove(const void* key) {
  std::lock_guard lock(mutex_);
  if (entities_.erase(key) != 0) publish_locked();
}

// ParticipantEntitiesInfo: the participant's GID and one node with its readers and writers,
// encoded from its .msg (a change of the graph is rare: the dynamic codec is fast enough).
void Ros2Graph::publish_locked() {
  if (!endpoint_) return;
  nlohmann::json readers = nlohmann::json::array(), writers = nlohmann::json::array();
  for (const auto& [key, guids] : entities_) {
    if (guids.first) writers.push_back({{"data", gid_json(*guids.first)}});
    if (guids.second) readers.push_back({{"data", gid_json(*guids.second)}});
  }
  const nlohmann::json info = {
      {"gid", {{"data", gid_json(*transport_->participant_guid())}}},
      {"node_entities_info_seq",
       {{{"node_namespace", node_.name_space}, {"node_name", node_.name}, {"reader_gid_seq", readers},
         {"writer_gid_seq", writers}}}}};
  auto body = ros2::encode_json(ros2::Interfaces::standard(), kType, info);
  if (!body) {
    log().warn("the ROS 2 graph ({}): {}", kTopic, body.error().message());
    return;
  }
  auto fill = [](void* ctx, std::span<std::byte> out) {
    const auto* b = static_cast<const std::vector<std::byte>*>(ctx);
    std::memcpy(out.data(), b->data(), b->size());
  };
  if (auto ok = endpoint_->write(body->size(), net::BodyWriter{fill, &*body}); !ok)
    log().warn("the ROS 2 graph ({}): {}", kTopic, ok.error().message());
}

}  // namespace horus::fleet::detail
