// The ROS 2 profile of a recording (RecordProfile::Ros2, recorder.hpp): what a topic is in a bag
// that rosbag2 writes, and the bag's metadata. Internal to record/src.
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "horus/error.hpp"
#include "horus/idlgen/emit.hpp"
#include "horus/record/recorder.hpp"

namespace horus::record_detail {

/// One recorded topic as a ROS 2 topic.
struct Ros2Channel {
  std::string topic;  // "/robot1/cmd_vel"
  idlgen::Ros2Mapped type;
  std::string frame_id, child_frame_id;
  std::string offered_qos;  // the channel's offered_qos_profiles (YAML)

  /// The channel's metadata: offered_qos_profiles, topic_type_hash, and horus's own keys.
  std::map<std::string, std::string> metadata(const RecordSource& source) const;
  /// Takes the next message of `source` as ROS 2 CDR (the encapsulation header, then the body)
  /// into `out`; its own stamp, or nothing when there was none.
  std::optional<std::uint64_t> next(RecordSource& source, std::vector<std::byte>& out) const;
};

/// The topic as its `ros2:` rule (or the default mapping) and its message type make it. Errors
/// name the topic and why it has no ROS 2 type.
Result<Ros2Channel> ros2_channel(const RecordSource& source);

/// One topic of a finished bag file, for its metadata.
struct BagTopic {
  const Ros2Channel* channel;
  std::uint64_t messages;
};
/// The bag's metadata as rosbag2 (metadata version 9, Jazzy) writes it into the "rosbag2"
/// Metadata record's "serialized_metadata" (metadata.yaml's content without its top-level key).
std::string bag_metadata(const std::string& file, const std::vector<BagTopic>& topics, std::uint64_t start_ns,
                         std::uint64_t end_ns, std::uint64_t messages);

}  // namespace horus::record_detail
