// Unit tests of the reflection layer: field lists, type names, layout
// signatures and hashes (golden values), custom messages, and the strict JSON
// reader's error messages.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <initializer_list>
#include <limits>
#include <set>
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

#include <fmt/format.h>

#include "horus/format.hpp"
#include "horus/json.hpp"
#include "horus/messages.hpp"

// ---------------------------------------------------------------------------
// Test types.

namespace horus_test {

// The spec's custom message example, declared in one go.
HORUS_MESSAGE(MotorFeedback, (std::uint64_t, timestamp_ns), (std::uint32_t, motor_id), (float, velocity),
              (float, current_amps), (float, temperature_c))

// An enum field printed through an ADL to_string().
enum class Mode : std::uint8_t { Idle = 0, Run = 1 };
constexpr std::string_view to_string(Mode m) { return m == Mode::Run ? "Run" : "Idle"; }
HORUS_MESSAGE(ModeReport, (Mode, mode), (std::uint16_t, code))

// A variable-size message (not memcpy-able, still reflectable).
HORUS_MESSAGE(NamedValues, (std::string, name), (std::vector<float>, values))

// A reflected type with its own log_summary().
struct Summarised {
  std::uint32_t count{};
  std::string log_summary() const { return fmt::format("Summarised({} items)", count); }
};
HORUS_REFLECT(Summarised, count)

}  // namespace horus_test

// Pairs of types that share the type name "test::Probe" and differ in exactly
// one respect from Base; the layout hash must tell them apart.
namespace probe {
struct Base {
  double a{};
  float b{};
  std::array<std::uint8_t, 4> c{};
};
HORUS_REFLECT_NAMED(Base, "test::Probe", a, b, c)

struct SameAsBase {
  double a{};
  float b{};
  std::array<std::uint8_t, 4> c{};
};
HORUS_REFLECT_NAMED(SameAsBase, "test::Probe", a, b, c)

struct FieldRenamed {
  double a{};
  float bb{};
  std::array<std::uint8_t, 4> c{};
};
HORUS_REFLECT_NAMED(FieldRenamed, "test::Probe", a, bb, c)

struct FieldRetyped {
  double a{};
  double b{};
  std::array<std::uint8_t, 4> c{};
};
HORUS_REFLECT_NAMED(FieldRetyped, "test::Probe", a, b, c)

struct SignednessChanged {
  double a{};
  float b{};
  std::array<std::int8_t, 4> c{};
};
HORUS_REFLECT_NAMED(SignednessChanged, "test::Probe", a, b, c)

struct FieldsReordered {
  float b{};
  double a{};
  std::array<std::uint8_t, 4> c{};
};
HORUS_REFLECT_NAMED(FieldsReordered, "test::Probe", b, a, c)

struct ArrayResized {
  double a{};
  float b{};
  std::array<std::uint8_t, 5> c{};
};
HORUS_REFLECT_NAMED(ArrayResized, "test::Probe", a, b, c)

struct FieldAdded {
  double a{};
  float b{};
  std::array<std::uint8_t, 4> c{};
  std::uint8_t d{};
};
HORUS_REFLECT_NAMED(FieldAdded, "test::Probe", a, b, c, d)

struct OtherName {
  double a{};
  float b{};
  std::array<std::uint8_t, 4> c{};
};
HORUS_REFLECT_NAMED(OtherName, "test::Probe2", a, b, c)
}  // namespace probe

