// Unit tests of the force, haptic and audio messages: WrenchStamped, ImpedanceParameters,
// ForceCommand, ContactInfo, HapticFeedback (force.hpp), AudioFrame (audio.hpp), and the
// properties of every message of the diagnostics, force and audio headers.
#include "msg_diagnostics_test.hpp"
#include "msg_properties_test.hpp"

namespace {

// ===========================================================================
// WrenchStamped

TEST(WrenchStamped, FactoriesPlaceForceAndTorqueAtTheOrigin) {
  const WrenchStamped w = WrenchStamped::make(Vector3::make(1, 2, 3), Vector3::make(4, 5, 6));
  EXPECT_EQ(w.force, Vector3::make(1, 2, 3));
  EXPECT_EQ(w.torque, Vector3::make(4, 5, 6));
  EXPECT_EQ(w.point_of_application, Point3::origin());
  EXPECT_EQ(WrenchStamped::force_only(Vector3::make(1, 0, 0)).torque, Vector3::zero());
  EXPECT_EQ(WrenchStamped::torque_only(Vector3::make(0, 1, 0)).force, Vector3::zero());
  EXPECT_EQ(WrenchStamped::torque_only(Vector3::make(0, 1, 0)).torque, Vector3::make(0, 1, 0));
}

TEST(WrenchStamped, MagnitudesAreEuclidean) {
  const WrenchStamped w = WrenchStamped::make(Vector3::make(3, 4, 12), Vector3::make(0, -6, 8));
  EXPECT_DOUBLE_EQ(w.force_magnitude(), 13.0);
  EXPECT_DOUBLE_EQ(w.torque_magnitude(), 10.0);
  EXPECT_EQ(WrenchStamped{}.force_magnitude(), 0.0);
}

TEST(WrenchStamped, ExceedsLimitsIsStrictAndTreatsNonFiniteReadingsAsExceeding) {
  const WrenchStamped w = WrenchStamped::make(Vector3::make(3, 4, 0), Vector3::make(0, 0, 2));
  EXPECT_FALSE(w.exceeds_limits(5.0, 2.0));
  EXPECT_TRUE(w.exceeds_limits(4.99, 2.0));
  EXPECT_TRUE(w.exceeds_limits(5.0, 1.99));
  EXPECT_TRUE(WrenchStamped::force_only(Vector3::make(kNaN, 0, 0)).exceeds_limits(100.0, 100.0));
  EXPECT_TRUE(WrenchStamped::torque_only(Vector3::make(0, kInf, 0)).exceeds_limits(100.0, 100.0));
}

TEST(WrenchStamped, FilterBlendsWithThePreviousSampleAndClampsAlpha) {
  const WrenchStamped prev = WrenchStamped::make(Vector3::make(0, 0, 0), Vector3::make(4, 4, 4));
  WrenchStamped w = WrenchStamped::make(Vector3::make(8, -8, 4), Vector3::make(0, 0, 0));
  w.filter(prev, 0.25);
  EXPECT_EQ(w.force, Vector3::make(2, -2, 1));
  EXPECT_EQ(w.torque, Vector3::make(3, 3, 3));

  WrenchStamped hi = WrenchStamped::force_only(Vector3::make(1, 1, 1));
  hi.filter(prev, 7.0);  // clamped to 1: keeps this sample
  EXPECT_EQ(hi.force, Vector3::make(1, 1, 1));
  EXPECT_EQ(hi.torque, Vector3::zero());
  WrenchStamped lo = WrenchStamped::force_only(Vector3::make(1, 1, 1));
  lo.filter(prev, -3.0);  // clamped to 0: takes the previous sample
  EXPECT_EQ(lo.force, prev.force);
  EXPECT_EQ(lo.torque, prev.torque);
  WrenchStamped nan = WrenchStamped::force_only(Vector3::make(1, 1, 1));
  nan.filter(prev, kNaN);
  EXPECT_EQ(nan, WrenchStamped::force_only(Vector3::make(1, 1, 1)));
}

TEST(WrenchStamped, WithFrameIdRefusesNamesThatDoNotFit) {
  EXPECT_EQ(WrenchStamped{}.with_frame_id("ft_sensor").frame_id_str(), "ft_sensor");
  EXPECT_THROW((void)WrenchStamped{}.with_frame_id(std::string(32, 'f')), std::invalid_argument);
  WrenchStamped w{};
  EXPECT_TRUE(w.set_frame_id("a"));
  EXPECT_FALSE(w.set_frame_id(std::string(32, 'f')));
  EXPECT_EQ(w.frame_id_str(), "a");
  EXPECT_EQ(sizeof(WrenchStamped), 112u);
}

// ===========================================================================
// ImpedanceParameters

TEST(ImpedanceParameters, PresetsMatchHorus) {
  const ImpedanceParameters m = ImpedanceParameters::make();
  EXPECT_EQ(m.stiffness, (std::array<double, 6>{1000, 1000, 1000, 100, 100, 100}));
  EXPECT_EQ(m.damping, (std::array<double, 6>{50, 50, 50, 5, 5, 5}));
  EXPECT_EQ(m.inertia, (std::array<double, 6>{1, 1, 1, 0.1, 0.1, 0.1}));
  EXPECT_EQ(m.force_limits, (std::array<double, 6>{50, 50, 50, 5, 5, 5}));
  EXPECT_FALSE(m.is_enabled());

  const ImpedanceParameters c = ImpedanceParameters::compliant();
  EXPECT_EQ(c.stiffness, (std::array<double, 6>{100, 100, 100, 10, 10, 10}));
  EXPECT_EQ(c.damping, (std::array<double, 6>{20, 20, 20, 2, 2, 2}));
  EXPECT_EQ(c.inertia, m.inertia);
  const ImpedanceParameters s = ImpedanceParameters::stiff();
  EXPECT_EQ(s.stiffness, (std::array<double, 6>{5000, 5000, 5000, 500, 500, 500}));
  EXPECT_EQ(s.damping, (std::array<double, 6>{100, 100, 100, 10, 10, 10}));
  EXPECT_EQ(s.force_limits, m.force_limits);
}

TEST(ImpedanceParameters, EnableAndDisable) {
  ImpedanceParameters p = ImpedanceParameters::make();
  p.enable();
  EXPECT_TRUE(p.is_enabled());
  EXPECT_EQ(p.enabled, 1u);
  p.disable();
  EXPECT_FALSE(p.is_enabled());
  EXPECT_EQ(sizeof(ImpedanceParameters), 208u);
}

TEST(ImpedanceParameters, ForceLimitsAreCheckedPerAxisOnAbsoluteValues) {
  const ImpedanceParameters p = ImpedanceParameters::make();  // 50 N, 5 N*m
  EXPECT_FALSE(p.exceeds_force_limits(WrenchStamped::make(Vector3::make(50, -50, 49), Vector3::make(5, -5, 0))));
  EXPECT_TRUE(p.exceeds_force_limits(WrenchStamped::force_only(Vector3::make(0, -50.5, 0))));
  EXPECT_TRUE(p.exceeds_force_limits(WrenchStamped::torque_only(Vector3::make(0, 0, 5.01))));
  EXPECT_TRUE(p.exceeds_force_limits(WrenchStamped::torque_only(Vector3::make(kNaN, 0, 0))));
  // Per axis, not on the magnitude: 40 N on each axis is 69 N in total but within limits.
  EXPECT_FALSE(p.exceeds_force_limits(WrenchStamped::force_only(Vector3::make(40, 40, 40))));
}

// ===========================================================================
// ForceCommand

TEST(ForceCommand, ForceOnlyControlsForceOnXYZ) {
  const ForceCommand c = ForceCommand::force_only(Vector3::make(0, 0, -10));
  EXPECT_EQ(c.target_force, Vector3::make(0, 0, -10));
  EXPECT_EQ(c.force_mode, (std::array<std::uint8_t, 6>{1, 1, 1, 0, 0, 0}));
  EXPECT_EQ(c.max_deviation, Vector3::make(0.01, 0.01, 0.01));
  EXPECT_EQ(c.gains, (std::array<double, 6>{1, 1, 1, 1, 1, 1}));
  EXPECT_FALSE(c.has_timeout());
  EXPECT_TRUE(c.is_force_axis(2));
  EXPECT_FALSE(c.is_force_axis(3));
  EXPECT_FALSE(c.is_force_axis(6));
}

TEST(ForceCommand, HybridKeepsAxesForceAndPosition) {
  const ForceCommand c = ForceCommand::hybrid({0, 0, 1, 0, 0, 1}, Vector3::make(0, 0, 5), Vector3::make(0.3, 0.1, 0));
  EXPECT_EQ(c.force_mode, (std::array<std::uint8_t, 6>{0, 0, 1, 0, 0, 1}));
  EXPECT_EQ(c.position_setpoint, Vector3::make(0.3, 0.1, 0));
  EXPECT_EQ(c.target_torque, Vector3::zero());
  EXPECT_TRUE(c.is_force_axis(5));
  EXPECT_FALSE(c.is_force_axis(0));
}

TEST(ForceCommand, SurfaceContactPushesAlongTheUnitNormal) {
  const ForceCommand v = ForceCommand::surface_contact(10.0, Vector3::make(0, 0, 2));
  EXPECT_EQ(v.target_force, Vector3::make(0, 0, 10));
  EXPECT_EQ(v.force_mode, (std::array<std::uint8_t, 6>{0, 0, 1, 0, 0, 0}));

  // |z| = 0.8 after normalising: not "mostly vertical".
  const ForceCommand s = ForceCommand::surface_contact(10.0, Vector3::make(3, 0, 4));
  EXPECT_NEAR(s.target_force.x, 6.0, 1e-12);
  EXPECT_NEAR(s.target_force.z, 8.0, 1e-12);
  EXPECT_EQ(s.force_mode, (std::array<std::uint8_t, 6>{1, 1, 1, 0, 0, 0}));

  const ForceCommand z = ForceCommand::surface_contact(10.0, Vector3::zero());
  EXPECT_EQ(z.target_force, Vector3::zero());
  EXPECT_EQ(z.force_mode, (std::array<std::uint8_t, 6>{1, 1, 1, 0, 0, 0}));
}

TEST(ForceCommand, BuildersSetTimeoutAndFrame) {
  const ForceCommand c = ForceCommand::force_only(Vector3::make(1, 0, 0)).with_timeout(2.5).with_frame_id("tool0");
  EXPECT_EQ(c.timeout_seconds, 2.5);
  EXPECT_TRUE(c.has_timeout());
  EXPECT_EQ(c.frame_id_str(), "tool0");
  EXPECT_THROW((void)c.with_frame_id(std::string(32, 'f')), std::invalid_argument);
  EXPECT_EQ(sizeof(ForceCommand), 224u);
  EXPECT_EQ(offsetof(ForceCommand, position_setpoint), 56u);
}

// ===========================================================================
// ContactInfo

TEST(ContactInfo, MakeUsesHorusDefaults) {
  const ContactInfo c = ContactInfo::make(ContactState::StableContact, 12.5);
  EXPECT_EQ(c.state_enum(), ContactState::StableContact);
  EXPECT_EQ(c.state, 2u);
  EXPECT_EQ(c.contact_force, 12.5);
  EXPECT_EQ(c.contact_normal, Vector3::make(0, 0, 1));
  EXPECT_EQ(c.contact_point, Point3::origin());
  EXPECT_EQ(c.confidence, 0.5f);
  EXPECT_EQ(to_string(ContactState::ContactLoss), "ContactLoss");
}

TEST(ContactInfo, InContactForInitialStableAndSlidingOnly) {
  EXPECT_FALSE(ContactInfo::make(ContactState::NoContact, 0).is_in_contact());
  EXPECT_TRUE(ContactInfo::make(ContactState::InitialContact, 1).is_in_contact());
  EXPECT_TRUE(ContactInfo::make(ContactState::StableContact, 1).is_in_contact());
  EXPECT_FALSE(ContactInfo::make(ContactState::ContactLoss, 1).is_in_contact());
  EXPECT_TRUE(ContactInfo::make(ContactState::Sliding, 1).is_in_contact());
  EXPECT_FALSE(ContactInfo::make(ContactState::Impact, 1).is_in_contact());
  ContactInfo odd{};
  odd.state = 77;
  EXPECT_FALSE(odd.is_in_contact());
}

TEST(ContactInfo, DurationIsZeroWithoutAStartAndNeverNegative) {
  ContactInfo c = ContactInfo::make(ContactState::StableContact, 1);
  c.timestamp_ns = 5'500'000'000ULL;
  EXPECT_EQ(c.contact_duration_seconds(), 0.0);
  c.contact_start_time = 3'000'000'000ULL;
  EXPECT_DOUBLE_EQ(c.contact_duration_seconds(), 2.5);
  c.contact_start_time = 6'000'000'000ULL;  // after the timestamp
  EXPECT_EQ(c.contact_duration_seconds(), 0.0);
  EXPECT_EQ(sizeof(ContactInfo), 136u);
}

// ===========================================================================
// HapticFeedback

TEST(HapticFeedback, VibrationClampsIntensityToZeroOne) {
  const HapticFeedback h = HapticFeedback::vibration(0.5f, 200.0f, 0.1f);
  EXPECT_EQ(h.vibration_intensity, 0.5f);
  EXPECT_EQ(h.vibration_frequency, 200.0f);
  EXPECT_EQ(h.duration_seconds, 0.1f);
  EXPECT_EQ(h.pattern_type, HapticFeedback::PATTERN_CONSTANT);
  EXPECT_TRUE(h.is_enabled());
  EXPECT_EQ(HapticFeedback::vibration(1.5f, 1, 1).vibration_intensity, 1.0f);
  EXPECT_EQ(HapticFeedback::vibration(-0.2f, 1, 1).vibration_intensity, 0.0f);
  EXPECT_EQ(HapticFeedback::vibration(std::numeric_limits<float>::quiet_NaN(), 1, 1).vibration_intensity, 0.0f);
}

TEST(HapticFeedback, ForceAndPulse) {
  const HapticFeedback f = HapticFeedback::force(Vector3::make(0, 3, 4), 0.25f);
  EXPECT_EQ(f.vibration_intensity, 0.0f);
  EXPECT_DOUBLE_EQ(f.force_magnitude(), 5.0);
  EXPECT_EQ(f.duration_seconds, 0.25f);
  EXPECT_TRUE(f.is_enabled());
  const HapticFeedback p = HapticFeedback::pulse(2.0f, 50.0f, 1.0f);
  EXPECT_EQ(p.pattern_type, HapticFeedback::PATTERN_PULSE);
  EXPECT_EQ(p.vibration_intensity, 1.0f);
  EXPECT_EQ(HapticFeedback::PATTERN_RAMP, 2u);
  EXPECT_EQ(sizeof(HapticFeedback), 56u);
}

// ===========================================================================
// AudioFrame

TEST(AudioEncoding, ValuesAndNames) {
  static_assert(static_cast<int>(AudioEncoding::F32) == 0 && static_cast<int>(AudioEncoding::I16) == 1);
  EXPECT_EQ(to_string(AudioEncoding::I16), "I16");
  AudioEncoding e{};
  EXPECT_TRUE(horus::reflect::enum_from_name("I16", e));
  EXPECT_EQ(e, AudioEncoding::I16);
}

TEST(AudioFrame, MonoHoldsTheSamplesAndKnowsItsDuration) {
  const std::vector<float> pcm(1600, 0.25f);
  const AudioFrame f = AudioFrame::mono(16000, pcm);
  EXPECT_EQ(f.num_samples, 1600u);
  EXPECT_EQ(f.sample_rate, 16000u);
  EXPECT_EQ(f.channels, 1u);
  EXPECT_EQ(f.encoding_enum(), AudioEncoding::F32);
  EXPECT_EQ(f.frame_count(), 1600u);
  EXPECT_EQ(f.valid_samples().size(), 1600u);
  EXPECT_DOUBLE_EQ(f.duration_ms(), 100.0);
  EXPECT_DOUBLE_EQ(f.duration_seconds(), 0.1);
  EXPECT_EQ(f.samples[1599], 0.25f);
  EXPECT_EQ(f.samples[1600], 0.0f);
}

TEST(AudioFrame, StereoSamplesAreInterleaved) {
  const std::vector<float> lr{0.1f, -0.1f, 0.2f, -0.2f, 0.3f, -0.3f};
  const AudioFrame f = AudioFrame::stereo(48000, lr);
  EXPECT_EQ(f.channels, 2u);
  EXPECT_EQ(f.frame_count(), 3u);
  EXPECT_EQ(f.sample_at(0, 0), 0.1f);
  EXPECT_EQ(f.sample_at(0, 1), -0.1f);
  EXPECT_EQ(f.sample_at(2, 1), -0.3f);
  EXPECT_EQ(f.sample_at(3, 0), std::nullopt);
  EXPECT_EQ(f.sample_at(0, 2), std::nullopt);
  EXPECT_DOUBLE_EQ(f.duration_ms(), 3.0 / 48.0);
  const AudioFrame four = AudioFrame::make(16000, 4, std::vector<float>(64, 0.0f));
  EXPECT_EQ(four.frame_count(), 16u);
}

TEST(AudioFrame, HoldsExactly4800SamplesAndRefusesMore) {
  EXPECT_EQ(AudioFrame::kMaxSamples, 4800u);
  static_assert(std::tuple_size_v<decltype(AudioFrame::samples)> == 4800);
  const std::vector<float> full(4800, 0.5f);
  EXPECT_EQ(AudioFrame::mono(48000, full).num_samples, 4800u);
  const std::vector<float> over(4801, 0.5f);
  const auto f = AudioFrame::create(48000, 1, over);
  ASSERT_FALSE(f.has_value());
  EXPECT_TRUE(contains(f.error(), "4800")) << f.error();
  EXPECT_TRUE(contains(f.error(), "4801")) << f.error();
  EXPECT_THROW((void)AudioFrame::mono(48000, over), std::invalid_argument);
}

TEST(AudioFrame, RefusesZeroRateZeroChannelsAndPartialFrames) {
  const std::vector<float> three(3, 0.0f);
  EXPECT_FALSE(AudioFrame::create(0, 1, three).has_value());
  EXPECT_FALSE(AudioFrame::create(16000, 0, three).has_value());
  const auto odd = AudioFrame::create(16000, 2, three);
  ASSERT_FALSE(odd.has_value());
  EXPECT_TRUE(contains(odd.error(), "not a multiple")) << odd.error();
  EXPECT_THROW((void)AudioFrame::stereo(16000, three), std::invalid_argument);
  EXPECT_TRUE(AudioFrame::create(16000, 3, three).has_value());
}

TEST(AudioFrame, ZeroFrameAndCorruptCountsAreSafe) {
  AudioFrame f{};
  EXPECT_EQ(f.duration_ms(), 0.0);
  EXPECT_EQ(f.frame_count(), 0u);
  EXPECT_TRUE(f.valid_samples().empty());
  f.num_samples = 1'000'000;
  f.channels = 1;
  f.sample_rate = 48000;
  EXPECT_EQ(f.valid_samples().size(), 4800u);
  EXPECT_EQ(f.frame_count(), 4800u);
  EXPECT_DOUBLE_EQ(f.duration_ms(), 100.0);
}

TEST(AudioFrame, BuildersSetFrameIdAndTimestamp) {
  const AudioFrame f = AudioFrame::mono(16000, std::vector<float>{0.0f}).with_frame_id("mic_left").with_timestamp(99);
  EXPECT_EQ(f.frame_id_str(), "mic_left");
  EXPECT_EQ(f.timestamp_ns, 99u);
  EXPECT_THROW((void)f.with_frame_id(std::string(32, 'm')), std::invalid_argument);
  AudioFrame g = f;
  g.set_encoding(AudioEncoding::I16);
  EXPECT_EQ(g.encoding, 1u);
}

TEST(AudioFrame, LogSummaryHasUnits) {
  const AudioFrame f = AudioFrame::stereo(48000, std::vector<float>(960, 0.0f)).with_frame_id("mic_array");
  EXPECT_EQ(f.log_summary(), "AudioFrame(2 ch, 48000 Hz, 960 samples, 10.0 ms, F32, mic_array)");
  AudioFrame odd = AudioFrame::mono(8000, std::vector<float>(80, 0.0f));
  odd.encoding = 7;
  EXPECT_EQ(odd.log_summary(), "AudioFrame(1 ch, 8000 Hz, 80 samples, 10.0 ms, encoding 7)");
}

TEST(AudioFrame, LayoutMatchesHorus) {
  EXPECT_EQ(offsetof(AudioFrame, num_samples), 19200u);
  EXPECT_EQ(offsetof(AudioFrame, channels), 19208u);
  EXPECT_EQ(offsetof(AudioFrame, timestamp_ns), 19216u);
  EXPECT_EQ(offsetof(AudioFrame, frame_id), 19224u);
  EXPECT_EQ(sizeof(AudioFrame), 19256u);
}

// ===========================================================================
// Properties of every message added here

template <>
NodeHeartbeat sample<NodeHeartbeat>() {
  NodeHeartbeat hb = NodeHeartbeat::make(NodeState::Running, HealthStatus::Warning, 1'700'000'000);
  hb.tick_count = 4'000'000'000u;
  hb.target_rate = 100.0f;
  hb.actual_rate = 99.5f;
  hb.error_count = 3;
  hb.last_tick_timestamp = 1'699'999'999;
  return hb;
}
template <>
Status sample<Status>() {
  Status s = Status::warn(404, "sensor \"lidar\" timed out").with_component("lidar_driver");
  s.timestamp_ns = 18'446'744'073'709'551'615ULL;
  return s;
}
template <>
DiagnosticStatus sample<DiagnosticStatus>() {
  DiagnosticStatus s = DiagnosticStatus::fatal(500, "watchdog expired").with_component("supervisor");
  s.timestamp_ns = 11;
  return s;
}
template <>
EmergencyStop sample<EmergencyStop>() {
  EmergencyStop e = EmergencyStop::engage("bumper pressed").with_source("bumper_front");
  e.auto_reset = 1;
  e.timestamp_ns = 12;
  return e;
}
template <>
SafetyStatus sample<SafetyStatus>() {
  SafetyStatus s = SafetyStatus::make();
  s.estop_engaged = 1;
  s.set_fault(77);
  s.timestamp_ns = 13;
  return s;
}
template <>
ResourceUsage sample<ResourceUsage>() {
  return ResourceUsage{12.5f, 1ULL << 33, 40.0f, 5ULL << 40, 71.25f, 123456, 654321, 55.5f, 24, 14};
}
template <>
DiagnosticValue sample<DiagnosticValue>() { return *DiagnosticValue::from_float("temp_c", -3.25); }
template <>
DiagnosticReport sample<DiagnosticReport>() {
  DiagnosticReport r = DiagnosticReport::make("motor_left");
  r.add_float("temp_c", 45.5);
  r.add_int("rpm", -1200);
  r.add_bool("ok", false);
  r.add_string("mode", "torque");
  r.set_level(StatusLevel::Error);
  r.timestamp_ns = 15;
  return r;
}
template <>
WrenchStamped sample<WrenchStamped>() {
  WrenchStamped w = WrenchStamped::make(Vector3::make(1, -2, 3.5), Vector3::make(0.1, 0.2, -0.3)).with_frame_id("ft");
  w.point_of_application = Point3::make(0, 0, 0.05);
  w.timestamp_ns = 16;
  return w;
}
template <>
ImpedanceParameters sample<ImpedanceParameters>() {
  ImpedanceParameters p = ImpedanceParameters::compliant();
  p.enable();
  p.timestamp_ns = 17;
  return p;
}
template <>
ForceCommand sample<ForceCommand>() {
  ForceCommand c = ForceCommand::hybrid({0, 0, 1, 1, 0, 0}, Vector3::make(0, 0, -5), Vector3::make(0.4, 0.1, 0.2))
                       .with_timeout(1.5)
                       .with_frame_id("tool0");
  c.target_torque = Vector3::make(0, 0.5, 0);
  c.orientation_setpoint = Vector3::make(0, 3.0, 0.1);
  c.gains[3] = 0.5;
  c.timestamp_ns = 18;
  return c;
}
template <>
ContactInfo sample<ContactInfo>() {
  ContactInfo c = ContactInfo::make(ContactState::Sliding, 4.5);
  c.contact_point = Point3::make(0.1, 0.2, 0.3);
  c.stiffness = 2000.0;
  c.damping = 10.0;
  c.confidence = 0.875f;
  c.contact_start_time = 1000;
  c.set_frame_id("finger_tip");
  c.timestamp_ns = 2000;
  return c;
}
template <>
HapticFeedback sample<HapticFeedback>() {
  HapticFeedback h = HapticFeedback::pulse(0.75f, 150.0f, 0.5f);
  h.force_feedback = Vector3::make(1, 0, -1);
  h.timestamp_ns = 19;
  return h;
}
template <>
AudioFrame sample<AudioFrame>() {
  std::vector<float> pcm(4800);
  for (std::size_t i = 0; i < pcm.size(); ++i) pcm[i] = static_cast<float>(i % 200) / 200.0f - 0.5f;
  AudioFrame f = AudioFrame::stereo(48000, pcm).with_frame_id("mic_array").with_timestamp(20);
  f.set_encoding(AudioEncoding::I16);
  return f;
}
template <>
GenericMessage sample<GenericMessage>() {
  // Packed as app::SensorReading of test_msg_generic.cpp packs (an array of its fields).
  const auto packed = GenericMessage::from_value(std::make_tuple(22.5, 60.0, std::string(300, 'g'), std::vector<int>{1, 2, 3}));
  return *GenericMessage::with_metadata(packed->data(), "sensor.generic \xE2\x9C\x93");
}

// The diagnostics, force, audio and generic types: the properties every message has
// (msg_properties_test.hpp; GenericMessage keeps its fields private), and that each prints a
// timestamp or its key field.
using DiagnosticsForceAudioMessages =
    ::testing::Types<NodeHeartbeat, Status, DiagnosticStatus, EmergencyStop, SafetyStatus, ResourceUsage,
                     DiagnosticValue, DiagnosticReport, WrenchStamped, ImpedanceParameters, ForceCommand, ContactInfo,
                     HapticFeedback, AudioFrame, GenericMessage>;
template <>
constexpr bool kNotAggregate<GenericMessage> = true;
INSTANTIATE_TYPED_TEST_SUITE_P(DiagnosticsForceAudio, MessageProperties, DiagnosticsForceAudioMessages);

template <class T>
class EveryNewMessage : public ::testing::Test {};
TYPED_TEST_SUITE(EveryNewMessage, DiagnosticsForceAudioMessages);

TYPED_TEST(EveryNewMessage, FormatsATimestampOrAKeyField) {
  const std::string text = fmt::format("{}", sample<TypeParam>());
  EXPECT_TRUE(contains(text, "timestamp_ns: ") || contains(text, "heartbeat_timestamp: ") ||
              contains(text, "value_type: ") || contains(text, "metadata: "))
      << text.substr(0, 200);
}

// Field-level JSON and fmt checks for a few types where the text matters.

TEST(Formatting, StatusPrintsItsTextFields) {
  EXPECT_EQ(fmt::format("{}", Status::warn(7, "hot").with_component("motor")),
            "Status { level: 1, code: 7, message: \"hot\", component: \"motor\", timestamp_ns: 0 }");
}

TEST(Formatting, DiagnosticValueAndEStopPrintReadably) {
  EXPECT_EQ(fmt::format("{}", *DiagnosticValue::from_bool("ok", true)),
            "DiagnosticValue { key: \"ok\", value: \"true\", value_type: 3 }");
  EXPECT_EQ(fmt::format("{}", EmergencyStop::engage("stop")),
            "EmergencyStop { engaged: 1, reason: \"stop\", source: \"\", auto_reset: 0, timestamp_ns: 0 }");
}

TEST(Formatting, GenericMessageJsonUsesHorusFieldNames) {
  const nlohmann::json j = horus::to_json(sample<GenericMessage>());
  for (const char* key :
       {"inline_data", "inline_len", "overflow_data", "overflow_len", "metadata", "metadata_len", "_padding"})
    EXPECT_TRUE(j.contains(key)) << key;
  EXPECT_EQ(j["metadata"], "sensor.generic \xE2\x9C\x93");
  EXPECT_EQ(j.size(), 7u);
}

TEST(Formatting, LogSummaryFallsBackToTheFullFormatForSmallMessages) {
  EXPECT_EQ(horus::log_summary(SafetyStatus::make()), horus::to_string(SafetyStatus::make()));
  EXPECT_EQ(horus::log_summary(sample<AudioFrame>()), sample<AudioFrame>().log_summary());
}

}  // namespace
