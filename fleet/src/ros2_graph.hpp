// The ROS 2 graph of this process (docs/ROS2.md): what ROS 2's `ros2 node list` and
// `ros2 topic info -v` read. Each ROS 2 participant publishes on the DDS topic
// `ros_discovery_info` (rmw_dds_common/msg/ParticipantEntitiesInfo; reliable, transient local, keep
// last 1) its GID and, per node, the GIDs of the node's readers and writers. A process with topics
// mapped onto ROS 2 is one node (Ros2Node: HORUS_ROS2_NODE, the file's ros2.node, else the
// program's name) on each DDS transport it uses: the graph lists the readers and writers its
// bridges hold, and publishes again when one comes or goes. Internal to fleet/src.
#pragma once

#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>

#include "horus/error.hpp"
#include "horus/network.hpp"
#include "horus/settings.hpp"

namespace horus::fleet::detail {

/// The node a process is on the ROS 2 graph.
struct Ros2Node {
  std::string name_space = "/";  // "/" or "/robot1"
  std::string name;              // "horus_planner"
};

class Ros2Graph final : public net::Listener {
 public:
  /// The graph of `transport` in this process, made on its first mapped topic (the part "ROS 2
  /// graphs"); `node` names the node the first time.
  static Result<std::shared_ptr<Ros2Graph>> of(const std::shared_ptr<net::Transport>& transport, const Ros2Node& node);

  /// A bridge's endpoint (its writer and reader) joins the node, or leaves it; either publishes
  /// the participant's entities again.
  void add(const void* key, const net::Endpoint& endpoint);
  void remove(const void* key);

  const Ros2Node& node() const noexcept { return node_; }
  ~Ros2Graph();

  Ros2Graph(std::shared_ptr<net::Transport> transport, Ros2Node node) : transport_(std::move(transport)), node_(std::move(node)) {}

 private:
  void on_sample(const net::Sample&) override {}  // other participants' graphs: not read here
  void on_error(std::string_view message) override;
  Result<void> open();
  void publish_locked();

  std::shared_ptr<net::Transport> transport_;
  Ros2Node node_;
  std::mutex mutex_;
  std::unique_ptr<net::Endpoint> endpoint_;  // ros_discovery_info
  std::map<const void*, std::pair<std::optional<net::Guid>, std::optional<net::Guid>>> entities_;  // writer, reader
};

/// This process's node: HORUS_ROS2_NODE, else the file's ros2.node, else the program's name under
/// "/". A value ROS 2 refuses is an error naming where it came from.
Result<Ros2Node> ros2_node_of(const Settings& settings);

/// A ROS 2 node name made of a program's name: letters, digits and '_', not starting with a
/// digit ("my-app.v2" -> "my_app_v2", "2d" -> "horus_2d", "" -> "horus").
std::string ros2_node_name_of(std::string_view program);

}  // namespace horus::fleet::detail
