// Unit tests of the actuator, time and input messages: MotorCommand, DifferentialDriveCommand,
// ServoCommand, PidConfig, TrajectoryPoint (control.hpp), Clock, TimeReference (time.hpp),
// JoystickInput, KeyboardInput (input.hpp).
#include "msg_motion_test.hpp"

namespace {

// ===========================================================================
// MotorCommand

TEST(MotorCommand, ModeConstantsMatchHorus) {
  EXPECT_EQ(MotorCommand::MODE_VELOCITY, 0);
  EXPECT_EQ(MotorCommand::MODE_POSITION, 1);
  EXPECT_EQ(MotorCommand::MODE_TORQUE, 2);
  EXPECT_EQ(MotorCommand::MODE_VOLTAGE, 3);
}

TEST(MotorCommand, VelocityCommandIsEnabledWithoutLimits) {
  const MotorCommand c = MotorCommand::velocity(3, 12.5f);
  EXPECT_EQ(c.motor_id, 3u);
  EXPECT_EQ(c.mode, MotorCommand::MODE_VELOCITY);
  EXPECT_EQ(c.target, 12.5f);
  EXPECT_EQ(c.max_velocity, kInff);
  EXPECT_EQ(c.max_acceleration, kInff);
  EXPECT_EQ(c.feed_forward, 0.0f);
  EXPECT_EQ(c.enable, 1u);
  EXPECT_EQ(c.timestamp_ns, 0u);
  EXPECT_TRUE(c.is_valid());
}

TEST(MotorCommand, PositionCommandCarriesItsVelocityLimit) {
  const MotorCommand c = MotorCommand::position(70000, 1.57f, 2.0f);
  EXPECT_EQ(c.motor_id, 70000u);  // u32 ids, as the spec types them
  EXPECT_EQ(c.mode, MotorCommand::MODE_POSITION);
  EXPECT_EQ(c.target, 1.57f);
  EXPECT_EQ(c.max_velocity, 2.0f);
  EXPECT_EQ(c.max_acceleration, kInff);
  EXPECT_EQ(c.enable, 1u);
  EXPECT_TRUE(c.is_valid());
}

TEST(MotorCommand, StopIsZeroVelocityAndDisabled) {
  const MotorCommand c = MotorCommand::stop(2);
  EXPECT_EQ(c.motor_id, 2u);
  EXPECT_EQ(c.mode, MotorCommand::MODE_VELOCITY);
  EXPECT_EQ(c.target, 0.0f);
  EXPECT_EQ(c.enable, 0u);
  EXPECT_TRUE(c.is_valid());
}

TEST(MotorCommand, IsValidRejectsNonFiniteTargetsNaNOrNegativeLimitsAndUnknownModes) {
  const MotorCommand ok = MotorCommand::position(1, 1.0f, 2.0f);
  MotorCommand c = ok;
  c.target = kNaNf;
  EXPECT_FALSE(c.is_valid());
  c = ok;
  c.target = kInff;
  EXPECT_FALSE(c.is_valid());
  c = ok;
  c.feed_forward = kNaNf;
  EXPECT_FALSE(c.is_valid());
  c = ok;
  c.max_velocity = kNaNf;
  EXPECT_FALSE(c.is_valid());
  c = ok;
  c.max_acceleration = -1.0f;
  EXPECT_FALSE(c.is_valid());
  c = ok;
  c.max_velocity = 0.0f;
  EXPECT_TRUE(c.is_valid());
  c = ok;
  c.mode = 4.0f;
  EXPECT_FALSE(c.is_valid());
  c.mode = 1.5f;
  EXPECT_FALSE(c.is_valid());
  c.mode = MotorCommand::MODE_TORQUE;
  EXPECT_TRUE(c.is_valid());
  c.mode = MotorCommand::MODE_VOLTAGE;
  EXPECT_TRUE(c.is_valid());
}

TEST(MotorCommand, NoLimitTravelsThroughJsonAsNullAndComesBackAsNaN) {
  const MotorCommand c = MotorCommand::velocity(1, 1.0f);
  const nlohmann::json j = horus::to_json(c);
  EXPECT_TRUE(j["max_velocity"].is_null()) << j.dump();
  const MotorCommand back = horus::from_json<MotorCommand>(j);
  EXPECT_TRUE(std::isnan(back.max_velocity));
  EXPECT_FALSE(back.is_valid());  // a receiver cannot mistake it for a valid limit
}

// ===========================================================================
// DifferentialDriveCommand

TEST(DifferentialDriveCommand, MakeIsEnabledAndStopIsDisabled) {
  const auto c = DifferentialDriveCommand::make(0.4f, 0.6f);
  EXPECT_EQ(c.left_velocity, 0.4f);
  EXPECT_EQ(c.right_velocity, 0.6f);
  EXPECT_EQ(c.max_acceleration, kInff);
  EXPECT_EQ(c.enable, 1u);
  EXPECT_TRUE(c.is_valid());
  const auto s = DifferentialDriveCommand::stop();
  EXPECT_EQ(s.left_velocity, 0.0f);
  EXPECT_EQ(s.right_velocity, 0.0f);
  EXPECT_EQ(s.enable, 0u);
  EXPECT_TRUE(s.is_valid());
}

TEST(DifferentialDriveCommand, FromTwistSplitsTheYawRateAcrossTheWheelBase) {
  // 1 m/s forward turning left at 0.5 rad/s on a 0.4 m wheel base.
  const auto c = DifferentialDriveCommand::from_twist(1.0, 0.5, 0.4);
  EXPECT_FLOAT_EQ(c.left_velocity, 0.9f);
  EXPECT_FLOAT_EQ(c.right_velocity, 1.1f);
  EXPECT_EQ(c.enable, 1u);
  // Turning on the spot: opposite wheel speeds.
  const auto spin = DifferentialDriveCommand::from_twist(0.0, 1.0, 0.5);
  EXPECT_FLOAT_EQ(spin.left_velocity, -0.25f);
  EXPECT_FLOAT_EQ(spin.right_velocity, 0.25f);
  // Straight ahead: equal speeds; turning right: the left wheel is faster.
  const auto straight = DifferentialDriveCommand::from_twist(0.7, 0.0, 0.5);
  EXPECT_EQ(straight.left_velocity, straight.right_velocity);
  const auto right = DifferentialDriveCommand::from_twist(0.5, -1.0, 0.5);
  EXPECT_GT(right.left_velocity, right.right_velocity);
}

TEST(DifferentialDriveCommand, FromTwistMessageUsesForwardSpeedAndYawRate) {
  Twist t = Twist::make({1.0, 5.0, 5.0}, {5.0, 5.0, 0.5});  // y, z, roll and pitch rates are ignored
  EXPECT_EQ(DifferentialDriveCommand::from_twist(t, 0.4), DifferentialDriveCommand::from_twist(1.0, 0.5, 0.4));
}

TEST(DifferentialDriveCommand, ZeroWheelBaseIgnoresTheYawRate) {
  const auto c = DifferentialDriveCommand::from_twist(0.3, 2.0, 0.0);
  EXPECT_EQ(c.left_velocity, 0.3f);
  EXPECT_EQ(c.right_velocity, 0.3f);
}

TEST(DifferentialDriveCommand, NonFiniteInputsGiveAnInvalidCommand) {
  EXPECT_FALSE(DifferentialDriveCommand::from_twist(kNaN, 0.0, 0.4).is_valid());
  EXPECT_FALSE(DifferentialDriveCommand::from_twist(0.5, kInf, 0.4).is_valid());
  EXPECT_FALSE(DifferentialDriveCommand::from_twist(0.5, 0.1, kNaN).is_valid());
  auto c = DifferentialDriveCommand::make(0.1f, 0.1f);
  c.max_acceleration = kNaNf;
  EXPECT_FALSE(c.is_valid());
  c.max_acceleration = -0.5f;
  EXPECT_FALSE(c.is_valid());
  c.max_acceleration = 0.5f;
  EXPECT_TRUE(c.is_valid());
}

// ===========================================================================
// ServoCommand

TEST(ServoCommand, MakeHasHalfSpeedAndTorqueOn) {
  const ServoCommand s = ServoCommand::make(7, 1.0f);
  EXPECT_EQ(s.servo_id, 7u);
  EXPECT_EQ(s.position, 1.0f);
  EXPECT_EQ(s.speed, 0.5f);
  EXPECT_EQ(s.enable, 1u);
  EXPECT_EQ(s.timestamp_ns, 0u);
  EXPECT_TRUE(s.is_valid());
}

TEST(ServoCommand, WithSpeedClampsIntoZeroToOne) {
  EXPECT_EQ(ServoCommand::with_speed(1, 0.5f, 0.75f).speed, 0.75f);
  EXPECT_EQ(ServoCommand::with_speed(1, 0.5f, 1.5f).speed, 1.0f);
  EXPECT_EQ(ServoCommand::with_speed(1, 0.5f, -0.2f).speed, 0.0f);
  const ServoCommand nan_speed = ServoCommand::with_speed(1, 0.5f, kNaNf);
  EXPECT_TRUE(std::isnan(nan_speed.speed));
  EXPECT_FALSE(nan_speed.is_valid());
}

TEST(ServoCommand, DisableRemovesTorque) {
  const ServoCommand s = ServoCommand::disable(4);
  EXPECT_EQ(s.servo_id, 4u);
  EXPECT_EQ(s.enable, 0u);
  EXPECT_EQ(s.position, 0.0f);
  EXPECT_EQ(s.speed, 0.0f);
}

TEST(ServoCommand, FromDegreesConvertsToRadians) {
  EXPECT_FLOAT_EQ(ServoCommand::from_degrees(1, 90.0f).position, static_cast<float>(kPi / 2));
  EXPECT_FLOAT_EQ(ServoCommand::from_degrees(1, -180.0f).position, static_cast<float>(-kPi));
  EXPECT_EQ(ServoCommand::from_degrees(1, 90.0f).speed, 0.5f);
}

TEST(ServoCommand, IsValidIncludesSpeedLimitsAndRejectsNonFinitePosition) {
  ServoCommand s = ServoCommand::make(1, 0.0f);
  s.speed = 0.0f;
  EXPECT_TRUE(s.is_valid());
  s.speed = 1.0f;
  EXPECT_TRUE(s.is_valid());
  s.speed = std::nextafter(1.0f, 2.0f);
  EXPECT_FALSE(s.is_valid());
  s.speed = -0.1f;
  EXPECT_FALSE(s.is_valid());
  s.speed = 0.5f;
  s.position = kNaNf;
  EXPECT_FALSE(s.is_valid());
  s.position = kInff;
  EXPECT_FALSE(s.is_valid());
}

// ===========================================================================
// PidConfig

TEST(PidConfig, MakeHasNoLimitsAndAntiWindupOn) {
  const PidConfig c = PidConfig::make(1.0, 0.1, 0.01);
  EXPECT_EQ(c.controller_id, 0u);
  EXPECT_EQ(c.kp, 1.0);
  EXPECT_EQ(c.ki, 0.1);
  EXPECT_EQ(c.kd, 0.01);
  EXPECT_EQ(c.integral_limit, kInf);
  EXPECT_EQ(c.output_limit, kInf);
  EXPECT_EQ(c.anti_windup, 1u);
  EXPECT_TRUE(c.is_valid());
}

TEST(PidConfig, ProportionalPiAndPdLeaveTheOtherGainsZero) {
  EXPECT_EQ(PidConfig::proportional(2.0), PidConfig::make(2.0, 0.0, 0.0));
  EXPECT_EQ(PidConfig::pi(2.0, 0.5), PidConfig::make(2.0, 0.5, 0.0));
  EXPECT_EQ(PidConfig::pd(2.0, 0.25), PidConfig::make(2.0, 0.0, 0.25));
}

TEST(PidConfig, WithLimitsReturnsACopyWithBothLimits) {
  const PidConfig base = PidConfig::make(1.0, 0.1, 0.01);
  const PidConfig limited = base.with_limits(10.0, 100.0);
  EXPECT_EQ(limited.integral_limit, 10.0);
  EXPECT_EQ(limited.output_limit, 100.0);
  EXPECT_EQ(limited.kp, 1.0);
  EXPECT_EQ(base.integral_limit, kInf);
  EXPECT_TRUE(limited.is_valid());
}

TEST(PidConfig, IsValidRejectsNegativeOrNonFiniteGainsAndNaNOrNegativeLimits) {
  EXPECT_FALSE(PidConfig::make(-1.0, 0.1, 0.01).is_valid());
  EXPECT_FALSE(PidConfig::make(1.0, -0.1, 0.01).is_valid());
  EXPECT_FALSE(PidConfig::make(1.0, 0.1, -0.01).is_valid());
  EXPECT_FALSE(PidConfig::make(kNaN, 0.1, 0.01).is_valid());
  EXPECT_FALSE(PidConfig::make(1.0, kInf, 0.01).is_valid());
  EXPECT_FALSE(PidConfig::make(1.0, 0.1, 0.01).with_limits(kNaN, 1.0).is_valid());
  EXPECT_FALSE(PidConfig::make(1.0, 0.1, 0.01).with_limits(1.0, -1.0).is_valid());
  EXPECT_TRUE(PidConfig::make(0.0, 0.0, 0.0).with_limits(0.0, kInf).is_valid());
}

// ===========================================================================
// TrajectoryPoint

TEST(TrajectoryPoint, New2dIsPlanarWithIdentityOrientation) {
  const TrajectoryPoint p = TrajectoryPoint::new_2d(1.0, 2.0, 0.5, -0.5, 3.0);
  EXPECT_EQ(p.position, (std::array<double, 3>{1.0, 2.0, 0.0}));
  EXPECT_EQ(p.velocity, (std::array<double, 3>{0.5, -0.5, 0.0}));
  EXPECT_EQ(p.acceleration, (std::array<double, 3>{}));
  EXPECT_EQ(p.orientation, (std::array<double, 4>{0.0, 0.0, 0.0, 1.0}));
  EXPECT_EQ(p.angular_velocity, (std::array<double, 3>{}));
  EXPECT_EQ(p.time_from_start, 3.0);
}

TEST(TrajectoryPoint, StationaryIsAtRestAtTimeZero) {
  const TrajectoryPoint p = TrajectoryPoint::stationary(1.0, 2.0, 3.0);
  EXPECT_EQ(p.position, (std::array<double, 3>{1.0, 2.0, 3.0}));
  EXPECT_EQ(p.velocity, (std::array<double, 3>{}));
  EXPECT_EQ(p.orientation, (std::array<double, 4>{0.0, 0.0, 0.0, 1.0}));
  EXPECT_EQ(p.time_from_start, 0.0);
}

// ===========================================================================
// Clock

TEST(Clock, SourceConstantsMatchHorus) {
  EXPECT_EQ(Clock::SOURCE_WALL, 0);
  EXPECT_EQ(Clock::SOURCE_SIM, 1);
  EXPECT_EQ(Clock::SOURCE_REPLAY, 2);
}

TEST(Clock, WallClockPutsTheTimeInEveryTimeFieldAtRealTimeSpeed) {
  const Clock c = Clock::wall_clock(1'700'000'000'000'000'000ULL);
  EXPECT_EQ(c.clock_ns, 1'700'000'000'000'000'000ULL);
  EXPECT_EQ(c.realtime_ns, c.clock_ns);
  EXPECT_EQ(c.timestamp_ns, c.clock_ns);
  EXPECT_EQ(c.sim_speed, 1.0);
  EXPECT_EQ(c.source, Clock::SOURCE_WALL);
  EXPECT_FALSE(c.is_paused());
}

TEST(Clock, WallClockWithoutArgumentsReadsTheSystemClock) {
  const auto now = [] {
    return static_cast<std::uint64_t>(
        std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::system_clock::now().time_since_epoch())
            .count());
  };
  const std::uint64_t before = now();
  const Clock c = Clock::wall_clock();
  const std::uint64_t after = now();
  EXPECT_GE(c.clock_ns, before);
  EXPECT_LE(c.clock_ns, after);
  EXPECT_EQ(c.realtime_ns, c.clock_ns);
}