namespace {

using namespace horus::msg;
namespace reflect = horus::reflect;

template <class T>
std::vector<std::string> field_names() {
  std::vector<std::string> names;
  reflect::for_each_field_desc<T>([&](const auto& fd) { names.emplace_back(fd.name); });
  return names;
}

// Runs fn, expects a horus::JsonError whose message contains every needle.
void ExpectJsonError(const std::function<void()>& fn, std::initializer_list<std::string_view> needles) {
  try {
    fn();
    ADD_FAILURE() << "expected horus::JsonError";
  } catch (const horus::JsonError& e) {
    const std::string what = e.what();
    for (std::string_view needle : needles)
      EXPECT_NE(what.find(needle), std::string::npos) << "'" << needle << "' not in: " << what;
  }
}

// ===========================================================================
// Field lists

TEST(Reflection, FieldNamesFollowTheSpecTablesInOrder) {
  using V = std::vector<std::string>;
  EXPECT_EQ(field_names<Point3>(), (V{"x", "y", "z"}));
  EXPECT_EQ(field_names<Vector3>(), (V{"x", "y", "z"}));
  EXPECT_EQ(field_names<Quaternion>(), (V{"x", "y", "z", "w"}));
  EXPECT_EQ(field_names<CmdVel>(), (V{"stamp_nanos", "linear", "angular"}));
  EXPECT_EQ(field_names<Twist>(), (V{"linear", "angular", "timestamp_ns"}));
  EXPECT_EQ(field_names<Pose2D>(), (V{"x", "y", "theta", "timestamp_ns"}));
  EXPECT_EQ(field_names<Pose3D>(), (V{"position", "orientation", "timestamp_ns"}));
  EXPECT_EQ(field_names<TransformStamped>(), (V{"translation", "rotation", "timestamp_ns"}));
  EXPECT_EQ(field_names<Imu>(), (V{"orientation", "orientation_covariance", "angular_velocity",
                                   "angular_velocity_covariance", "linear_acceleration",
                                   "linear_acceleration_covariance", "timestamp_ns"}));
  EXPECT_EQ(field_names<LaserScan>(), (V{"ranges", "angle_min", "angle_max", "range_min", "range_max",
                                         "angle_increment", "time_increment", "scan_time", "timestamp_ns"}));
  EXPECT_EQ(field_names<Odometry>(), (V{"pose", "twist", "pose_covariance", "twist_covariance", "frame_id",
                                        "child_frame_id", "timestamp_ns"}));
  EXPECT_EQ(field_names<JointState>(),
            (V{"names", "joint_count", "positions", "velocities", "efforts", "timestamp_ns"}));
  EXPECT_EQ(field_names<JointCommand>(),
            (V{"joint_names", "joint_count", "positions", "velocities", "efforts", "modes", "timestamp_ns"}));
  EXPECT_EQ(field_names<Heartbeat>(), (V{"node_name", "node_id", "sequence", "alive", "uptime", "timestamp_ns"}));
}

TEST(Reflection, FieldCountIsKnownAtCompileTime) {
  static_assert(reflect::field_count<Pose2D> == 4);
  static_assert(reflect::field_count<CmdVel> == 3);
  static_assert(reflect::field_count<LaserScan> == 9);
  static_assert(reflect::field_count<Odometry> == 7);
  static_assert(reflect::field_count<JointCommand> == 7);
  static_assert(reflect::field_count<horus_test::MotorFeedback> == 5);
  SUCCEED();
}

TEST(Reflection, OffsetsMatchOffsetof) {
  constexpr auto pose = reflect::fields<Pose2D>();
  static_assert(reflect::get<0>(pose).offset == offsetof(Pose2D, x));
  static_assert(reflect::get<1>(pose).offset == offsetof(Pose2D, y));
  static_assert(reflect::get<2>(pose).offset == offsetof(Pose2D, theta));
  static_assert(reflect::get<3>(pose).offset == offsetof(Pose2D, timestamp_ns));

  constexpr auto cmd = reflect::fields<CmdVel>();
  static_assert(reflect::get<0>(cmd).offset == offsetof(CmdVel, stamp_nanos));
  static_assert(reflect::get<1>(cmd).offset == offsetof(CmdVel, linear));
  static_assert(reflect::get<2>(cmd).offset == offsetof(CmdVel, angular));

  constexpr auto scan = reflect::fields<LaserScan>();
  static_assert(reflect::get<0>(scan).offset == offsetof(LaserScan, ranges));
  static_assert(reflect::get<1>(scan).offset == offsetof(LaserScan, angle_min));
  static_assert(reflect::get<8>(scan).offset == offsetof(LaserScan, timestamp_ns));

  constexpr auto hb = reflect::fields<Heartbeat>();
  static_assert(reflect::get<3>(hb).offset == offsetof(Heartbeat, alive));
  static_assert(reflect::get<4>(hb).offset == offsetof(Heartbeat, uptime));

  constexpr auto jc = reflect::fields<JointCommand>();
  static_assert(reflect::get<5>(jc).offset == offsetof(JointCommand, modes));
  SUCCEED();
}

template <class T>
void ExpectOffsetsAreTheMemberAddresses() {
  const T obj{};
  const auto* base = reinterpret_cast<const unsigned char*>(&obj);
  std::size_t previous_end = 0;
  reflect::for_each_field_desc<T>([&](const auto& fd) {
    const auto* member = reinterpret_cast<const unsigned char*>(&fd.get(obj));
    EXPECT_EQ(fd.offset, static_cast<std::size_t>(member - base)) << reflect::type_name<T>() << "::" << fd.name;
    EXPECT_GE(fd.offset, previous_end) << "fields out of declaration order at " << fd.name;
    previous_end = fd.offset + sizeof(fd.get(obj));
  });
  EXPECT_LE(previous_end, sizeof(T));
}

TEST(Reflection, EveryMessageFieldOffsetIsTheMemberAddressInDeclarationOrder) {
  ExpectOffsetsAreTheMemberAddresses<Point3>();
  ExpectOffsetsAreTheMemberAddresses<Vector3>();
  ExpectOffsetsAreTheMemberAddresses<Quaternion>();
  ExpectOffsetsAreTheMemberAddresses<CmdVel>();
  ExpectOffsetsAreTheMemberAddresses<Twist>();
  ExpectOffsetsAreTheMemberAddresses<Pose2D>();
  ExpectOffsetsAreTheMemberAddresses<Pose3D>();
  ExpectOffsetsAreTheMemberAddresses<TransformStamped>();
  ExpectOffsetsAreTheMemberAddresses<Imu>();
  ExpectOffsetsAreTheMemberAddresses<LaserScan>();
  ExpectOffsetsAreTheMemberAddresses<Odometry>();
  ExpectOffsetsAreTheMemberAddresses<JointState>();
  ExpectOffsetsAreTheMemberAddresses<JointCommand>();
  ExpectOffsetsAreTheMemberAddresses<Heartbeat>();
}

TEST(Reflection, ForEachFieldVisitsValuesAndCanWriteThem) {
  Pose2D p = Pose2D::make(1, 2, 3);
  double sum = 0;
  reflect::for_each_field(p, [&](std::string_view, const auto& v) { sum += static_cast<double>(v); });
  EXPECT_EQ(sum, 6.0);
  reflect::for_each_field(p, [](std::string_view name, auto& v) {
    if constexpr (std::is_floating_point_v<std::remove_reference_t<decltype(v)>>)
      if (name == "theta") v = 0.25;
  });
  EXPECT_EQ(p.theta, 0.25);
}

// ===========================================================================
// Type names, signatures and hashes

TEST(TypeName, IsFullyQualified) {
  EXPECT_EQ(horus::type_name<Pose2D>(), "horus::msg::Pose2D");
  EXPECT_EQ(horus::type_name<JointCommand>(), "horus::msg::JointCommand");
  EXPECT_EQ(horus::type_name<horus_test::MotorFeedback>(), "horus_test::MotorFeedback");
  static_assert(horus::type_name<Heartbeat>() == "horus::msg::Heartbeat");
}

TEST(TypeName, ReflectNamedOverridesTheCppName) {
  EXPECT_EQ(horus::type_name<probe::Base>(), "test::Probe");
  EXPECT_EQ(horus::type_name<probe::OtherName>(), "test::Probe2");
}

// GOLDEN: this text and this number are part of the wire contract (peers
// compare type hashes). If this test fails, the layout of Pose2D or the
// signature scheme changed: that is a breaking change, not a test to update.
constexpr std::uint64_t kPose2DHash = 0x544adfe01cf22304ULL;
static_assert(horus::type_hash<Pose2D> == kPose2DHash, "Pose2D type hash changed: wire-incompatible");

TEST(TypeHash, Pose2DSignatureAndHashArePinned) {
  EXPECT_EQ(reflect::type_signature<Pose2D>(), "horus::msg::Pose2D{f64 x;f64 y;f64 theta;u64 timestamp_ns;}");
  EXPECT_EQ(horus::type_hash<Pose2D>, kPose2DHash);
}

TEST(TypeHash, IsFnv1aOfTheSignature) {
  // Recomputed here at run time, independently of the constexpr path.
  const auto fnv = [](std::string_view s) {
    std::uint64_t h = 0xcbf29ce484222325ULL;
    for (char c : s) {
      h ^= static_cast<unsigned char>(c);
      h *= 0x100000001b3ULL;
    }
    return h;
  };
  EXPECT_EQ(fnv(reflect::type_signature<Pose2D>()), horus::type_hash<Pose2D>);
  EXPECT_EQ(fnv(reflect::type_signature<Odometry>()), horus::type_hash<Odometry>);
  EXPECT_EQ(fnv(reflect::type_signature<JointCommand>()), horus::type_hash<JointCommand>);
}

// GOLDEN: the layout of every standard message, as the spec tables give it.
TEST(TypeSignature, EveryStandardMessageMatchesTheSpecLayout) {
  EXPECT_EQ(reflect::type_signature<Point3>(), "horus::msg::Point3{f64 x;f64 y;f64 z;}");
  EXPECT_EQ(reflect::type_signature<Vector3>(), "horus::msg::Vector3{f64 x;f64 y;f64 z;}");
  EXPECT_EQ(reflect::type_signature<Quaternion>(), "horus::msg::Quaternion{f64 x;f64 y;f64 z;f64 w;}");
  EXPECT_EQ(reflect::type_signature<CmdVel>(), "horus::msg::CmdVel{u64 stamp_nanos;f32 linear;f32 angular;}");
  EXPECT_EQ(reflect::type_signature<Twist>(), "horus::msg::Twist{[f64;3] linear;[f64;3] angular;u64 timestamp_ns;}");
  EXPECT_EQ(reflect::type_signature<TransformStamped>(),
            "horus::msg::TransformStamped{[f64;3] translation;[f64;4] rotation;u64 timestamp_ns;}");
  EXPECT_EQ(reflect::type_signature<Imu>(),
            "horus::msg::Imu{[f64;4] orientation;[f64;9] orientation_covariance;[f64;3] angular_velocity;"
            "[f64;9] angular_velocity_covariance;[f64;3] linear_acceleration;"
            "[f64;9] linear_acceleration_covariance;u64 timestamp_ns;}");
  EXPECT_EQ(reflect::type_signature<LaserScan>(),
            "horus::msg::LaserScan{[f32;360] ranges;f32 angle_min;f32 angle_max;f32 range_min;f32 range_max;"
            "f32 angle_increment;f32 time_increment;f32 scan_time;u64 timestamp_ns;}");
  EXPECT_EQ(reflect::type_signature<JointState>(),
            "horus::msg::JointState{[[char;32];16] names;u8 joint_count;[f64;16] positions;[f64;16] velocities;"
            "[f64;16] efforts;u64 timestamp_ns;}");
  EXPECT_EQ(reflect::type_signature<JointCommand>(),
            "horus::msg::JointCommand{[[char;32];16] joint_names;u8 joint_count;[f64;16] positions;"
            "[f64;16] velocities;[f64;16] efforts;[u8;16] modes;u64 timestamp_ns;}");
  EXPECT_EQ(reflect::type_signature<Heartbeat>(),
            "horus::msg::Heartbeat{[char;32] node_name;u32 node_id;u64 sequence;u8 alive;f64 uptime;"
            "u64 timestamp_ns;}");
}

TEST(TypeSignature, NestedMessagesAreExpandedInPlace) {
  EXPECT_EQ(reflect::type_signature<Pose3D>(),
            "horus::msg::Pose3D{horus::msg::Point3{f64 x;f64 y;f64 z;} position;"
            "horus::msg::Quaternion{f64 x;f64 y;f64 z;f64 w;} orientation;u64 timestamp_ns;}");
  EXPECT_EQ(reflect::type_signature<Odometry>(),
            "horus::msg::Odometry{horus::msg::Pose2D{f64 x;f64 y;f64 theta;u64 timestamp_ns;} pose;"
            "horus::msg::Twist{[f64;3] linear;[f64;3] angular;u64 timestamp_ns;} twist;"
            "[f64;36] pose_covariance;[f64;36] twist_covariance;[char;32] frame_id;[char;32] child_frame_id;"
            "u64 timestamp_ns;}");
}

TEST(TypeSignature, EnumsStringsAndSequences) {
  EXPECT_EQ(reflect::type_signature<horus_test::ModeReport>(),
            "horus_test::ModeReport{enum horus_test::Mode:u8 mode;u16 code;}");
  EXPECT_EQ(reflect::type_signature<horus_test::NamedValues>(), "horus_test::NamedValues{string name;seq<f32> values;}");
}

TEST(TypeHash, ChangesWithFieldNameTypeOrderArraySizeAndTypeName) {
  constexpr auto base = horus::type_hash<probe::Base>;
  EXPECT_NE(base, horus::type_hash<probe::FieldRenamed>) << "field name";
  EXPECT_NE(base, horus::type_hash<probe::FieldRetyped>) << "field type";
  EXPECT_NE(base, horus::type_hash<probe::SignednessChanged>) << "element signedness";
  EXPECT_NE(base, horus::type_hash<probe::FieldsReordered>) << "field order";
  EXPECT_NE(base, horus::type_hash<probe::ArrayResized>) << "array size";
  EXPECT_NE(base, horus::type_hash<probe::FieldAdded>) << "added field";
  EXPECT_NE(base, horus::type_hash<probe::OtherName>) << "type name";
}

TEST(TypeHash, IdenticalDeclarationsUnderTheSameNameHashEqual) {
  static_assert(horus::type_hash<probe::Base> == horus::type_hash<probe::SameAsBase>);
  EXPECT_EQ(reflect::type_signature<probe::Base>(), reflect::type_signature<probe::SameAsBase>());
  EXPECT_EQ(reflect::type_signature<probe::Base>(), "test::Probe{f64 a;f32 b;[u8;4] c;}");
}

TEST(TypeHash, EveryStandardMessageHasItsOwnHash) {
  const std::set<std::uint64_t> hashes{
      horus::type_hash<Point3>,    horus::type_hash<Vector3>,          horus::type_hash<Quaternion>,
      horus::type_hash<CmdVel>,    horus::type_hash<Twist>,            horus::type_hash<Pose2D>,
      horus::type_hash<Pose3D>,    horus::type_hash<TransformStamped>, horus::type_hash<Imu>,
      horus::type_hash<LaserScan>, horus::type_hash<Odometry>,         horus::type_hash<JointState>,
      horus::type_hash<JointCommand>, horus::type_hash<Heartbeat>,
  };
  EXPECT_EQ(hashes.size(), 14u);  // Point3 and Vector3 share a layout but not a name
}

// ===========================================================================
// Custom messages

TEST(CustomMessage, HorusMessageDeclaresAFixedSizeReflectedStruct) {
  using horus_test::MotorFeedback;
  static_assert(horus::reflect::is_fixed_size<MotorFeedback>);
  static_assert(horus::Reflected<MotorFeedback>);
  EXPECT_EQ(field_names<MotorFeedback>(),
            (std::vector<std::string>{"timestamp_ns", "motor_id", "velocity", "current_amps", "temperature_c"}));
  EXPECT_EQ(reflect::type_signature<MotorFeedback>(),
            "horus_test::MotorFeedback{u64 timestamp_ns;u32 motor_id;f32 velocity;f32 current_amps;f32 temperature_c;}");
  const MotorFeedback zero{};
  EXPECT_EQ(zero.motor_id, 0u);
  EXPECT_EQ(zero.velocity, 0.0f);
}

TEST(CustomMessage, FormatsAndRoundTripsThroughJson) {
  horus_test::MotorFeedback m{};
  m.timestamp_ns = 1000;
  m.motor_id = 3;
  m.velocity = 12.5f;
  m.current_amps = 1.25f;
  m.temperature_c = 41.5f;
  EXPECT_EQ(fmt::format("{}", m),
            "MotorFeedback { timestamp_ns: 1000, motor_id: 3, velocity: 12.5, current_amps: 1.25, temperature_c: 41.5 }");
  EXPECT_EQ(horus::log_summary(m), fmt::format("{}", m));
  const auto j = horus::to_json(m);
  EXPECT_EQ(j.dump(), R"({"current_amps":1.25,"motor_id":3,"temperature_c":41.5,"timestamp_ns":1000,"velocity":12.5})");
  const auto back = horus::from_json<horus_test::MotorFeedback>(j);
  EXPECT_EQ(back.timestamp_ns, m.timestamp_ns);
  EXPECT_EQ(back.motor_id, m.motor_id);
  EXPECT_EQ(back.velocity, m.velocity);
  EXPECT_EQ(back.current_amps, m.current_amps);
  EXPECT_EQ(back.temperature_c, m.temperature_c);
}

TEST(CustomMessage, EnumFieldsPrintTheirNameAndTravelAsNumbers) {
  const horus_test::ModeReport r{horus_test::Mode::Run, 3};
  EXPECT_EQ(fmt::format("{}", r), "ModeReport { mode: Run, code: 3 }");
  EXPECT_EQ(horus::to_json(r).dump(), R"({"code":3,"mode":1})");
  EXPECT_EQ(horus::from_json<horus_test::ModeReport>(horus::to_json(r)).mode, horus_test::Mode::Run);
}

TEST(CustomMessage, VariableSizeMessagesAreReflectedButNotFixedSize) {
  static_assert(!horus::reflect::is_fixed_size<horus_test::NamedValues>);
  const horus_test::NamedValues v{"gains", {1.5f, -2.0f}};
  EXPECT_EQ(fmt::format("{}", v), "NamedValues { name: \"gains\", values: [1.5, -2] }");
  const auto back = horus::from_json<horus_test::NamedValues>(horus::to_json(v));
  EXPECT_EQ(back.name, "gains");
  EXPECT_EQ(back.values, v.values);
}

// ===========================================================================
// log_summary dispatch

TEST(LogSummary, UsesTheMemberWhenPresent) {
  EXPECT_EQ(horus::log_summary(horus_test::Summarised{4}), "Summarised(4 items)");
  LaserScan scan = LaserScan::make();
  scan.ranges[0] = 1.0f;
  EXPECT_EQ(horus::log_summary(scan), scan.log_summary());
  EXPECT_EQ(horus::log_summary(scan).rfind("LaserScan(", 0), 0u);
}

TEST(LogSummary, FallsBackToTheFullFormat) {
  const Pose2D p = Pose2D::make(1, 2, 0.5);
  EXPECT_EQ(horus::log_summary(p), horus::to_string(p));
  EXPECT_EQ(horus::log_summary(p), "Pose2D { x: 1, y: 2, theta: 0.5, timestamp_ns: 0 }");
  EXPECT_EQ(horus::log_summary(42), "42");
}

// ===========================================================================
// JSON

TEST(Json, NonFiniteFloatsRenderAsNullAndReadBackAsNaN) {
  const Pose2D p{std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity(),
                 -std::numeric_limits<double>::infinity(), 5};
  const auto j = horus::to_json(p);
  EXPECT_EQ(j.dump(), R"({"theta":null,"timestamp_ns":5,"x":null,"y":null})");
  const Pose2D back = horus::from_json<Pose2D>(j);
  EXPECT_TRUE(std::isnan(back.x));
  EXPECT_TRUE(std::isnan(back.y));
  EXPECT_TRUE(std::isnan(back.theta));
  EXPECT_EQ(back.timestamp_ns, 5u);

  LaserScan scan = LaserScan::make();
  scan.ranges[7] = std::numeric_limits<float>::infinity();
  const auto js = horus::to_json(scan);
  EXPECT_TRUE(js["ranges"][7].is_null());
  EXPECT_TRUE(std::isnan(horus::from_json<LaserScan>(js).ranges[7]));
}

TEST(Json, MissingKeysKeepTheirDefaults) {
  EXPECT_EQ(horus::from_json<Pose2D>(nlohmann::json{{"x", 1.0}}), (Pose2D{1.0, 0.0, 0.0, 0}));
  EXPECT_EQ(horus::from_json<Pose2D>(nlohmann::json::object()), Pose2D{});
}

TEST(Json, UnknownFieldIsNamedAndValidFieldsAreListed) {
  ExpectJsonError([] { (void)horus::from_json<Pose2D>(nlohmann::json{{"x", 1.0}, {"heading", 2.0}}); },
                  {"'heading'", "horus::msg::Pose2D", "x, y, theta, timestamp_ns"});
  ExpectJsonError([] { (void)horus::from_json<Odometry>(nlohmann::json::parse(R"({"pose":{"z":1}})")); },
                  {"'pose.z'", "x, y, theta, timestamp_ns"});
}

TEST(Json, WrongTypeIsNamed) {
  ExpectJsonError([] { (void)horus::from_json<Pose2D>(nlohmann::json{{"x", "one"}}); }, {"'x'", "expected a number"});
  ExpectJsonError([] { (void)horus::from_json<Pose2D>(nlohmann::json{{"timestamp_ns", 1.5}}); },
                  {"'timestamp_ns'", "integer"});
  ExpectJsonError([] { (void)horus::from_json<Heartbeat>(nlohmann::json{{"node_name", 5}}); },
                  {"'node_name'", "expected a string"});
  ExpectJsonError([] { (void)horus::from_json<Twist>(nlohmann::json{{"linear", 1.0}}); },
                  {"'linear'", "expected an array"});
  ExpectJsonError([] { (void)horus::from_json<Odometry>(nlohmann::json::parse(R"({"pose":{"theta":"x"}})")); },
                  {"'pose.theta'"});
  ExpectJsonError([] { (void)horus::from_json<JointState>(nlohmann::json::parse(R"({"positions":[0, "a"]})")); },
                  {"'positions[1]'"});
  ExpectJsonError([] { (void)horus::from_json<Pose2D>(nlohmann::json::array()); },
                  {"horus::msg::Pose2D", "expected an object"});
}

TEST(Json, OutOfRangeIntegerIsNamed) {
  ExpectJsonError([] { (void)horus::from_json<Heartbeat>(nlohmann::json{{"alive", 256}}); },
                  {"'alive'", "out of range"});
  ExpectJsonError([] { (void)horus::from_json<Heartbeat>(nlohmann::json{{"node_id", 4294967296LL}}); },
                  {"'node_id'", "out of range"});
  ExpectJsonError([] { (void)horus::from_json<Heartbeat>(nlohmann::json{{"sequence", -1}}); },
                  {"'sequence'", "non-negative"});
  ExpectJsonError([] { (void)horus::from_json<JointCommand>(nlohmann::json::parse(R"({"modes":[0, 1, 300]})")); },
                  {"'modes[2]'", "out of range"});
  // Integers put into a json from C++ (stored signed by nlohmann) read like parsed ones.
  nlohmann::json built;
  built["node_id"] = 7;
  EXPECT_EQ(horus::from_json<Heartbeat>(built).node_id, 7u);
  EXPECT_EQ(horus::from_json<Heartbeat>(nlohmann::json::parse(R"({"node_id":7})")).node_id, 7u);
  // The largest values still fit.
  EXPECT_EQ(horus::from_json<Heartbeat>(nlohmann::json{{"node_id", 4294967295LL}}).node_id, 4294967295u);
  EXPECT_EQ(horus::from_json<Heartbeat>(nlohmann::json{{"alive", 255}}).alive, 255u);
  EXPECT_EQ(horus::from_json<Heartbeat>(nlohmann::json{{"sequence", std::numeric_limits<std::uint64_t>::max()}}).sequence,
            std::numeric_limits<std::uint64_t>::max());
}

TEST(Json, TextTooLongForItsFieldIsNamed) {
  const std::string too_long(32, 'n');
  ExpectJsonError([&] { (void)horus::from_json<Heartbeat>(nlohmann::json{{"node_name", too_long}}); },
                  {"'node_name'", "32 characters", "at most 31"});
  ExpectJsonError([&] { (void)horus::from_json<Odometry>(nlohmann::json{{"child_frame_id", too_long}}); },
                  {"'child_frame_id'"});
  ExpectJsonError(
      [&] { (void)horus::from_json<JointState>(nlohmann::json{{"names", nlohmann::json::array({"ok", too_long})}}); },
      {"'names[1]'"});
  EXPECT_EQ(horus::from_json<Heartbeat>(nlohmann::json{{"node_name", std::string(31, 'n')}}).node_name_str(),
            std::string(31, 'n'));
}

TEST(Json, ArrayLongerThanItsFieldIsNamed) {
  ExpectJsonError([] { (void)horus::from_json<JointState>(nlohmann::json{{"positions", std::vector<double>(17, 0.0)}}); },
                  {"'positions'", "17"});
  // A shorter array fills the front and keeps the rest at default.
  const auto js = horus::from_json<JointState>(nlohmann::json{{"positions", {1.0, 2.0}}});
  EXPECT_EQ(js.positions[1], 2.0);
  EXPECT_EQ(js.positions[2], 0.0);
}

TEST(Json, CharFieldsAreStringsAndNamesArraysAreStringArrays) {
  JointState js{};
  js.add_joint("shoulder", 0.5);
  const auto j = horus::to_json(js);
  EXPECT_EQ(j["names"][0], "shoulder");
  EXPECT_EQ(j["names"][1], "");
  EXPECT_EQ(j["names"].size(), 16u);
  EXPECT_EQ(j["joint_count"], 1);
}

}  // namespace
