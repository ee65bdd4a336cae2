// Every standard message, through every generic path: the in-process Topic, JSON, fmt, the
// local codec, the library's network table; and the catalogue counted against the spec so no message is forgotten.
#include <gtest/gtest.h>

#include <fmt/format.h>

#include <algorithm>
#include <concepts>
#include <cstdint>
#include <set>
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

#include "horus/wire/local.hpp"
#include "horus/wire/xcdr1.hpp"
#include "horus/wire/lcm.hpp"
#include "horus/format.hpp"
#include "horus/json.hpp"
#include "horus/msg/all.hpp"
#include "horus/topic.hpp"
#include "message_samples.hpp"
#include "process_support.hpp"
#include "test_support.hpp"

namespace {

using horus_test::AllTypes;
using horus_test::SameMessage;
using horus_test::sample;
using horus_test::topic_sample;
using horus_test::TypeNames;

template <class T>
class EveryMessage : public ::testing::Test {};
TYPED_TEST_SUITE(EveryMessage, AllTypes, TypeNames);

TYPED_TEST(EveryMessage, IsComparableAndDefaultConstructible) {
  static_assert(std::equality_comparable<TypeParam>, "standard messages have operator==");
  static_assert(std::is_default_constructible_v<TypeParam>);
  EXPECT_TRUE(TypeParam{} == TypeParam{});
  EXPECT_FALSE(sample<TypeParam>() == TypeParam{});
}

TYPED_TEST(EveryMessage, RoundTripsThroughTheInProcessTopic) {
  const auto name = horus_test::unique_name("every");
  auto pub = horus::Topic<TypeParam>::with_capacity(name, 4, std::nullopt);
  ASSERT_TRUE(pub) << pub.error().message();
  horus::Topic<TypeParam> sub(name);
  const TypeParam m = topic_sample<TypeParam>();
  pub->send(m);
  auto got = sub.recv();
  ASSERT_TRUE(got);
  EXPECT_TRUE(SameMessage(*got, m));
  using Top = horus::Topic<TypeParam>;
  EXPECT_EQ(Top::kSerialized || Top::kPooled, !horus::reflect::is_fixed_size<TypeParam>);
  if constexpr (Top::kPooled) {
    // The reflection sample's metadata does not describe its bytes: refused at send, counted.
    pub->send(sample<TypeParam>());
    EXPECT_EQ(pub->metrics().send_failures(), 1u);
    EXPECT_FALSE(sub.recv());
  }
}

TYPED_TEST(EveryMessage, CrossesProcessesThroughSharedMemory) {
  const auto name = horus_test::unique_name("every.xproc");
  auto sub = horus::Topic<TypeParam>::open(name, horus::TopicOptions{horus::Backend::SharedMemory, std::nullopt, std::nullopt});
  ASSERT_TRUE(sub) << sub.error().message();
  const TypeParam m = topic_sample<TypeParam>();
  const pid_t child = horus_test::spawn([&] {
    auto pub = horus::Topic<TypeParam>::open(name, horus::TopicOptions{horus::Backend::SharedMemory, std::nullopt, std::nullopt});
    if (!pub) return 3;
    pub->send(m);
    return pub->metrics().send_failures() == 0 ? 0 : 4;
  });
  ASSERT_EQ(horus_test::wait_for(child), 0);
  auto got = sub->recv();  // sent by a process that has exited since
  ASSERT_TRUE(got);
  EXPECT_TRUE(SameMessage(*got, m));
}

TYPED_TEST(EveryMessage, RoundTripsThroughJson) {
  const TypeParam m = sample<TypeParam>();
  const auto j = horus::to_json(m);
  ASSERT_TRUE(j.is_object());
  EXPECT_EQ(j.size(), horus::reflect::field_count<TypeParam>);
  const TypeParam back = horus::from_json<TypeParam>(nlohmann::json::parse(j.dump()));
  EXPECT_TRUE(SameMessage(back, m));
}

TYPED_TEST(EveryMessage, RoundTripsThroughTheLocalCodec) {
  const TypeParam m = sample<TypeParam>();
  const auto bytes = horus::codec::encode(m);
  auto back = horus::codec::decode<TypeParam>(bytes);
  ASSERT_TRUE(back) << back.error();
  EXPECT_TRUE(SameMessage(*back, m));
}

TYPED_TEST(EveryMessage, RoundTripsThroughXcdr1AndRefusesEveryTruncation) {
  const TypeParam m = sample<TypeParam>();
  const auto bytes = horus::cdr::encode(m);
  EXPECT_EQ(bytes.size(), horus::cdr::encoded_size(m));
  auto back = horus::cdr::decode<TypeParam>(bytes);
  ASSERT_TRUE(back) << back.error();
  EXPECT_TRUE(SameMessage(*back, m));
  // Cut anywhere (short of 3 bytes of possible padding): an error, never a crash.
  const std::size_t step = std::max<std::size_t>(1, bytes.size() / 512);
  for (std::size_t n = 0; n + 3 < bytes.size(); n += step)
    EXPECT_FALSE(horus::cdr::decode<TypeParam>(std::span(bytes.data(), n))) << "decoded from " << n << " bytes";
}

TYPED_TEST(EveryMessage, RoundTripsThroughLcmAndRefusesEveryTruncation) {
  const TypeParam m = sample<TypeParam>();
  const auto bytes = horus::lcm::encode(m);
  EXPECT_EQ(bytes.size(), horus::lcm::encoded_size(m));
  auto back = horus::lcm::decode<TypeParam>(bytes);
  ASSERT_TRUE(back) << back.error();
  EXPECT_TRUE(SameMessage(*back, m));
  const std::size_t step = std::max<std::size_t>(1, bytes.size() / 512);
  for (std::size_t n = 0; n < bytes.size(); n += step)
    EXPECT_FALSE(horus::lcm::decode<TypeParam>(std::span(bytes.data(), n))) << "decoded from " << n << " bytes";
}

// A Topic<T> of a standard message takes its network table (XCDR1 and LCM codecs, bridge port)
// from the library (api/src/standard_wire_ops_*.cpp), compiled once: it must encode exactly what
// the codecs encode.
TYPED_TEST(EveryMessage, TakesItsNetworkCodecsFromTheLibrary) {
  static_assert(horus::reflect::StandardMessage<TypeParam>);
  const horus::detail::WireOps* ops = horus::detail::wire_ops_of<TypeParam>();
  ASSERT_NE(ops, nullptr) << "the library has no table for " << horus::type_name<TypeParam>();
  EXPECT_EQ(ops, horus::detail::standard_wire_ops(horus::type_hash<TypeParam>));
  const TypeParam m = sample<TypeParam>();
  for (const auto format : {horus::net::WireFormat::Xcdr1, horus::net::WireFormat::Lcm}) {
    SCOPED_TRACE(std::string(horus::net::to_string(format)));
    ASSERT_TRUE(ops->expressible(format));
    const auto size = ops->encoded_size(format, &m);
    ASSERT_TRUE(size) << size.error().message();
    std::vector<std::byte> bytes(*size);
    ops->encode(format, &m, bytes);
    const auto expected = format == horus::net::WireFormat::Lcm ? horus::lcm::encode(m) : horus::cdr::encode(m);
    EXPECT_TRUE(std::equal(bytes.begin(), bytes.end(), expected.begin(), expected.end()));
  }
}

TEST(NetworkCodecs, AUsersTypeMakesItsOwnTableAndTheLibraryKnowsOnlyStandardHashes) {
  static_assert(!horus::reflect::StandardMessage<horus_test::Stamp>);
  EXPECT_EQ(horus::detail::wire_ops_of<horus_test::Stamp>(), &horus::detail::kWireOpsOf<horus_test::Stamp>);
  EXPECT_EQ(horus::detail::standard_wire_ops(horus::type_hash<horus_test::Stamp>), nullptr);
  EXPECT_EQ(horus::detail::standard_wire_ops(0), nullptr);
  EXPECT_NE(horus::detail::standard_wire_ops(horus::type_hash<horus::msg::Pose2D>), nullptr);
}

TYPED_TEST(EveryMessage, FormatsWithItsNameAndLogsASummary) {
  const TypeParam m = sample<TypeParam>();
  const std::string text = fmt::format("{}", m);
  EXPECT_NE(text.find(TypeNames::GetName<TypeParam>(0)), std::string::npos) << text;
  EXPECT_FALSE(horus::log_summary(m).empty());
}

TEST(Catalogue, EveryMessageHasADistinctTypeHashAndName) {
  std::set<std::uint64_t> hashes;
  std::set<std::string_view> names;
  std::size_t n = 0;
  horus::msg::for_each_message([&]<class T>(std::string_view) {
    hashes.insert(horus::type_hash<T>);
    names.insert(horus::type_name<T>());
    ++n;
  });
  EXPECT_EQ(hashes.size(), n);
  EXPECT_EQ(names.size(), n);
}

// ---------------------------------------------------------------------------
// The spec's catalogue (../shared/spec/messages.txt, navigation-messages.txt,
// joint-messages.txt): every message type it names. NavGoal is the navigation page's
// name of Goal; NavPath is Path with the field names of that page.

const std::vector<std::string_view> kSpecMessages = {
    // geometry
    "CmdVel", "Twist", "Pose2D", "Pose3D", "Point3", "Vector3", "Quaternion", "TransformStamped",
    // sensor
    "LaserScan", "Imu", "Odometry", "Range", "BatteryState", "NavSatFix", "JointState",
    // control
    "MotorCommand", "DifferentialDriveCommand", "ServoCommand", "JointCommand", "PidConfig", "TrajectoryPoint",
    // vision
    "Image", "CompressedImage", "CameraInfo", "StereoInfo", "RegionOfInterest",
    // detection
    "BoundingBox2D", "BoundingBox3D", "Detection", "Detection3D",
    // perception
    "PointCloud", "PointXYZ", "PointXYZRGB", "PointXYZI", "DepthImage", "Tensor", "ImageDescriptor",
    "PointCloudDescriptor", "DepthImageDescriptor",
    // navigation
    "Goal", "GoalResult", "Waypoint", "Path", "NavPath", "PathPlan", "OccupancyGrid", "CostMap", "VelocityObstacle",
    "VelocityObstacles",
    // diagnostics
    "Heartbeat", "NodeHeartbeat", "Status", "DiagnosticStatus", "EmergencyStop", "SafetyStatus", "ResourceUsage",
    "DiagnosticValue", "DiagnosticReport",
    // force
    "WrenchStamped", "ImpedanceParameters", "ForceCommand", "ContactInfo", "HapticFeedback",
    // input
    "JoystickInput", "KeyboardInput",
    // tracking
    "SegmentationMask", "Landmark", "Landmark3D", "LandmarkArray", "TrackedObject", "TrackingHeader",
    // time, audio, generic
    "Clock", "TimeReference", "AudioFrame", "GenericMessage"};

// Value types the spec names that are enums here (not messages of their own).
const std::vector<std::string_view> kSpecEnums = {"ImageEncoding", "TensorDtype", "GoalStatus", "AudioEncoding"};

TEST(Catalogue, HoldsEveryMessageTheSpecNames) {
  std::set<std::string> ours;
  horus::msg::for_each_message(
      [&]<class T>(std::string_view) { ours.insert(TypeNames::GetName<T>(0)); });
  for (auto name : kSpecMessages) EXPECT_TRUE(ours.contains(std::string(name))) << "missing: " << name;
  EXPECT_GE(ours.size(), 70u) << "the spec promises 70+ standard messages";
  EXPECT_GE(ours.size(), kSpecMessages.size());
}

TEST(Catalogue, TheSpecsEnumsAreReflected) {
  EXPECT_EQ(horus::reflect::enum_name(horus::msg::ImageEncoding::Rgb8), "Rgb8");
  EXPECT_EQ(horus::reflect::enum_name(horus::msg::TensorDtype::F32), "F32");
  EXPECT_EQ(horus::reflect::enum_name(horus::msg::GoalStatus::TimedOut), "TimedOut");
  EXPECT_EQ(horus::reflect::enum_name(horus::msg::AudioEncoding::I16), "I16");
  const std::set<std::string> ours = {horus::reflect::type_label<horus::msg::ImageEncoding>(),
                                       horus::reflect::type_label<horus::msg::TensorDtype>(),
                                       horus::reflect::type_label<horus::msg::GoalStatus>(),
                                       horus::reflect::type_label<horus::msg::AudioEncoding>()};
  EXPECT_EQ(ours, std::set<std::string>(kSpecEnums.begin(), kSpecEnums.end()));
}

TEST(Catalogue, NavGoalIsGoalAndNavPathIsPathWithTheNavigationPagesFieldNames) {
  static_assert(std::is_same_v<horus::msg::NavGoal, horus::msg::Goal>);
  EXPECT_EQ(sizeof(horus::msg::NavPath), sizeof(horus::msg::Path));
  EXPECT_NE(horus::type_hash<horus::msg::NavPath>, horus::type_hash<horus::msg::Path>);
}

}  // namespace
