// The motion, power, GNSS, actuator, time and input messages as a whole: the layouts the spec
// fixes, and the properties of every message (POD, zero default, every field sampled, JSON).
#include "msg_motion_test.hpp"
#include "msg_properties_test.hpp"

namespace {

// ===========================================================================
// Layouts the spec (or HORUS, where the spec only names the type) fixes:
// field names, order, types and array sizes, via the canonical signature.

TEST(Layout, SpecTableMessagesHaveTheSpecFields) {
  using horus::reflect::type_signature;
  EXPECT_EQ(type_signature<Range>(),
            "horus::msg::Range{u8 sensor_type;f32 field_of_view;f32 min_range;f32 max_range;f32 range;"
            "u64 timestamp_ns;}");
  EXPECT_EQ(type_signature<BatteryState>(),
            "horus::msg::BatteryState{f32 voltage;f32 current;f32 charge;f32 capacity;f32 percentage;"
            "u8 power_supply_status;f32 temperature;[f32;16] cell_voltages;u8 cell_count;u64 timestamp_ns;}");
  EXPECT_EQ(type_signature<NavSatFix>(),
            "horus::msg::NavSatFix{f64 latitude;f64 longitude;f64 altitude;[f64;9] position_covariance;u8 status;"
            "u16 satellites_visible;f32 hdop;f32 vdop;f32 speed;f32 heading;u64 timestamp_ns;}");
  EXPECT_EQ(type_signature<MotorCommand>(),
            "horus::msg::MotorCommand{u32 motor_id;f32 mode;f32 target;f32 max_velocity;f32 max_acceleration;"
            "f32 feed_forward;u8 enable;u64 timestamp_ns;}");
  EXPECT_EQ(type_signature<DifferentialDriveCommand>(),
            "horus::msg::DifferentialDriveCommand{f32 left_velocity;f32 right_velocity;f32 max_acceleration;"
            "u8 enable;u64 timestamp_ns;}");
  EXPECT_EQ(type_signature<ServoCommand>(),
            "horus::msg::ServoCommand{u32 servo_id;f32 position;f32 speed;u8 enable;u64 timestamp_ns;}");
  EXPECT_EQ(type_signature<PidConfig>(),
            "horus::msg::PidConfig{u32 controller_id;f64 kp;f64 ki;f64 kd;f64 integral_limit;f64 output_limit;"
            "u8 anti_windup;u64 timestamp_ns;}");
  EXPECT_EQ(type_signature<TrajectoryPoint>(),
            "horus::msg::TrajectoryPoint{[f64;3] position;[f64;3] velocity;[f64;3] acceleration;"
            "[f64;4] orientation;[f64;3] angular_velocity;f64 time_from_start;}");
}

TEST(Layout, HorusDefinedMessagesHaveTheHorusFields) {
  using horus::reflect::type_signature;
  const std::string accel = "horus::msg::Accel{[f64;3] linear;[f64;3] angular;u64 timestamp_ns;}";
  EXPECT_EQ(type_signature<Accel>(), accel);
  EXPECT_EQ(type_signature<AccelStamped>(),
            "horus::msg::AccelStamped{" + accel + " accel;[char;32] frame_id;u64 timestamp_ns;}");
  const std::string pose_sig = type_signature<PoseWithCovariance>();
  EXPECT_EQ(pose_sig.rfind("horus::msg::PoseWithCovariance{horus::msg::Pose3D{", 0), 0u) << pose_sig;
  EXPECT_TRUE(contains(pose_sig, "} pose;[f64;36] covariance;[char;32] frame_id;u64 timestamp_ns;}")) << pose_sig;
  const std::string twist_sig = type_signature<TwistWithCovariance>();
  EXPECT_EQ(twist_sig,
            "horus::msg::TwistWithCovariance{horus::msg::Twist{[f64;3] linear;[f64;3] angular;"
            "u64 timestamp_ns;} twist;[f64;36] covariance;[char;32] frame_id;u64 timestamp_ns;}");
  EXPECT_EQ(type_signature<Clock>(),
            "horus::msg::Clock{u64 clock_ns;u64 realtime_ns;f64 sim_speed;u8 paused;u8 source;u64 timestamp_ns;}");
  EXPECT_EQ(type_signature<TimeReference>(),
            "horus::msg::TimeReference{u64 time_ref_ns;[char;32] source;i64 offset_ns;u64 timestamp_ns;}");
  EXPECT_EQ(type_signature<JoystickInput>(),
            "horus::msg::JoystickInput{u32 joystick_id;[char;16] event_type;u32 element_id;[char;32] element_name;"
            "f32 value;u8 pressed;u64 timestamp_ms;}");
  EXPECT_EQ(type_signature<KeyboardInput>(),
            "horus::msg::KeyboardInput{[char;32] key_name;u32 code;u32 modifier_flags;u8 pressed;"
            "u64 timestamp_ms;}");
}

TEST(Layout, OffsetsMatchTheHorusRustLayout) {
  // repr(C) offsets of HORUS clock.rs and joystick_msg.rs (Clock pads 6 bytes after source).
  EXPECT_EQ(offsetof(Clock, paused), 24u);
  EXPECT_EQ(offsetof(Clock, source), 25u);
  EXPECT_EQ(offsetof(Clock, timestamp_ns), 32u);
  EXPECT_EQ(sizeof(Clock), 40u);
  EXPECT_EQ(offsetof(JoystickInput, element_name), 24u);
  EXPECT_EQ(offsetof(JoystickInput, timestamp_ms), 64u);
  EXPECT_EQ(sizeof(JoystickInput), 72u);
  EXPECT_EQ(sizeof(TimeReference), 56u);
  EXPECT_EQ(sizeof(Accel), 56u);
  EXPECT_EQ(sizeof(TrajectoryPoint), 136u);  // 17 doubles
}

// ===========================================================================
// Properties of every message: POD, zero default, every field sampled, JSON
// round trip, fmt.

template <>
Accel sample<Accel>() {
  Accel a = Accel::make({0.1, -0.2, 9.81}, {0.01, 0.02, -0.03});
  a.timestamp_ns = 11;
  return a;
}
template <>
AccelStamped sample<AccelStamped>() {
  AccelStamped s = AccelStamped::make(sample<Accel>()).with_frame_id("imu_link");
  s.timestamp_ns = 12;
  return s;
}
template <>
PoseWithCovariance sample<PoseWithCovariance>() {
  Pose3D p = Pose3D::make(Point3::make(1.0, 2.0, -0.5), Quaternion::from_euler(0.1, 0.2, 0.3));
  p.timestamp_ns = 5;
  PoseWithCovariance m = PoseWithCovariance::make(p).with_frame_id("map");
  for (std::size_t i = 0; i < 36; ++i) m.covariance[i] = 0.001 * static_cast<double>(i + 1);
  m.timestamp_ns = 6;
  return m;
}
template <>
TwistWithCovariance sample<TwistWithCovariance>() {
  Twist t = Twist::make({0.5, 0.1, 0.0}, {0.0, 0.0, 0.2});
  t.timestamp_ns = 18'446'744'073'709'551'615ULL;  // u64 max survives JSON
  TwistWithCovariance m = TwistWithCovariance::make(t).with_frame_id("base_link");
  m.covariance[0] = 0.02;
  m.covariance[35] = -0.04;
  m.timestamp_ns = 1;
  return m;
}
template <>
Range sample<Range>() {
  Range r = Range::make(Range::INFRARED, 0.8f);
  r.timestamp_ns = 13;
  return r;
}
template <>
BatteryState sample<BatteryState>() {
  BatteryState b = BatteryState::make(12.6f, 75.0f);
  b.current = -2.5f;
  b.charge = 3.75f;
  b.capacity = 5.0f;
  b.power_supply_status = BatteryState::STATUS_DISCHARGING;
  b.temperature = 28.5f;
  b.cell_voltages = {4.2f, 4.19f, 4.21f};
  b.cell_count = 3;
  b.timestamp_ns = 14;
  return b;
}
template <>
NavSatFix sample<NavSatFix>() {
  NavSatFix f = NavSatFix::from_coordinates(47.397742, -8.545594, 488.25);
  f.position_covariance = {1.5, 0, 0, 0, 1.5, 0, 0, 0, 4.0};
  f.status = NavSatFix::STATUS_SBAS_FIX;
  f.satellites_visible = 65535;
  f.hdop = 0.9f;
  f.vdop = 1.4f;
  f.speed = 2.5f;
  f.heading = -1.25f;
  f.timestamp_ns = 15;
  return f;
}
template <>
MotorCommand sample<MotorCommand>() {
  MotorCommand c = MotorCommand::position(4'000'000'000u, -1.5f, 3.0f);
  c.max_acceleration = 10.0f;
  c.feed_forward = 0.25f;
  c.timestamp_ns = 16;
  return c;
}
template <>
DifferentialDriveCommand sample<DifferentialDriveCommand>() {
  DifferentialDriveCommand c = DifferentialDriveCommand::from_twist(1.0, 0.5, 0.4);
  c.max_acceleration = 2.0f;
  c.timestamp_ns = 17;
  return c;
}
template <>
ServoCommand sample<ServoCommand>() {
  ServoCommand s = ServoCommand::with_speed(9, 0.75f, 0.25f);
  s.timestamp_ns = 18;
  return s;
}
template <>
PidConfig sample<PidConfig>() {
  PidConfig c = PidConfig::make(2.0, 0.5, 0.125).with_limits(10.0, 100.0);
  c.controller_id = 3;
  c.timestamp_ns = 19;
  return c;
}
template <>
TrajectoryPoint sample<TrajectoryPoint>() {
  TrajectoryPoint p = TrajectoryPoint::new_2d(1.0, 2.0, 0.5, -0.5, 3.25);
  p.position[2] = 0.1;
  p.acceleration = {0.1, 0.2, 0.3};
  p.orientation = {0.0, 0.0, 0.6, 0.8};
  p.angular_velocity = {0.0, 0.0, 0.4};
  return p;
}
template <>
Clock sample<Clock>() {
  Clock c = Clock::replay_time(2'000'000'000, 0.5, 1'700'000'000'000'000'000ULL).with_paused(true);
  c.timestamp_ns = 1'700'000'000'000'000'001ULL;
  return c;
}
template <>
TimeReference sample<TimeReference>() {
  TimeReference t = TimeReference::make(1'000'000'000, "gps", std::numeric_limits<std::int64_t>::min());
  t.timestamp_ns = 20;
  return t;
}
template <>
JoystickInput sample<JoystickInput>() {
  JoystickInput j = JoystickInput::new_button(1, 2, "RightBumper", true);
  j.value = 0.5f;  // e.g. an analogue button
  j.timestamp_ms = 1'700'000'000'000ULL;
  return j;
}
template <>
KeyboardInput sample<KeyboardInput>() {
  KeyboardInput k = KeyboardInput::make("s", 83, KeyboardInput::MODIFIER_CTRL | KeyboardInput::MODIFIER_SHIFT, true);
  k.timestamp_ms = 1'700'000'000'001ULL;
  return k;
}

// The motion family's types: the properties every message has (msg_properties_test.hpp), and
// what only this family checks: every field sampled, in the JSON and in the text, a short summary.
using MotionMessages = ::testing::Types<Accel, AccelStamped, PoseWithCovariance, TwistWithCovariance, Range,
                                        BatteryState, NavSatFix, MotorCommand, DifferentialDriveCommand, ServoCommand,
                                        PidConfig, TrajectoryPoint, Clock, TimeReference, JoystickInput, KeyboardInput>;
INSTANTIATE_TYPED_TEST_SUITE_P(Motion, MessageProperties, MotionMessages);

template <class T>
class EveryMotionMessage : public ::testing::Test {};
TYPED_TEST_SUITE(EveryMotionMessage, MotionMessages);

TYPED_TEST(EveryMotionMessage, SampleSetsEveryFieldToANonDefaultValue) { ExpectSampleSetsEveryField<TypeParam>(); }

TYPED_TEST(EveryMotionMessage, JsonHasOneKeyPerField) {
  const nlohmann::json j = horus::to_json(sample<TypeParam>());
  ASSERT_TRUE(j.is_object());
  EXPECT_EQ(j.size(), horus::reflect::field_count<TypeParam>);
  horus::reflect::for_each_field_desc<TypeParam>(
      [&](const auto& fd) { EXPECT_TRUE(j.contains(std::string(fd.name))) << fd.name << " in " << j.dump(); });
}

TYPED_TEST(EveryMotionMessage, FormatsEveryFieldByName) {
  const std::string text = fmt::format("{}", sample<TypeParam>());
  horus::reflect::for_each_field_desc<TypeParam>(
      [&](const auto& fd) { EXPECT_TRUE(contains(text, std::string(fd.name) + ": ")) << fd.name << " in " << text; });
}

TYPED_TEST(EveryMotionMessage, LogSummaryIsShort) {
  const std::string line = horus::log_summary(sample<TypeParam>());
  EXPECT_FALSE(line.empty());
  // Types without their own log_summary() print in full; the big ones summarise.
  if constexpr (horus::reflect::detail::HasLogSummary<TypeParam>) {
    EXPECT_LT(line.size(), 240u) << line;
  }
}

// Spot checks of the printed text.
TEST(MotionFormatting, TextFieldsPrintQuotedAndNumbersShortest) {
  EXPECT_EQ(fmt::format("{}", sample<ServoCommand>()),
            "ServoCommand { servo_id: 9, position: 0.75, speed: 0.25, enable: 1, timestamp_ns: 18 }");
  EXPECT_EQ(fmt::format("{}", TimeReference::make(5, "ptp", -3)),
            "TimeReference { time_ref_ns: 5, source: \"ptp\", offset_ns: -3, timestamp_ns: 0 }");
  EXPECT_TRUE(contains(fmt::format("{}", sample<KeyboardInput>()), "key_name: \"s\", code: 83, modifier_flags: 5"));
}

TEST(MotionFormatting, NaNChargePrintsAndTravelsAsNull) {
  const BatteryState b = BatteryState::make(12.0f, 50.0f);
  EXPECT_TRUE(contains(fmt::format("{}", b), "charge: nan")) << fmt::format("{}", b);
  const nlohmann::json j = horus::to_json(b);
  EXPECT_TRUE(j["charge"].is_null()) << j.dump();
  const BatteryState back = horus::from_json<BatteryState>(j);
  EXPECT_TRUE(std::isnan(back.charge));
  EXPECT_TRUE(std::isnan(back.capacity));
  EXPECT_EQ(back.voltage, 12.0f);
}

}  // namespace
