// The ROS 2 profile of a recording (ros2_profile.hpp).
#include "ros2_profile.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <filesystem>

#include "horus/config.hpp"
#include "horus/ros2/interface.hpp"
#include "horus/ros2/names.hpp"
#include "horus/transport/encapsulation.hpp"

namespace horus::record_detail {
namespace {

// rosbag2's rendering of an rmw_time_t: {sec, nsec}; "infinite" is RMW_DURATION_INFINITE's
// (INT64_MAX ns) split, as rosbag2 (Jazzy) writes it.
std::string duration_yaml(std::string_view key, std::string_view indent) {
  return fmt::format("{0}{1}:\n{0}  sec: 9223372036\n{0}  nsec: 854775807\n", indent, key);
}

// One publisher's offered QoS as rosbag2 serializes rclcpp::QoS (metadata version 9: the
// policies by name).
std::string offered_qos_yaml(bool reliable, bool transient_local, std::uint32_t depth) {
  std::string y = fmt::format("- history: keep_last\n  depth: {}\n  reliability: {}\n  durability: {}\n", depth,
                              reliable ? "reliable" : "best_effort", transient_local ? "transient_local" : "volatile");
  y += duration_yaml("deadline", "  ");
  y += duration_yaml("lifespan", "  ");
  y += "  liveliness: automatic\n";
  y += duration_yaml("liveliness_lease_duration", "  ");
  y += "  avoid_ros_namespace_conventions: false";
  return y;
}

// The QoS the topic's bridge offers on the ROS 2 wire (fleet's apply_ros2_qos): the topic's own
// reliability and durability, else the mapping's profile, else reliable and volatile.
std::string offered_qos_of(const TopicOptions& o, Ros2Mapping::Qos profile) {
  const bool sensor = profile == Ros2Mapping::Qos::SensorData;
  const bool reliable = o.reliability ? *o.reliability == net::Reliability::Reliable : !sensor;
  const bool transient = o.durability && *o.durability == net::Durability::TransientLocal;
  const std::uint32_t depth = profile == Ros2Mapping::Qos::Topic ? o.capacity.value_or(10) : (sensor ? 5 : 10);
  return offered_qos_yaml(reliable, transient, depth);
}

void encode_with(void* ctx, const void* msg) {
  auto& [channel, out] = *static_cast<std::pair<const Ros2Channel*, std::vector<std::byte>*>*>(ctx);
  const ros2::Context context{channel->frame_id, channel->child_frame_id};
  const std::size_t body = channel->type.conversion->encoded_size(msg, context);
  out->resize(net::encapsulation::serialized_size(body));
  channel->type.conversion->encode(msg, context,
                                   std::span<std::byte>(*out).subspan(net::encapsulation::kHeaderSize, body));
  net::encapsulation::write_header_and_padding(*out, body);
}

}  // namespace

Result<Ros2Channel> ros2_channel(const RecordSource& source) {
  const auto& t = source.type();
  auto why = [&](const std::string& what) {
    return fail(Errc::InvalidArgument,
                fmt::format("topic '{}' cannot be recorded in the ros2 profile: {}", source.topic(), what));
  };
  if (!t.schema.empty()) return why("it is recorded in Foxglove's schema " + t.name + ", not as a horus type");
  auto options = resolve_topic_options(source.topic(), {});
  if (!options) return why(options.error().message());
  const Ros2Mapping mapping = options->ros2 && options->ros2->enabled ? *options->ros2 : Ros2Mapping{};
  Ros2Channel c;
  auto name = ros2::topic_name(mapping.name.empty() ? ros2::topic_name_of(source.topic()) : mapping.name);
  if (!name) return why("its ROS 2 name: " + name.error().message() + "; give it one ('ros2: {name: /...}')");
  auto type = idlgen::ros2_mapped_type(t.name, t.hash, t.signature, mapping.type);
  if (!type) return why(type.error().message());
  c.topic = std::move(*name);
  c.type = std::move(*type);
  c.frame_id = mapping.frame_id;
  c.child_frame_id = mapping.child_frame_id;
  c.offered_qos = offered_qos_of(*options, mapping.qos);
  return c;
}

std::map<std::string, std::string> Ros2Channel::metadata(const RecordSource& source) const {
  const auto& t = source.type();
  return {{"offered_qos_profiles", offered_qos},
          {"topic_type_hash", type.type_hash},
          {"horus.topic", source.topic()},
          {"horus.type", t.name},
          {"horus.type_hash", fmt::format("{:016x}", t.hash)},
          {"horus.scope", source.scope()}};
}

std::optional<std::uint64_t> Ros2Channel::next(RecordSource& source, std::vector<std::byte>& out) const {
  if (type.conversion == nullptr) return source.next(RecordFormat::Mcap, out);  // horus_msgs: the same bytes
  std::pair<const Ros2Channel*, std::vector<std::byte>*> ctx{this, &out};
  return source.take(&encode_with, &ctx);
}

std::string bag_metadata(const std::string& file, const std::vector<BagTopic>& topics, std::uint64_t start_ns,
                         std::uint64_t end_ns, std::uint64_t messages) {
  const std::string name = std::filesystem::path(file).filename().string();
  const std::uint64_t duration = end_ns >= start_ns ? end_ns - start_ns : 0;
  std::string y = "version: 9\nstorage_identifier: mcap\n";
  y += fmt::format("duration:\n  nanoseconds: {}\nstarting_time:\n  nanoseconds_since_epoch: {}\n", duration, start_ns);
  y += fmt::format("message_count: {}\ntopics_with_message_count:{}\n", messages, topics.empty() ? " []" : "");
  for (const auto& t : topics) {
    std::string qos;  // the profiles' sequence, nested (metadata version 9)
    for (std::size_t at = 0; at < t.channel->offered_qos.size();) {
      const auto end = std::min(t.channel->offered_qos.find('\n', at), t.channel->offered_qos.size());
      qos += "        " + t.channel->offered_qos.substr(at, end - at) + "\n";
      at = end + 1;
    }
    y += fmt::format(
        "  - topic_metadata:\n      name: {}\n      type: {}\n      serialization_format: cdr\n"
        "      offered_qos_profiles:\n{}      type_description_hash: {}\n    message_count: {}\n",
        t.channel->topic, t.channel->type.type, qos, t.channel->type.type_hash, t.messages);
  }
  y += "compression_format: \"\"\ncompression_mode: \"\"\n";
  y += fmt::format("relative_file_paths:\n  - {}\nfiles:\n  - path: {}\n", name, name);
  y += fmt::format("    starting_time:\n      nanoseconds_since_epoch: {}\n    duration:\n      nanoseconds: {}\n",
                   start_ns, duration);
  y += fmt::format("    message_count: {}\ncustom_data: ~\nros_distro: jazzy\n", messages);
  return y;
}

}  // namespace horus::record_detail
