// Every standard message, through every generic path: the library's Topic of it (in-process and
// across processes), JSON, fmt, the local codec, the library's network table; and the catalogue
// counted against the spec so no message is forgotten.
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
#include "horus/detail/bridge_port.hpp"
#include "horus/msg/all.hpp"
#include "horus/standard_types.hpp"
#include "horus/transport/encapsulation.hpp"
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

// Every standard message's Topic as the library compiles it once (horus/standard_types.hpp: the
// AnyTopic the CLI, Python, the recorder and the player open; a program's own Topic<T> is the
// same template): null (and a failure) when it does not open.
template <class T>
std::unique_ptr<horus::AnyTopic> open_standard(const std::string& name, const horus::TopicOptions& options) {
  const horus::StandardType* type = horus::find_standard_type(horus::type_hash<T>);
  if (type == nullptr) {
    ADD_FAILURE() << "the library has no table for " << horus::type_name<T>();
    return nullptr;
  }
  EXPECT_EQ(type->name, horus::type_name<T>());
  auto topic = type->open(name, options);
  if (!topic) {
    ADD_FAILURE() << topic.error().message();
    return nullptr;
  }
  return std::move(*topic);
}

TYPED_TEST(EveryMessage, RoundTripsThroughTheInProcessTopic) {
  const auto name = horus_test::unique_name("every");
  horus::TopicOptions four;
  four.capacity = 4;
  auto pub = open_standard<TypeParam>(name, four);
  ASSERT_TRUE(pub);
  auto sub = open_standard<TypeParam>(name, {});
  ASSERT_TRUE(sub);
  const TypeParam m = topic_sample<TypeParam>();
  pub->send(&m);
  TypeParam got{};
  ASSERT_TRUE(sub->recv_into(&got));
  EXPECT_TRUE(SameMessage(got, m));
  constexpr bool pooled = horus::is_pool_message<TypeParam>;
  EXPECT_EQ(horus::is_serialized_message<TypeParam> || pooled, !horus::reflect::is_fixed_size<TypeParam>);
  if constexpr (pooled) {
    // The reflection sample's metadata does not describe its bytes: refused at send, counted.
    const TypeParam bad = sample<TypeParam>();
    pub->send(&bad);
    EXPECT_EQ(pub->metrics().send_failures(), 1u);
    TypeParam none{};
    EXPECT_FALSE(sub->recv_into(&none));
  }
}

