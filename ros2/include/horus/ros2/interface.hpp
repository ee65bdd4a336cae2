// ROS 2 message interfaces as ROS 2 itself describes them: the .msg text, the type description
// rosidl derives from it, and its type hash (RIHS01, REP-2011) that ROS 2 (Iron and later) puts in
// every endpoint's USER_DATA as `typehash=RIHS01_<sha256>;`.
//
//   parse_msg("geometry_msgs/msg/Twist", "Vector3 linear\nVector3 angular\n")  -> Message
//   Interfaces::standard().type_hash("geometry_msgs/msg/Twist")              -> "RIHS01_9c45bf16..."
//
// A type's hash covers its fields and those of every type it refers to (its referenced type
// descriptions, sorted by name), never its constants, comments or default values: two programs
// agree on a hash when they agree on the layout. Interfaces::standard() holds the ROS 2 common
// interfaces horus maps its messages to (their .msg text as ROS 2 ships it); a program adds its
// own (horus_msgs). No ROS 2 installation is needed or read.
#pragma once

#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "horus/error.hpp"

#include "horus/export.hpp"

HORUS_API_BEGIN

namespace horus::ros2 {

/// A field's value type: type_description_interfaces/msg/FieldType's ids of the single value.
/// A .msg `char` is a uint8 and a `byte` an octet (rosidl's mapping).
enum class Base : std::uint8_t {
  Nested = 1,
  Int8 = 2,
  Uint8 = 3,
  Int16 = 4,
  Uint16 = 5,
  Int32 = 6,
  Uint32 = 7,
  Int64 = 8,
  Uint64 = 9,
  Float32 = 10,
  Float64 = 11,
  Bool = 15,
  Byte = 16,
  String = 17,
  WString = 18,
  BoundedString = 21,
  BoundedWString = 22,
};

/// Single value, T[N], T[<=N] or T[].
enum class Shape : std::uint8_t { Single, Array, BoundedSequence, Sequence };

struct FieldType {
  Base base = Base::Int32;
  Shape shape = Shape::Single;
  std::uint64_t capacity = 0;         // T[N]: N; T[<=N]: N
  std::uint64_t string_capacity = 0;  // string<=N: N
  std::string nested;                 // Base::Nested: "pkg/msg/Name"

  /// FieldType's id: the base's, +48 for an array, +96 a bounded sequence, +144 a sequence.
  int type_id() const noexcept;
  /// As a .msg writes it: "float64[36]", "string<=8", "geometry_msgs/Vector3[]".
  std::string to_msg() const;
  friend bool operator==(const FieldType&, const FieldType&) = default;
};

struct Field {
  std::string name;
  FieldType type;
  std::string default_value;  // as written after the name; empty: none
  friend bool operator==(const Field&, const Field&) = default;
};

struct Constant {
  std::string name;
  FieldType type;  // a single value of a basic type or a string
  std::string value;
  friend bool operator==(const Constant&, const Constant&) = default;
};

/// One message type: its name ("pkg/msg/Name"), its fields in order, its constants, and the
/// .msg text it was parsed from.
struct Message {
  std::string type_name;
  std::vector<Field> fields;
  std::vector<Constant> constants;
  std::string text;
};

/// A ROS 2 message type name split: "sensor_msgs/msg/LaserScan" or "sensor_msgs/LaserScan".
struct TypeName {
  std::string package;
  std::string name;
  std::string full() const { return package + "/msg/" + name; }  // "pkg/msg/Name"
  /// The DDS type name ROS 2's rmw layers register: "pkg::msg::dds_::Name_".
  std::string dds() const { return package + "::msg::dds_::" + name + "_"; }
};
/// Parses a type name as ROS 2 writes it ("pkg/msg/Name", "pkg/Name"); an error says which part
/// breaks ROS 2's naming rules (package: lower case, digits, '_'; name: CamelCase).
Result<TypeName> parse_type_name(std::string_view text);

/// Parses .msg text for the type `type_name` ("pkg/msg/Name"): fields (`type name [default]`),
/// constants (`TYPE NAME=value`), comments. A type of the same package may be written without
/// its package, `Header` is std_msgs/Header. An error names the line, what was wrong and what
/// was expected.
Result<Message> parse_msg(std::string_view type_name, std::string_view text);

/// A set of message types, closed under reference: what type descriptions and hashes are taken
/// from.
class Interfaces {
 public:
  /// The ROS 2 common interfaces horus knows (builtin_interfaces, std_msgs, geometry_msgs,
  /// sensor_msgs, nav_msgs, tf2_msgs, diagnostic_msgs, rosgraph_msgs, rmw_dds_common), as of
  /// ROS 2 Jazzy.
  static const Interfaces& standard();

  /// Adds a type parsed from .msg text (replacing none: a name already present is an error).
  Result<void> add(std::string_view type_name, std::string_view msg_text);
  const Message* find(std::string_view type_name) const;
  std::vector<std::string> names() const;

  /// The type and every type it refers to, directly or not (sorted, without the type): an error
  /// names a referenced type that is not in the set.
  Result<std::vector<std::string>> references(std::string_view type_name) const;
  /// What rosidl hashes: the type's description and its referenced ones, as JSON with Python's
  /// separators (", ", ": "), without default values.
  Result<std::string> hashed_description(std::string_view type_name) const;
  /// "RIHS01_" + the SHA-256 of hashed_description, in lower-case hex.
  Result<std::string> type_hash(std::string_view type_name) const;
  /// The definition an MCAP `ros2msg` schema holds, as rosbag2 writes it: the type's .msg text,
  /// then for each referenced type a newline, a line of 80 '=', "MSG: pkg/Name" and its text.
  Result<std::string> message_definition(std::string_view type_name) const;

 private:
  std::map<std::string, Message, std::less<>> types_;
};

/// USER_DATA of an endpoint of this type as ROS 2 writes it: "typehash=RIHS01_...;".
std::string user_data_of(std::string_view type_hash);
/// The type hash in an endpoint's USER_DATA ("...typehash=RIHS01_<64 hex>;..."), or empty.
std::string type_hash_in(std::string_view user_data);

}  // namespace horus::ros2

HORUS_API_END
