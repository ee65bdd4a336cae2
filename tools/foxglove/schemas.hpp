// Foxglove's own schemas, which its 3D and Image panels draw (foxglove::RawImage, CompressedImage, PointCloud,
// LaserScan, PoseInFrame, FrameTransform, as @foxglove/schemas defines them in OMG IDL), and the conversion of the
// horus messages that carry the same things into them. `horus foxglove` advertises such a channel beside each horus
// topic of these types (TOPIC/foxglove, converted only while a client subscribes); `horus record --foxglove` records
// it.
//
//   horus                     foxglove
//   Image, DepthImage         RawImage (mono8, mono16, rgb8, bgr8, rgba8, bgra8, yuv422, 32FC1, bayer_rggb8,
//                             16UC1; Rgb32F becomes rgb8, each channel clamped to 0..1)
//   CompressedImage           CompressedImage
//   PointCloud                PointCloud (x, y, z [, intensity | red, green, blue [, alpha]])
//   LaserScan                 LaserScan (a beam without a valid return is NaN)
//   Pose2D, Pose3D, Odometry  PoseInFrame
//   TransformStamped          FrameTransform (parent: the frame option, child: the topic's name)
// Messages without a frame of their own are put in `frame` (default "world"); a message stamped 0 gets the time it was
// taken.
#pragma once

#include <memory>
#include <string>
#include <string_view>

#include "horus/backend.hpp"
#include "horus/record/recorder.hpp"

namespace horus::tools::fox {

inline constexpr std::string_view kConvertedSuffix = "/foxglove";

struct FoxgloveSchema {
  std::string_view name;  // "foxglove::RawImage"
  std::string_view idl;   // the OMG IDL: the type and every type it uses, in module foxglove
};

/// The Foxglove schema the standard message `horus_type` (qualified or not) converts to, or null.
const FoxgloveSchema* foxglove_schema_of(std::string_view horus_type);

/// A source of topic `name` (opened as `horus_type` with `options`) whose messages come out converted: the Foxglove
/// schema's CDR (XCDR1, little-endian, with its encapsulation header). Its type() names the schema and holds its IDL
/// (RecordedType::schema). Null with `error` set when the type has no conversion or the topic does not open.
std::unique_ptr<RecordSource> open_foxglove_source(std::string_view horus_type, const std::string& name,
                                                   const TopicOptions& options, const std::string& frame,
                                                   std::string& error);

}  // namespace horus::tools::fox