TYPED_TEST(EveryMessage, CrossesProcessesThroughSharedMemory) {
  const auto name = horus_test::unique_name("every.xproc");
  const horus::TopicOptions shm{horus::Backend::SharedMemory, std::nullopt, std::nullopt};
  auto sub = open_standard<TypeParam>(name, shm);
  ASSERT_TRUE(sub);
  const TypeParam m = topic_sample<TypeParam>();
  const pid_t child = horus_test::spawn([&] {
    auto pub = horus::find_standard_type(horus::type_hash<TypeParam>)->open(name, shm);
    if (!pub) return 3;
    (*pub)->send(&m);
    return (*pub)->metrics().send_failures() == 0 ? 0 : 4;
  });
  ASSERT_EQ(horus_test::wait_for(child), 0);
  TypeParam got{};
  ASSERT_TRUE(sub->recv_into(&got));  // sent by a process that has exited since
  EXPECT_TRUE(SameMessage(got, m));
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

// The library's table of each standard message says what the templates say of it.
TYPED_TEST(EveryMessage, HasALibraryTableThatAgreesWithTheTemplates) {
  const horus::StandardType* t = horus::find_standard_type(horus::type_hash<TypeParam>);
  ASSERT_NE(t, nullptr) << horus::type_name<TypeParam>();
  EXPECT_EQ(t->name, horus::type_name<TypeParam>());
  EXPECT_EQ(t->signature(), horus::reflect::type_signature<TypeParam>());
  const TypeParam m = sample<TypeParam>();
  EXPECT_EQ(t->to_json(&m), horus::to_json(m));
  EXPECT_EQ(t->summary(&m), horus::log_summary(m));
  EXPECT_EQ(t->xcdr_size(&m), horus::cdr::encoded_size(m));
  std::vector<std::byte> recorded;
  t->encode_xcdr(&m, recorded);
  const auto parsed = horus::net::encapsulation::parse(recorded);
  ASSERT_TRUE(std::holds_alternative<horus::net::Sample>(parsed)) << std::get<std::string>(parsed);
  const auto body = horus::cdr::encode(m);
  const auto& sample_body = std::get<horus::net::Sample>(parsed).body;
  EXPECT_TRUE(std::equal(sample_body.begin(), sample_body.end(), body.begin(), body.end()));
  std::vector<std::byte> lcm_bytes;
  EXPECT_EQ(t->encode_lcm(&m, lcm_bytes), horus::lcm::expressible<TypeParam>);
  if constexpr (horus::lcm::expressible<TypeParam>) {
    EXPECT_EQ(lcm_bytes, horus::lcm::encode(m));
    EXPECT_EQ(t->lcm_fingerprint, horus::lcm::fingerprint<TypeParam>());
    // (LCM's fingerprint hashes the fields, not the type's name: Vector3 and Point3 share one,
    // and the lookup gives the first of the catalogue.)
    const horus::StandardType* by_fingerprint = horus::find_standard_type_by_lcm_fingerprint(t->lcm_fingerprint);
    ASSERT_NE(by_fingerprint, nullptr);
    EXPECT_EQ(by_fingerprint->lcm_fingerprint, t->lcm_fingerprint);
  } else {
    EXPECT_EQ(t->lcm_fingerprint, 0u);
  }
  EXPECT_EQ(horus::find_standard_type(t->name), t);
  EXPECT_EQ(horus::find_standard_type(t->short_name()), t);
}

TEST(StandardTypes, AreTheCatalogueInItsOrderAndNothingElse) {
  std::vector<std::string_view> names;
  horus::msg::for_each_message([&]<class T>(std::string_view) { names.push_back(horus::type_name<T>()); });
  const auto types = horus::standard_types();
  ASSERT_EQ(types.size(), names.size());
  for (std::size_t i = 0; i < types.size(); ++i) EXPECT_EQ(types[i]->name, names[i]) << i;
  EXPECT_EQ(horus::find_standard_type("NoSuchMessage"), nullptr);
  EXPECT_EQ(horus::find_standard_type("msg::NoSuchMessage"), nullptr);
  EXPECT_EQ(horus::find_standard_type("ose2D"), nullptr);  // a tail of a name is not a name
  EXPECT_EQ(horus::find_standard_type(""), nullptr);
  EXPECT_EQ(horus::find_standard_type(std::uint64_t{0}), nullptr);
  EXPECT_EQ(horus::find_standard_type(horus::type_hash<horus_test::Stamp>), nullptr);
  EXPECT_EQ(horus::find_standard_type_by_lcm_fingerprint(0), nullptr);
}

TEST(StandardTypes, AnyTopicSendsJsonAndRecordedBytesAndNamesWhatIsWrong) {
  const horus::StandardType* pose = horus::find_standard_type("Pose2D");
  ASSERT_NE(pose, nullptr);
  const auto name = horus_test::unique_name("any");
  auto pub = pose->open(name, {});
  auto sub = pose->open(name, {});
  ASSERT_TRUE(pub && sub);
  (*sub)->wait_for(std::chrono::nanoseconds(0));  // subscribes
  ASSERT_TRUE((*pub)->send_json(nlohmann::json{{"x", 1.5}, {"y", 2.0}, {"theta", 0.25}, {"timestamp_ns", 7}},
                                std::chrono::seconds(1)));
  nlohmann::json got;
  ASSERT_TRUE((*sub)->take([&](const void* m) { got = pose->to_json(m); }));
  EXPECT_EQ(got["x"], 1.5);
  EXPECT_EQ(got["timestamp_ns"], 7);
  EXPECT_FALSE((*sub)->take([](const void*) {}));  // nothing more
  const auto bad = (*pub)->send_json(nlohmann::json{{"x", "far"}}, std::chrono::seconds(1));
  ASSERT_FALSE(bad);
  EXPECT_EQ(bad.error().code(), horus::Errc::InvalidArgument);
  EXPECT_NE(bad.error().message().find("'x'"), std::string::npos) << bad.error().message();
  // Recorded bytes: the encapsulation header and XCDR1, as encode_xcdr writes them.
  const horus::msg::Pose2D p{3.0, 4.0, 0.5, 9};
  std::vector<std::byte> bytes;
  pose->encode_xcdr(&p, bytes);
  ASSERT_TRUE((*pub)->send_recorded(bytes, false, std::chrono::seconds(1)));
  horus::msg::Pose2D back{};
  ASSERT_TRUE((*sub)->recv_into(&back));
  EXPECT_EQ(back, p);
  bytes.resize(bytes.size() - 9);  // cut inside the body
  const auto cut = (*pub)->send_recorded(bytes, false, std::chrono::seconds(1));
  ASSERT_FALSE(cut);
  EXPECT_EQ(cut.error().code(), horus::Errc::Corrupt);
  // A type LCM cannot carry refuses LCM bytes.
  for (const horus::StandardType* t : horus::standard_types()) {
    if (t->lcm_fingerprint != 0) continue;
    auto topic = t->open(horus_test::unique_name("any.nolcm"), {});
    ASSERT_TRUE(topic) << topic.error().message();
    const auto refused = (*topic)->send_recorded(bytes, true, std::chrono::seconds(1));
    ASSERT_FALSE(refused);
    EXPECT_EQ(refused.error().code(), horus::Errc::TypeMismatch) << t->name;
    break;
  }
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
