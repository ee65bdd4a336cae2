// A fleet topic mapped onto ROS 2 (ros2_wire.hpp).
#include "ros2_wire.hpp"

#include <fmt/format.h>

#include "horus/idlgen/emit.hpp"
#include "horus/ros2/interface.hpp"
#include "horus/ros2/names.hpp"

namespace horus::fleet::detail {
namespace {

// The ROS 2 name: the mapping's, else the topic's own ("robot1.cmd_vel" -> "/robot1/cmd_vel").
// Checked here too: code may set TopicOptions::ros2 without the file's parser.
Result<std::string> ros2_name(const horus::detail::TopicCore& core, const Ros2Mapping& m) {
  if (!m.name.empty()) {
    auto name = ros2::topic_name(m.name);
    if (!name) return fail(Errc::Config, fmt::format("topic '{}': {}", core.name, name.error().message()));
    return name;
  }
  auto name = ros2::topic_name(ros2::topic_name_of(core.name));
  if (!name)
    return fail(Errc::Config, fmt::format("topic '{}': its ROS 2 name: {}; give it one ('ros2: {{name: /...}}')",
                                          core.name, name.error().message()));
  return name;
}

}  // namespace

std::string Ros2Wire::wire_topic() const { return ros2::dds_topic(name); }
std::string Ros2Wire::user_data() const { return ros2::user_data_of(type_hash); }

Result<Ros2Wire> resolve_ros2(const horus::detail::TopicCore& core, const Ros2Mapping& mapping,
                              std::string_view transport) {
  Ros2Mapping m = mapping;
  if (!m.type.empty()) {  // "pkg/Name" -> "pkg/msg/Name"; checked (code may not have been parsed)
    auto t = ros2::parse_type_name(m.type);
    if (!t) return fail(Errc::Config, fmt::format("topic '{}': {}", core.name, t.error().message()));
    m.type = t->full();
  }
  if (transport != "cyclonedds" && transport != "fastdds")
    return fail(Errc::Config, fmt::format("topic '{}': a ROS 2 mapping needs a DDS backend (cyclonedds or fastdds), "
                                          "not {}: ROS 2 nodes speak DDS",
                                          core.name, transport));
  Ros2Wire w;
  auto name = ros2_name(core, m);
  if (!name) return std::unexpected(name.error());
  w.name = std::move(*name);
  w.frame_id = m.frame_id;
  w.child_frame_id = m.child_frame_id;
  w.qos = m.qos;
  auto type = idlgen::ros2_mapped_type(core.type_name, core.type_hash,
                                       core.segment ? core.segment->signature() : std::string_view{}, m.type);
  if (!type) return fail(Errc::Config, fmt::format("topic '{}': {}", core.name, type.error().message()));
  w.conversion = type->conversion;
  w.type = std::move(type->type);
  w.type_hash = std::move(type->type_hash);
  w.dds_type = ros2::parse_type_name(w.type)->dds();
  return w;
}

void apply_ros2_qos(net::Qos& qos, Ros2Mapping::Qos profile, const TopicOptions& options) noexcept {
  if (profile == Ros2Mapping::Qos::Topic) return;
  const bool sensor = profile == Ros2Mapping::Qos::SensorData;
  if (!options.reliability) qos.reliability = sensor ? net::Reliability::BestEffort : net::Reliability::Reliable;
  if (!options.durability) qos.durability = net::Durability::Volatile;
  qos.depth = sensor ? 5 : 10;
}

}  // namespace horus::fleet::detail
