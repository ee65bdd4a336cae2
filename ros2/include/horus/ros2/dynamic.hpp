// Any ROS 2 message type of an Interfaces set, as its CDR bytes and as JSON, without generated
// code: what tests and tools read and write ROS 2 samples with (the conversions of convert.hpp
// are the fast, typed path).
//
//   auto json = decode_json(Interfaces::standard(), "geometry_msgs/msg/Twist", body);
//   (*json)["linear"]["x"]                                    -> 0.5
//   auto bytes = encode_json(Interfaces::standard(), "geometry_msgs/msg/Twist",
//                            {{"linear", {{"x", 0.5}}}});      // the other fields 0
//
// The bytes are the sample body as ROS 2 puts it on the DDS wire (XCDR1, after the 4-byte
// encapsulation header): numbers aligned to their size from the body's first byte, u32 counts,
// strings with their NUL, no padding after the count of an empty sequence. A type without
// fields is rosidl's one uint8 placeholder; a wstring is a u32 count of UTF-16 code units, then
// the units (no NUL). In JSON, a message is an object keyed by field name, an array or sequence
// a JSON array (uint8[] and byte[] too: arrays of numbers), char and byte are numbers, a string
// is text (a wstring as UTF-8), a float NaN may be given as null (JSON has no NaN).
#pragma once

#include <cstddef>
#include <span>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

#include "horus/error.hpp"
#include "horus/ros2/interface.hpp"

#include "horus/export.hpp"

HORUS_API_BEGIN

namespace horus::ros2 {

/// The sample of `type_name` in `body`, in the byte order given, as JSON. Bounded: never reads
/// past the body, checks every count against the bytes that remain before allocating, allows
/// at most 3 trailing bytes. Errors (Errc::Corrupt: the bytes; Errc::InvalidArgument: a type
/// not in the set) name the field's path: "sensor_msgs/msg/LaserScan.ranges[3]: ...".
Result<nlohmann::json> decode_json(const Interfaces& types, std::string_view type_name,
                                   std::span<const std::byte> body, bool little_endian = true);

/// The CDR body (little endian) of a sample of `type_name` given as JSON (an object). A missing
/// field is the type's default value (the .msg's, else zero, empty). An unknown field, a JSON
/// value of the wrong type or out of the field's range, a fixed array of another length, a
/// bounded sequence or string over its bound is an error (Errc::InvalidArgument) naming the path.
Result<std::vector<std::byte>> encode_json(const Interfaces& types, std::string_view type_name,
                                           const nlohmann::json& value);

}  // namespace horus::ros2

HORUS_API_END
