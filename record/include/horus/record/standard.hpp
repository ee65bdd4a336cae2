// Recording and playing the standard messages by name, for programs that know a topic's type
// only at run time (`horus record` / `horus play`, the Python package): a RecordSource and a
// PlaySink of every standard type over the library's AnyTopic (horus/standard_types.hpp: the
// types' topics and codecs are compiled once there).
#pragma once

#include <cstdint>
#include <memory>
#include <string_view>

#include "horus/backend.hpp"
#include "horus/error.hpp"
#include "horus/record/player.hpp"
#include "horus/record/recorder.hpp"

#include "horus/export.hpp"

HORUS_API_BEGIN

namespace horus {

/// A recorder's source for topic `name` of the standard message called `type_name` (qualified,
/// "horus::msg::Pose2D", or not, "Pose2D"), opened as Topic<T>::open(name, options). Errors:
/// the topic's, and Errc::InvalidArgument when `type_name` names no standard message.
Result<std::unique_ptr<RecordSource>> open_standard_source(std::string_view type_name, std::string_view name,
                                                           const TopicOptions& options = {});

/// A player's sink publishing into topic `name` the standard message called `type_name`,
/// decoding LCM's encoding (`lcm_encoding`) or XCDR1 with its header. `type_hash` receives the
/// type's hash, to compare with the recorded one. Errors as open_standard_source.
Result<std::unique_ptr<PlaySink>> open_standard_sink(std::string_view type_name, std::string_view name,
                                                     bool lcm_encoding, std::uint64_t& type_hash,
                                                     const TopicOptions& options = {});

/// The same for a channel of a ROS 2 bag whose messages are `conversion`'s ROS 2 type (CDR with
/// its header), each converted into the standard message (a PlayChannel's `conversion`).
Result<std::unique_ptr<PlaySink>> open_ros2_sink(std::string_view type_name, std::string_view name,
                                                 const ros2::Conversion& conversion, std::uint64_t& type_hash,
                                                 const TopicOptions& options = {});

}  // namespace horus

HORUS_API_END
