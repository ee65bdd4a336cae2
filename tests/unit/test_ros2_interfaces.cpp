// ROS 2 message interfaces (ros2/include/horus/ros2/interface.hpp): the type hashes are the ones
// ROS 2 publishes (rosidl's output for Jazzy, test vectors of issue 53 and of ROS 2's generated
// code), the .msg parser reads ROS 2's grammar and refuses what ROS 2 refuses, with the line.
#include <gtest/gtest.h>

#include <fstream>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "horus/ros2/convert.hpp"
#include "horus/ros2/interface.hpp"
#include "ros2_hash_vectors.hpp"

namespace {

using horus::ros2::Base;
using horus::ros2::Interfaces;
using horus::ros2::Shape;

TEST(Ros2Interfaces, TheTypeHashesAreTheOnesRos2Publishes) {
  const Interfaces& std_types = Interfaces::standard();
  for (const auto& [type, hash] : horus_test::kRos2PublishedHashes) {
    auto got = std_types.type_hash(type);
    ASSERT_TRUE(got) << type << ": " << got.error().message();
    EXPECT_EQ(*got, hash) << type << "'s description: " << std_types.hashed_description(type).value_or("?");
  }
}

TEST(Ros2Interfaces, TheHashedDescriptionIsRosidlsJson) {
  auto d = Interfaces::standard().hashed_description("geometry_msgs/msg/Twist");
  ASSERT_TRUE(d) << d.error().message();
  const std::string vector3 =
      "{\"type_name\": \"geometry_msgs/msg/Vector3\", \"fields\": [{\"name\": \"x\", \"type\": {\"type_id\": 11, "
      "\"capacity\": 0, \"string_capacity\": 0, \"nested_type_name\": \"\"}}, {\"name\": \"y\", \"type\": {\"type_id\": "
      "11, \"capacity\": 0, \"string_capacity\": 0, \"nested_type_name\": \"\"}}, {\"name\": \"z\", \"type\": "
      "{\"type_id\": 11, \"capacity\": 0, \"string_capacity\": 0, \"nested_type_name\": \"\"}}]}";
  EXPECT_EQ(*d,
            "{\"type_description\": {\"type_name\": \"geometry_msgs/msg/Twist\", \"fields\": [{\"name\": \"linear\", "
            "\"type\": {\"type_id\": 1, \"capacity\": 0, \"string_capacity\": 0, \"nested_type_name\": "
            "\"geometry_msgs/msg/Vector3\"}}, {\"name\": \"angular\", \"type\": {\"type_id\": 1, \"capacity\": 0, "
            "\"string_capacity\": 0, \"nested_type_name\": \"geometry_msgs/msg/Vector3\"}}]}, "
            "\"referenced_type_descriptions\": [" +
                vector3 + "]}");
}

TEST(Ros2Interfaces, TheParserReadsEveryShapeConstantsDefaultsAndShorthands) {
  auto m = horus::ros2::parse_msg("my_pkg/msg/Sample",
                                  "# a comment\n"
                                  "uint8 MODE_A=1  # first\n"
                                  "string GREETING=hello # not a comment\n"
                                  "Header header\n"
                                  "Point p          # same package\n"
                                  "geometry_msgs/Vector3[] vs\n"
                                  "float64[36] covariance\n"
                                  "int32[<=4] small\n"
                                  "string<=8 name \"abc\"\n"
                                  "char c\n"
                                  "byte b\n"
                                  "bool[] flags [true, false]\n");
  ASSERT_TRUE(m) << m.error().message();
  ASSERT_EQ(m->constants.size(), 2u);
  EXPECT_EQ(m->constants[0].name, "MODE_A");
  EXPECT_EQ(m->constants[0].value, "1");
  EXPECT_EQ(m->constants[1].value, "hello # not a comment");
  ASSERT_EQ(m->fields.size(), 9u);
  EXPECT_EQ(m->fields[0].type.nested, "std_msgs/msg/Header");
  EXPECT_EQ(m->fields[1].type.nested, "my_pkg/msg/Point");
  EXPECT_EQ(m->fields[2].type.nested, "geometry_msgs/msg/Vector3");
  EXPECT_EQ(m->fields[2].type.type_id(), 1 + 144);
  EXPECT_EQ(m->fields[3].type.shape, Shape::Array);
  EXPECT_EQ(m->fields[3].type.capacity, 36u);
  EXPECT_EQ(m->fields[3].type.type_id(), 11 + 48);
  EXPECT_EQ(m->fields[4].type.shape, Shape::BoundedSequence);
  EXPECT_EQ(m->fields[4].type.type_id(), 6 + 96);
  EXPECT_EQ(m->fields[5].type.base, Base::BoundedString);
  EXPECT_EQ(m->fields[5].type.string_capacity, 8u);
  EXPECT_EQ(m->fields[5].default_value, "\"abc\"");
  EXPECT_EQ(m->fields[6].type.base, Base::Uint8) << "a .msg char is a uint8";
  EXPECT_EQ(m->fields[7].type.base, Base::Byte) << "a .msg byte is an octet";
  EXPECT_EQ(m->fields[8].default_value, "[true, false]");
  EXPECT_EQ(m->fields[3].type.to_msg(), "float64[36]");
  EXPECT_EQ(m->fields[2].type.to_msg(), "geometry_msgs/Vector3[]");
  EXPECT_EQ(m->fields[5].type.to_msg(), "string<=8");
  // An empty message gets rosidl's placeholder field.
  auto empty = horus::ros2::parse_msg("std_msgs/Empty", "# nothing\n");
  ASSERT_TRUE(empty);
  ASSERT_EQ(empty->fields.size(), 1u);
  EXPECT_EQ(empty->fields[0].name, "structure_needs_at_least_one_member");
}

TEST(Ros2Interfaces, WhatRos2RefusesIsAnErrorNamingTheLine) {
  const std::vector<std::pair<std::string, std::string>> bad = {
      {"int32 x\nfloat65 y\n", "line 2: 'float65' is not a type"},
      {"int32 Bad\n", "line 1: field 'Bad' is not a valid name"},
      {"int32 x\nint32 x\n", "line 2: field 'x' is declared twice"},
      {"int32[0] x\n", "line 1: '0' is not an array size"},
      {"int32[<=k] x\n", "line 1: 'k' is not an array size"},
      {"int32 lower=1\n", "line 1: constant 'lower' is not a valid name"},
      {"int32[] LIST=[1]\n", "a constant is a single value"},
      {"string<=0 s\n", "'string<=0' has no valid bound"},
      {"int32\n", "has a type and no name"},
      {"Bad-Pkg/Type x\n", "package 'Bad-Pkg' is not a valid name"},
  };
  for (const auto& [text, expected] : bad) {
    auto m = horus::ros2::parse_msg("pkg/msg/T", text);
    ASSERT_FALSE(m) << text;
    EXPECT_NE(m.error().message().find(expected), std::string::npos) << m.error().message();
    EXPECT_NE(m.error().message().find("pkg/msg/T"), std::string::npos) << m.error().message();
  }
}

TEST(Ros2Interfaces, TypeNamesFollowRos2sRulesAndGiveTheDdsName) {
  auto n = horus::ros2::parse_type_name("sensor_msgs/LaserScan");
  ASSERT_TRUE(n);
  EXPECT_EQ(n->full(), "sensor_msgs/msg/LaserScan");
  EXPECT_EQ(n->dds(), "sensor_msgs::msg::dds_::LaserScan_");
  for (const char* bad : {"LaserScan", "sensor_msgs/srv/SetMap", "Sensor/LaserScan", "sensor_msgs/laser_scan", ""})
    EXPECT_FALSE(horus::ros2::parse_type_name(bad)) << bad;
}

TEST(Ros2Interfaces, AnUnknownTypeOrReferenceIsAnErrorAndAddedTypesHash) {
  Interfaces mine;
  EXPECT_FALSE(mine.type_hash("std_msgs/msg/String"));
  ASSERT_TRUE(mine.add("my_pkg/msg/Outer", "Inner inner\n"));
  auto dangling = mine.type_hash("my_pkg/msg/Outer");
  ASSERT_FALSE(dangling);
  EXPECT_NE(dangling.error().message().find("'my_pkg/msg/Inner'"), std::string::npos) << dangling.error().message();
  ASSERT_TRUE(mine.add("my_pkg/msg/Inner", "float64 x\n"));
  auto h = mine.type_hash("my_pkg/msg/Outer");
  ASSERT_TRUE(h) << h.error().message();
  EXPECT_EQ(h->size(), 7u + 64u);
  EXPECT_FALSE(mine.add("my_pkg/msg/Inner", "float64 y\n")) << "a type defined twice";
  // The layout, not the text, decides: comments, constants and defaults do not change the hash.
  Interfaces other;
  ASSERT_TRUE(other.add("my_pkg/msg/Outer", "# outer\nint32 K=3\nmy_pkg/Inner inner\n"));
  ASSERT_TRUE(other.add("my_pkg/msg/Inner", "float64 x 1.5 # x\n"));
  EXPECT_EQ(other.type_hash("my_pkg/msg/Outer").value_or(""), *h);
  Interfaces changed;
  ASSERT_TRUE(changed.add("my_pkg/msg/Outer", "Inner inner\n"));
  ASSERT_TRUE(changed.add("my_pkg/msg/Inner", "float32 x\n"));
  EXPECT_NE(changed.type_hash("my_pkg/msg/Outer").value_or(""), *h) << "a field's type is part of the hash";
}

TEST(Ros2Interfaces, TheDefinitionListsEveryReferencedTypeAfterRosbag2sSeparator) {
  auto d = Interfaces::standard().message_definition("geometry_msgs/msg/TwistStamped");
  ASSERT_TRUE(d) << d.error().message();
  // rosbag2's: the text's newline, a blank line, the separator, the name as fields write it.
  const std::string sep = "\n\n" + std::string(80, '=') + "\nMSG: ";
  for (const char* dep : {"builtin_interfaces/Time", "geometry_msgs/Twist", "geometry_msgs/Vector3", "std_msgs/Header"})
    EXPECT_NE(d->find(sep + dep + "\n"), std::string::npos) << dep << " in\n" << *d;
  for (std::size_t at = d->find("\nMSG: "); at != std::string::npos; at = d->find("\nMSG: ", at + 1))
    EXPECT_EQ(d->substr(at, d->find('\n', at + 1) - at).find("/msg/"), std::string::npos) << *d;
  EXPECT_TRUE(d->starts_with(Interfaces::standard().find("geometry_msgs/msg/TwistStamped")->text));
}

TEST(Ros2Interfaces, UserDataCarriesTheHashAsRos2WritesIt) {
  const std::string hash = Interfaces::standard().type_hash("std_msgs/msg/String").value();
  EXPECT_EQ(horus::ros2::user_data_of(hash), "typehash=" + hash + ";");
  EXPECT_EQ(horus::ros2::type_hash_in("enclave=/;typehash=" + hash + ";"), hash);
  EXPECT_EQ(horus::ros2::type_hash_in(horus::ros2::user_data_of(hash)), hash);
  EXPECT_EQ(horus::ros2::type_hash_in("typehash=RIHS01_abc;"), "") << "not 64 hex digits";
  EXPECT_EQ(horus::ros2::type_hash_in("enclave=/;"), "");
}

}  // namespace

// docs/ROS2.md's table of conversions is the library's: a row per conversion, with what each
// direction cannot carry, and no row the library lacks.
TEST(Ros2Docs, TheTableOfConversionsIsTheLibrarys) {
  std::ifstream in(HORUS_ROS2_MD);
  ASSERT_TRUE(in) << HORUS_ROS2_MD;
  std::stringstream ss;
  ss << in.rdbuf();
  const std::string doc = ss.str();
  const std::string begin = "<!-- the table of conversions (a test compares it with ros2::conversions()) -->\n";
  const auto a = doc.find(begin);
  const auto b = doc.find("<!-- end of the table -->");
  ASSERT_NE(a, std::string::npos);
  ASSERT_NE(b, std::string::npos);
  std::string want = "| horus type | ROS 2 type | preferred | what does not cross |\n|---|---|---|---|\n";
  for (const auto& c : horus::ros2::conversions())
    want += "| `" + std::string(c.horus_type) + "` | `" + std::string(c.ros_type) + "` | " + (c.preferred ? "yes" : "") +
            " | " + std::string(c.loses) + " |\n";
  EXPECT_EQ(doc.substr(a + begin.size(), b - a - begin.size()), want);
}
