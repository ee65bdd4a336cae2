// A fleet topic mapped onto ROS 2 (TopicOptions::ros2, docs/ROS2.md): what its bridge puts on
// the DDS wire instead of horus's own naming. Resolved once when the bridge opens:
//   the DDS topic    rt/<ROS 2 name>                     ("rt/robot1/cmd_vel")
//   the type name    <pkg>::msg::dds_::<Name>_           ("geometry_msgs::msg::dds_::Twist_")
//   USER_DATA        typehash=RIHS01_<sha256>;           (the ROS 2 type's, as rosidl hashes it)
//   the bytes        a conversion of ros2/convert.hpp for a standard message with a ROS 2
//                    equivalent; else the message's own XCDR1 bytes, which are those of its type
//                    in the ROS 2 package `horus idl --ros2` writes (horus_msgs/msg/<Name>)
// Internal to fleet/src.
#pragma once

#include <string>

#include "horus/detail/topic_core.hpp"
#include "horus/error.hpp"
#include "horus/network.hpp"
#include "horus/ros2/convert.hpp"
#include "horus/topic_options.hpp"

namespace horus::fleet::detail {

struct Ros2Wire {
  std::string name;       // "/robot1/cmd_vel"
  std::string type;       // "geometry_msgs/msg/Twist"
  std::string dds_type;   // "geometry_msgs::msg::dds_::Twist_"
  std::string type_hash;  // "RIHS01_..."
  /// The conversion of a standard message; nullptr: the message's own XCDR1 bytes.
  const ros2::Conversion* conversion = nullptr;
  std::string frame_id, child_frame_id;
  Ros2Mapping::Qos qos = Ros2Mapping::Qos::Topic;

  std::string wire_topic() const;  // "rt" + name
  std::string user_data() const;   // "typehash=...;"
  ros2::Context context() const noexcept { return {frame_id, child_frame_id}; }
};

/// The mapping of a fleet topic on `transport` ("cyclonedds", "fastdds"). Errors name the topic
/// and what is wrong: LCM, a ROS 2 name ROS 2 refuses, a type the message does not convert to, a
/// message with no ROS 2 type.
Result<Ros2Wire> resolve_ros2(const horus::detail::TopicCore& core, const Ros2Mapping& mapping,
                              std::string_view transport);

/// The QoS of a mapped topic: a profile (ROS 2's default or sensor data) where the topic's own
/// options set no reliability or durability.
void apply_ros2_qos(net::Qos& qos, Ros2Mapping::Qos profile, const TopicOptions& options) noexcept;

}  // namespace horus::fleet::detail
