// ROS 2 topic names: the rules a ROS 2 node's name must keep, and the wire name rmw uses.
//
//   topic_name("cmd_vel")              -> "/cmd_vel" (made absolute: horus's node is at "/")
//   topic_name("/robot1/2d")           -> error: a token starts with a digit
//   topic_name_of("robot1.cmd_vel")    -> "/robot1/cmd_vel"
//   horus_topic_of("/robot1/cmd_vel")  -> "robot1.cmd_vel"
//   dds_topic("/robot1/cmd_vel")       -> "rt/robot1/cmd_vel"
#pragma once

#include <cstddef>
#include <string>
#include <string_view>

#include "horus/error.hpp"

#include "horus/export.hpp"

HORUS_API_BEGIN

namespace horus::ros2 {

/// Longest fully qualified topic name rmw accepts (RMW_TOPIC_MAX_NAME_LENGTH).
inline constexpr std::size_t kMaxTopicNameLength = 247;

/// Checks a ROS 2 topic name and makes it absolute: letters, digits, '_' and '/' between
/// tokens; no empty token, no token starting with a digit, no "__", not ending with '/', at
/// most kMaxTopicNameLength characters. The error names the rule broken and where.
Result<std::string> topic_name(std::string_view text);
/// The ROS 2 name of a horus topic: "/" + its name with '.' as '/' (not checked).
std::string topic_name_of(std::string_view horus_topic);
/// The horus topic of a ROS 2 name: "/robot1/cmd_vel" -> "robot1.cmd_vel" (not checked).
std::string horus_topic_of(std::string_view ros_name);
/// A ROS 2 node: its namespace ("/" or "/robot1") and name ("planner").
struct NodeName {
  std::string name_space = "/";
  std::string name;
};
/// Parses "[/namespace/]name" by ROS 2's rules (the name: letters, digits and '_', not starting
/// with a digit; the namespace: as a topic name); the error says which rule is broken.
Result<NodeName> node_name(std::string_view text);

/// The ROS 2 type of a DDS type name rmw registers: "sensor_msgs::msg::dds_::LaserScan_" ->
/// "sensor_msgs/msg/LaserScan"; empty when it is not of that form (not a ROS 2 message).
std::string ros_type_of_dds(std::string_view dds_type);
/// The DDS topic of a ROS 2 topic, as rmw_cyclonedds_cpp and rmw_fastrtps_cpp name it.
inline std::string dds_topic(std::string_view ros_name) { return "rt" + std::string(ros_name); }

}  // namespace horus::ros2

HORUS_API_END
