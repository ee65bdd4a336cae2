// Every standard message, through every generic path: the in-process Topic, JSON, fmt, the
// local codec; and the catalogue counted against the spec so no message is forgotten.
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

#include "horus/codec.hpp"
#include "horus/format.hpp"
#include "horus/json.hpp"
#include "horus/msg/all.hpp"
#include "horus/topic.hpp"
#include "process_support.hpp"
#include "test_support.hpp"

namespace {

// ---------------------------------------------------------------------------
// A message with a distinct, valid value in every field (reflection-driven), so that a
// path that drops, reorders or truncates a field shows up as a difference.

struct Filler {
  std::uint64_t k = 1;

  template <class V>
  void fill(V& v) {
    using namespace horus::reflect;
    if constexpr (std::is_same_v<V, bool>) {
      v = (k++ % 2) == 1;
    } else if constexpr (detail::is_char_array<V>::value) {
      horus::set_fixed_str(v, fmt::format("t{}", k++).substr(0, std::tuple_size_v<V> - 1));
    } else if constexpr (std::is_same_v<V, char>) {
      v = static_cast<char>('a' + k++ % 26);
    } else if constexpr (std::is_integral_v<V>) {
      v = static_cast<V>(k++ % 100 + 1);
    } else if constexpr (std::is_floating_point_v<V>) {
      v = static_cast<V>(static_cast<double>(k++ % 1000) * 0.5 + 0.25);
    } else if constexpr (ReflectedEnum<V>) {
      const auto values = enum_values<V>();
      v = values[k++ % values.size()].value;
    } else if constexpr (std::is_enum_v<V>) {
      v = static_cast<V>(1);
    } else if constexpr (std::is_same_v<V, std::string>) {
      v = fmt::format("s{}", k++);
    } else if constexpr (detail::is_std_array<V>::value) {
      for (auto& e : v) fill(e);
    } else if constexpr (detail::is_std_vector<V>::value) {
      v.resize(3);
      for (auto& e : v) fill(e);
    } else {
      for_each_field(v, [&](std::string_view, auto& f) { fill(f); });
    }
  }
};

template <class T>
T sample() {
  T m{};
  Filler f;
  f.fill(m);
  return m;
}

template <class T>
::testing::AssertionResult SameMessage(const T& a, const T& b) {
  if constexpr (std::equality_comparable<T>) {
    if (!(a == b)) return ::testing::AssertionFailure() << "operator== says they differ: " << horus::to_string(a)
                                                        << "\n vs " << horus::to_string(b);
  }
  if (horus::to_json(a) != horus::to_json(b))
    return ::testing::AssertionFailure() << "JSON differs: " << horus::to_json(a).dump() << "\n vs "
                                         << horus::to_json(b).dump();
  return ::testing::AssertionSuccess();
}

template <class... T>
::testing::Types<T...> to_gtest(horus::msg::TypeList<T...>);
using AllTypes = decltype(to_gtest(horus::msg::AllMessages{}));

template <class T>
class EveryMessage : public ::testing::Test {};

struct TypeNames {
  template <class T>
  static std::string GetName(int) {
    const std::string_view q = horus::type_name<T>();
    return std::string(q.substr(q.rfind("::") + 2));
  }
};
TYPED_TEST_SUITE(EveryMessage, AllTypes, TypeNames);

TYPED_TEST(EveryMessage, IsComparableAndDefaultConstructible) {
  static_assert(std::equality_comparable<TypeParam>, "standard messages have operator==");
  static_assert(std::is_default_constructible_v<TypeParam>);
  EXPECT_TRUE(TypeParam{} == TypeParam{});
  EXPECT_FALSE(sample<TypeParam>() == TypeParam{});
}

// A large-data message whose metadata describes its bytes (the reflection sample's sizes do
// not agree with each other), with a distinct byte pattern and the sample's text and stamps.
template <class T>
T topic_sample() {
  using namespace horus::msg;
  T m;
  if constexpr (std::is_same_v<T, Image>) {
    m = Image(3, 5, ImageEncoding::Rgb8);
    m.set_frame_id("cam");
    m.set_timestamp_ns(42);
  } else if constexpr (std::is_same_v<T, PointCloud>) {
    m = PointCloud::make(7, 4, TensorDtype::F32);
    m.set_timestamp_ns(42);
  } else if constexpr (std::is_same_v<T, DepthImage>) {
    m = DepthImage::millimeters(4, 6);
    m.set_timestamp_ns(42);
  } else if constexpr (std::is_same_v<T, Tensor>) {
    m = Tensor({2, 3, 4}, TensorDtype::U16);
  } else {
    return sample<T>();
  }
  if constexpr (horus::PoolMessage<T>) {
    auto bytes = m.data_mut();
    for (std::size_t i = 0; i < bytes.size(); ++i) bytes[i] = static_cast<std::uint8_t>(i * 7 + 3);
  }
  return m;
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
