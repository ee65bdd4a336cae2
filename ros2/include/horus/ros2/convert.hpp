// horus's standard messages as ROS 2's common interfaces, both ways, in the bytes a ROS 2 node
// puts on the DDS wire (XCDR1, the sample body after the 4-byte encapsulation header).
//
//   const Conversion* c = find_conversion(horus::type_hash<msg::CmdVel>, "");  // its preferred
//   std::size_t n = c->encoded_size(&cmd, ctx);   // geometry_msgs/msg/Twist's CDR bytes
//   c->encode(&cmd, ctx, body);                   // exactly n bytes
//   msg::CmdVel back{};
//   auto ok = c->decode(body, true, &back, nullptr);   // Refusal: malformed, or does not fit
//
// Each conversion maps one horus type to one ROS 2 type, field by field (docs/ROS2.md has the
// table): horus's `*_ns` stamps are builtin_interfaces/msg/Time, a horus frame id field is the
// header's frame_id (a horus type without one takes Context::frame_id, the topic rule's), units
// are the same (SI). What the ROS 2 type has and the horus type cannot hold is never cut: a
// longer name, more beams, more joints than the horus type holds is a Refusal that names the
// field and the limit (the bridge drops the sample and counts it). What the horus type does not
// carry at all (a Twist's linear.y into a CmdVel) is left out, as each conversion's `loses`
// says.
#pragma once

#include <cstddef>
#include <cstdint>
#include <expected>
#include <span>
#include <string>
#include <string_view>

#include "horus/byte_buffer.hpp"

#include "horus/export.hpp"

HORUS_API_BEGIN

namespace horus::ros2 {

/// What a topic's mapping adds to its messages: the frame ids a horus type has no field for.
struct Context {
  std::string_view frame_id;        // header.frame_id where the horus type has none
  std::string_view child_frame_id;  // child_frame_id (TransformStamped, Odometry) likewise
};

/// Why a ROS 2 sample did not become a horus message.
struct Refusal {
  /// true: the bytes are not the ROS 2 type (truncated, corrupt); false: a valid sample that
  /// the horus type cannot hold (a field over its limit).
  bool malformed = false;
  /// "sensor_msgs/msg/LaserScan.ranges: 720 beams; horus::msg::LaserScan holds 360".
  std::string what;
};

/// One horus type <-> one ROS 2 type. Functions take the horus message as `const void*` /
/// `void*` to a value of `horus_type` (the bridge knows the type by its hash only).
struct Conversion {
  std::string_view horus_type;  // "horus::msg::CmdVel"
  std::uint64_t horus_hash;     // horus::type_hash of it
  std::string_view ros_type;    // "geometry_msgs/msg/Twist"
  bool preferred;               // the ROS 2 type a `ros2:` rule without `type:` gets
  std::string_view loses;       // what each direction cannot carry, in words (docs/ROS2.md)
  /// The CDR body's size (no encapsulation header).
  std::size_t (*encoded_size)(const void* msg, const Context& ctx);
  /// Writes exactly encoded_size bytes.
  void (*encode)(const void* msg, const Context& ctx, std::span<std::byte> body) noexcept;
  /// Reads a body in the given byte order into *out (a default-constructed horus message);
  /// large data goes where `sink` places it when given (the topic's pool).
  std::expected<void, Refusal> (*decode)(std::span<const std::byte> body, bool little_endian, void* out,
                                         const ByteSink* sink);
};

/// Every conversion horus has, by horus type then ROS 2 type.
std::span<const Conversion> conversions() noexcept;
/// The conversion of the horus type `horus_hash` to `ros_type` ("pkg/msg/Name"), or to its
/// preferred ROS 2 type when `ros_type` is empty; nullptr when there is none.
const Conversion* find_conversion(std::uint64_t horus_hash, std::string_view ros_type) noexcept;
/// The ROS 2 types the horus type `horus_hash` converts to, "a, b or c" (errors list them); empty
/// when none.
std::string conversion_targets(std::uint64_t horus_hash);

}  // namespace horus::ros2

HORUS_API_END
