// The ROS 2 graph from the command line (ros2_cmd.cpp): `horus topic list --ros2` (the DDS
// domain's ROS 2 topics, their types, publishers, subscribers and nodes), and the ROS 2 topics
// that `horus topic echo/hz/bw /scan` read by their ROS 2 name, without a configuration file.
#pragma once

#include <atomic>
#include <cstddef>
#include <map>
#include <memory>
#include <set>
#include <string>

#include "horus/error.hpp"
#include "horus/network.hpp"

#include "remote_reader.hpp"
#include "topic_cmd.hpp"

namespace horus::tools {

/// The DDS transport the ROS 2 commands use: --backend, else the configured fleet transport when
/// it is a DDS one, else Cyclone DDS (ROS 2's rmw layers all speak DDS; the domain is
/// HORUS_DOMAIN_ID's, as ROS_DOMAIN_ID).
std::string ros2_transport(const std::string& backend_flag);

/// The transport of that name for the domain (HORUS_DOMAIN_ID), or why not (not DDS, not built).
Result<std::shared_ptr<net::Transport>> open_ros2_transport(const std::string& name);

/// One ROS 2 topic of the domain as discovery sees it.
struct Ros2TopicInfo {
  std::string type;       // "sensor_msgs/msg/LaserScan" (the DDS type name when it is not a ROS 2 one)
  std::string dds_type;   // "sensor_msgs::msg::dds_::LaserScan_"
  std::string type_hash;  // from a publisher's or subscriber's USER_DATA, or empty
  std::size_t publishers = 0, subscribers = 0;
  std::set<std::string> publishing_nodes, subscribing_nodes;  // from ros_discovery_info
};
/// The domain's ROS 2 topics now (DDS topics "rt/<name>"), by ROS 2 name; no nodes.
std::map<std::string, Ros2TopicInfo> ros2_topics(const net::Transport& transport);

int cmd_list_ros2(bool json, const Lookup& lookup, const std::atomic<bool>& stop);

/// A reader of ROS 2 topic `name` ("/scan") as the type its publishers announce, once one is
/// discovered (within lookup's wait); null, with the error printed (`horus topic CMD: ...`).
std::unique_ptr<RemoteReader> open_ros2_topic(const std::string& name, const Lookup& lookup, const char* cmd,
                                              const std::atomic<bool>& stop);

}  // namespace horus::tools