TEST(Clock, SimAndReplayTimeKeepTheirClockSpeedAndWallTime) {
  const Clock sim = Clock::sim_time(500'000'000, 2.0, 123);
  EXPECT_EQ(sim.source, Clock::SOURCE_SIM);
  EXPECT_EQ(sim.clock_ns, 500'000'000u);
  EXPECT_EQ(sim.sim_speed, 2.0);
  EXPECT_EQ(sim.realtime_ns, 123u);
  EXPECT_EQ(sim.timestamp_ns, 123u);
  const Clock replay = Clock::replay_time(1'000'000'000, 0.5);
  EXPECT_EQ(replay.source, Clock::SOURCE_REPLAY);
  EXPECT_EQ(replay.clock_ns, 1'000'000'000u);
  EXPECT_EQ(replay.sim_speed, 0.5);
  EXPECT_EQ(replay.realtime_ns, 0u);
  EXPECT_FALSE(replay.is_paused());
}

TEST(Clock, ElapsedSinceIsTheClockDifferenceAndZeroWhenTimeWentBack) {
  const Clock earlier = Clock::sim_time(100, 1.0);
  const Clock later = Clock::sim_time(350, 1.0);
  EXPECT_EQ(later.elapsed_since(earlier), 250u);
  EXPECT_EQ(earlier.elapsed_since(later), 0u);
  EXPECT_EQ(later.elapsed_since(later), 0u);
  EXPECT_EQ(Clock::sim_time(~0ULL, 1.0).elapsed_since(Clock{}), ~0ULL);
}

TEST(Clock, SetPausedChangesInPlaceAndWithPausedReturnsACopy) {
  Clock c = Clock::sim_time(0, 1.0);
  c.set_paused(true);
  EXPECT_TRUE(c.is_paused());
  EXPECT_EQ(c.paused, 1u);
  const Clock running = c.with_paused(false);
  EXPECT_FALSE(running.is_paused());
  EXPECT_TRUE(c.is_paused());
  c.paused = 7;  // any non-zero byte reads as paused
  EXPECT_TRUE(c.is_paused());
  c.set_paused(false);
  EXPECT_EQ(c.paused, 0u);
}

// ===========================================================================
// TimeReference

TEST(TimeReference, CreateAndMakeStoreSourceTimeAndOffset) {
  const auto t = TimeReference::create(1'000'000'000, "gps", -500);
  ASSERT_TRUE(t.has_value());
  EXPECT_EQ(t->time_ref_ns, 1'000'000'000u);
  EXPECT_EQ(t->source_str(), "gps");
  EXPECT_EQ(t->source_name(), "gps");
  EXPECT_EQ(t->offset_ns, -500);
  EXPECT_EQ(t->timestamp_ns, 0u);
  EXPECT_EQ(TimeReference::make(1'000'000'000, "gps", -500), *t);
}

TEST(TimeReference, SourceNamesThatDoNotFitAreRejected) {
  const std::string too_long(32, 's');
  EXPECT_EQ(TimeReference::create(0, too_long, 0), std::nullopt);
  EXPECT_THROW((void)TimeReference::make(0, too_long, 0), std::invalid_argument);
  EXPECT_TRUE(TimeReference::create(0, std::string(31, 's'), 0).has_value());
  TimeReference t = TimeReference::make(0, "ntp", 0);
  EXPECT_FALSE(t.set_source(too_long));
  EXPECT_EQ(t.source_str(), "ntp");
}

TEST(TimeReference, CorrectTimestampRemovesTheOffset) {
  // Local clock 500 ns ahead of the reference.
  EXPECT_EQ(TimeReference::make(1000, "ntp", 500).correct_timestamp(1500), 1000u);
  // Local clock 500 ns behind the reference.
  EXPECT_EQ(TimeReference::make(1000, "ptp", -500).correct_timestamp(500), 1000u);
  EXPECT_EQ(TimeReference::make(1000, "ptp", 0).correct_timestamp(777), 777u);
}

TEST(TimeReference, CorrectTimestampSaturatesInsteadOfWrapping) {
  constexpr std::uint64_t kMax = std::numeric_limits<std::uint64_t>::max();
  constexpr std::int64_t kMin64 = std::numeric_limits<std::int64_t>::min();
  constexpr std::int64_t kMax64 = std::numeric_limits<std::int64_t>::max();
  EXPECT_EQ(TimeReference::make(0, "gps", 1000).correct_timestamp(400), 0u);
  EXPECT_EQ(TimeReference::make(0, "gps", kMax64).correct_timestamp(kMax), kMax - static_cast<std::uint64_t>(kMax64));
  EXPECT_EQ(TimeReference::make(0, "gps", -1000).correct_timestamp(kMax - 10), kMax);
  EXPECT_EQ(TimeReference::make(0, "gps", kMin64).correct_timestamp(0), 1ULL << 63);
  EXPECT_EQ(TimeReference::make(0, "gps", kMin64).correct_timestamp(1ULL << 63), kMax);
  EXPECT_EQ(TimeReference::make(0, "gps", kMin64).correct_timestamp((1ULL << 63) - 1), kMax);
}

// ===========================================================================
// JoystickInput

TEST(JoystickInput, ButtonPressAndRelease) {
  const JoystickInput down = JoystickInput::new_button(0, 3, "A", true);
  EXPECT_EQ(down.joystick_id, 0u);
  EXPECT_EQ(down.element_id, 3u);
  EXPECT_EQ(down.element_name_str(), "A");
  EXPECT_EQ(down.event_type_str(), "button");
  EXPECT_TRUE(down.is_button());
  EXPECT_TRUE(down.is_pressed());
  EXPECT_EQ(down.value, 1.0f);
  EXPECT_EQ(down.timestamp_ms, 0u);
  const JoystickInput up = JoystickInput::new_button(1, 3, "A", false);
  EXPECT_EQ(up.joystick_id, 1u);
  EXPECT_TRUE(up.is_button());
  EXPECT_FALSE(up.is_pressed());
  EXPECT_EQ(up.value, 0.0f);
}

TEST(JoystickInput, AxisAndHatEventsCarryTheirValueAndAreNotPressed) {
  const JoystickInput axis = JoystickInput::new_axis(0, 1, "LeftStickX", -0.75f);
  EXPECT_TRUE(axis.is_axis());
  EXPECT_FALSE(axis.is_button());
  EXPECT_FALSE(axis.is_hat());
  EXPECT_FALSE(axis.is_connection_event());
  EXPECT_EQ(axis.value, -0.75f);
  EXPECT_FALSE(axis.is_pressed());
  EXPECT_EQ(axis.element_name_str(), "LeftStickX");
  const JoystickInput hat = JoystickInput::new_hat(0, 0, "DPad", 1.0f);
  EXPECT_TRUE(hat.is_hat());
  EXPECT_FALSE(hat.is_axis());
  EXPECT_EQ(hat.event_type_str(), JoystickInput::EVENT_HAT);
  EXPECT_FALSE(hat.is_pressed());
}

TEST(JoystickInput, ConnectionEvents) {
  const JoystickInput on = JoystickInput::new_connection(2, true);
  EXPECT_TRUE(on.is_connection_event());
  EXPECT_TRUE(on.is_connected());
  EXPECT_EQ(on.element_name_str(), "Connected");
  EXPECT_EQ(on.joystick_id, 2u);
  const JoystickInput off = JoystickInput::new_connection(2, false);
  EXPECT_TRUE(off.is_connection_event());
  EXPECT_FALSE(off.is_connected());
  EXPECT_EQ(off.element_name_str(), "Disconnected");
  // A button with value 1 is not a connection.
  EXPECT_FALSE(JoystickInput::new_button(0, 0, "A", true).is_connected());
  JoystickInput nan_value = on;
  nan_value.value = kNaNf;
  EXPECT_FALSE(nan_value.is_connected());
}

TEST(JoystickInput, NamesThatDoNotFitAreRejected) {
  EXPECT_THROW((void)JoystickInput::new_button(0, 0, std::string(32, 'b'), true), std::invalid_argument);
  EXPECT_THROW((void)JoystickInput::new_axis(0, 0, std::string(50, 'a'), 0.0f), std::invalid_argument);
  EXPECT_NO_THROW((void)JoystickInput::new_hat(0, 0, std::string(31, 'h'), 0.0f));
  JoystickInput j = JoystickInput::new_button(0, 0, "B", true);
  EXPECT_FALSE(j.set_element_name(std::string(32, 'x')));
  EXPECT_EQ(j.element_name_str(), "B");
  EXPECT_FALSE(j.set_event_type(std::string(16, 'e')));  // 15 characters at most
  EXPECT_TRUE(j.is_button());
  EXPECT_TRUE(j.set_event_type(std::string(15, 'e')));
  EXPECT_FALSE(j.is_button());
}

// ===========================================================================
// KeyboardInput

TEST(KeyboardInput, ModifierConstantsAreTheHorusBits) {
  EXPECT_EQ(KeyboardInput::MODIFIER_CTRL, 1u);
  EXPECT_EQ(KeyboardInput::MODIFIER_ALT, 2u);
  EXPECT_EQ(KeyboardInput::MODIFIER_SHIFT, 4u);
  EXPECT_EQ(KeyboardInput::MODIFIER_SUPER, 8u);
  EXPECT_EQ(KeyboardInput::MODIFIER_HYPER, 16u);
  EXPECT_EQ(KeyboardInput::MODIFIER_META, 32u);
}

TEST(KeyboardInput, MakeStoresKeyCodeModifiersAndPressed) {
  const KeyboardInput k = KeyboardInput::make("s", 83, KeyboardInput::MODIFIER_CTRL, true);
  EXPECT_EQ(k.key_name_str(), "s");
  EXPECT_EQ(k.code, 83u);
  EXPECT_EQ(k.modifier_flags, KeyboardInput::MODIFIER_CTRL);
  EXPECT_TRUE(k.is_pressed());
  EXPECT_EQ(k.timestamp_ms, 0u);
  EXPECT_FALSE(KeyboardInput::make("s", 83, 0, false).is_pressed());
}

TEST(KeyboardInput, ModifierFlagParsesTheHorusNamesExactly) {
  EXPECT_EQ(KeyboardInput::modifier_flag("Ctrl"), KeyboardInput::MODIFIER_CTRL);
  EXPECT_EQ(KeyboardInput::modifier_flag("Alt"), KeyboardInput::MODIFIER_ALT);
  EXPECT_EQ(KeyboardInput::modifier_flag("Shift"), KeyboardInput::MODIFIER_SHIFT);
  EXPECT_EQ(KeyboardInput::modifier_flag("Super"), KeyboardInput::MODIFIER_SUPER);
  EXPECT_EQ(KeyboardInput::modifier_flag("Hyper"), KeyboardInput::MODIFIER_HYPER);
  EXPECT_EQ(KeyboardInput::modifier_flag("Meta"), KeyboardInput::MODIFIER_META);
  EXPECT_EQ(KeyboardInput::modifier_flag("ctrl"), 0u);
  EXPECT_EQ(KeyboardInput::modifier_flag("Fn"), 0u);
  EXPECT_EQ(KeyboardInput::modifier_flag(""), 0u);
}

TEST(KeyboardInput, ModifierTestsByNameByMaskAndByShortcut) {
  const KeyboardInput k =
      KeyboardInput::make("z", 90, KeyboardInput::MODIFIER_CTRL | KeyboardInput::MODIFIER_SHIFT, true);
  EXPECT_TRUE(k.has_modifier("Ctrl"));
  EXPECT_TRUE(k.has_modifier("Shift"));
  EXPECT_FALSE(k.has_modifier("Alt"));
  EXPECT_FALSE(k.has_modifier("Unknown"));
  EXPECT_TRUE(k.is_ctrl());
  EXPECT_TRUE(k.is_shift());
  EXPECT_FALSE(k.is_alt());
  EXPECT_TRUE(k.has_modifiers(KeyboardInput::MODIFIER_CTRL | KeyboardInput::MODIFIER_SHIFT));
  EXPECT_FALSE(k.has_modifiers(KeyboardInput::MODIFIER_CTRL | KeyboardInput::MODIFIER_ALT));
  EXPECT_TRUE(k.has_modifiers(0));
  const KeyboardInput plain = KeyboardInput::make("a", 65, 0, true);
  EXPECT_FALSE(plain.is_ctrl());
  EXPECT_FALSE(plain.has_modifier("Ctrl"));
  EXPECT_TRUE(plain.modifiers().empty());
}

TEST(KeyboardInput, ModifiersListsNamesInHorusOrderAndSkipsUnknownBits) {
  const KeyboardInput k = KeyboardInput::make(
      "F4", 115, KeyboardInput::MODIFIER_META | KeyboardInput::MODIFIER_ALT | KeyboardInput::MODIFIER_CTRL | (1u << 20),
      true);
  EXPECT_EQ(k.modifiers(), (std::vector<std::string_view>{"Ctrl", "Alt", "Meta"}));
}

TEST(KeyboardInput, KeyNamesThatDoNotFitAreRejected) {
  EXPECT_THROW((void)KeyboardInput::make(std::string(32, 'k'), 1, 0, true), std::invalid_argument);
  EXPECT_NO_THROW((void)KeyboardInput::make(std::string(31, 'k'), 1, 0, true));
  KeyboardInput k = KeyboardInput::make("Enter", 13, 0, true);
  EXPECT_FALSE(k.set_key_name(std::string(32, 'k')));
  EXPECT_EQ(k.key_name_str(), "Enter");
}

}  // namespace
