// Unit tests of the motion, power, GNSS, actuator, time and input messages:
// Accel, AccelStamped, PoseWithCovariance, TwistWithCovariance (geometry.hpp),
// Range, BatteryState, NavSatFix (sensor.hpp), MotorCommand,
// DifferentialDriveCommand, ServoCommand, PidConfig, TrajectoryPoint
// (control.hpp), Clock, TimeReference (time.hpp), JoystickInput, KeyboardInput
// (input.hpp): helpers and their edge cases, the layouts the spec fixes, fmt
// and JSON.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <array>
#include <bit>
#include <chrono>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <limits>
#include <numbers>
#include <optional>
#include <ostream>
#include <stdexcept>
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

#include "horus/format.hpp"
#include "horus/json.hpp"
#include "horus/msg/control.hpp"
#include "horus/msg/geometry.hpp"
#include "horus/msg/input.hpp"
#include "horus/msg/sensor.hpp"
#include "horus/msg/time.hpp"
#include "message_test_support.hpp"

namespace {

using namespace horus_test::values;

using namespace horus::msg;


// ===========================================================================
// Accel, AccelStamped

TEST(Accel, MakeSetsBothVectorsAndLeavesTheTimestampZero) {
  const Accel a = Accel::make({1.0, -2.0, 9.81}, {0.1, 0.2, 0.3});
  EXPECT_EQ(a.linear, (std::array<double, 3>{1.0, -2.0, 9.81}));
  EXPECT_EQ(a.angular, (std::array<double, 3>{0.1, 0.2, 0.3}));
  EXPECT_EQ(a.timestamp_ns, 0u);
  EXPECT_TRUE(a.is_valid());
  EXPECT_TRUE(Accel{}.is_valid());
}

TEST(Accel, IsValidRejectsNaNOrInfinityInAnyComponent) {
  for (std::size_t i = 0; i < 3; ++i) {
    for (double bad : {kNaN, kInf, -kInf}) {
      Accel lin = Accel::make({1, 2, 3}, {4, 5, 6});
      lin.linear[i] = bad;
      EXPECT_FALSE(lin.is_valid()) << "linear[" << i << "] = " << bad;
      Accel ang = Accel::make({1, 2, 3}, {4, 5, 6});
      ang.angular[i] = bad;
      EXPECT_FALSE(ang.is_valid()) << "angular[" << i << "] = " << bad;
    }
  }
}

TEST(AccelStamped, MakeTakesTheAccelerationAndItsTimestamp) {
  Accel a = Accel::make({0, 0, 9.81}, {});
  a.timestamp_ns = 42;
  const AccelStamped s = AccelStamped::make(a);
  EXPECT_EQ(s.accel, a);
  EXPECT_EQ(s.timestamp_ns, 42u);
  EXPECT_EQ(s.frame_id_str(), "");
}

TEST(AccelStamped, FrameNamesThatDoNotFitAreRejected) {
  AccelStamped s{};
  EXPECT_TRUE(s.set_frame_id("imu_link"));
  EXPECT_EQ(s.frame_id_str(), "imu_link");
  EXPECT_FALSE(s.set_frame_id(std::string(32, 'f')));
  EXPECT_FALSE(s.set_frame_id(std::string_view("a\0b", 3)));
  EXPECT_EQ(s.frame_id_str(), "imu_link");
  EXPECT_TRUE(s.set_frame_id(std::string(31, 'f')));
  EXPECT_EQ(s.frame_id_str().size(), 31u);
}

TEST(AccelStamped, WithFrameIdReturnsACopyAndThrowsWhenTheNameDoesNotFit) {
  const AccelStamped s = AccelStamped::make(Accel::make({1, 0, 0}, {}));
  const AccelStamped framed = s.with_frame_id("base_link");
  EXPECT_EQ(framed.frame_id_str(), "base_link");
  EXPECT_EQ(framed.accel, s.accel);
  EXPECT_EQ(s.frame_id_str(), "");
  EXPECT_THROW((void)s.with_frame_id(std::string(32, 'x')), std::invalid_argument);
}

// ===========================================================================
// PoseWithCovariance, TwistWithCovariance

TEST(PoseWithCovariance, MakeHasZeroCovarianceAndThePoseTimestamp) {
  Pose3D p = Pose3D::make(Point3::make(1, 2, 3), Quaternion::identity());
  p.timestamp_ns = 99;
  const PoseWithCovariance m = PoseWithCovariance::make(p);
  EXPECT_EQ(m.pose, p);
  EXPECT_EQ(m.covariance, (std::array<double, 36>{}));
  EXPECT_EQ(m.timestamp_ns, 99u);
  EXPECT_EQ(m.frame_id_str(), "");
}

TEST(PoseWithCovariance, VariancesAreTheDiagonalOfTheRowMajorMatrix) {
  PoseWithCovariance m{};
  for (std::size_t i = 0; i < 36; ++i) m.covariance[i] = static_cast<double>(i) + 0.5;
  EXPECT_EQ(m.position_variance(), (std::array<double, 3>{0.5, 7.5, 14.5}));
  EXPECT_EQ(m.orientation_variance(), (std::array<double, 3>{21.5, 28.5, 35.5}));
}

TEST(PoseWithCovariance, WithFrameIdAndSetFrameIdRefuseNamesThatDoNotFit) {
  PoseWithCovariance m = PoseWithCovariance::make(Pose3D::identity()).with_frame_id("map");
  EXPECT_EQ(m.frame_id_str(), "map");
  EXPECT_FALSE(m.set_frame_id(std::string(40, 'm')));
  EXPECT_EQ(m.frame_id_str(), "map");
  EXPECT_THROW((void)m.with_frame_id(std::string(32, 'm')), std::invalid_argument);
}

TEST(PoseWithCovariance, LogSummaryNamesTheFrameWithUnits) {
  PoseWithCovariance m = PoseWithCovariance::make(Pose3D::make(Point3::make(1, 2, 0), Quaternion::identity()));
  m.set_frame_id("map");
  m.covariance[0] = 0.01;
  m.covariance[35] = 0.05;
  const std::string s = m.log_summary();
  EXPECT_TRUE(contains(s, "map")) << s;
  EXPECT_TRUE(contains(s, "(1.00, 2.00, 0.00) m")) << s;
  EXPECT_TRUE(contains(s, "m^2")) << s;
  EXPECT_TRUE(contains(s, "0.05")) << s;
  EXPECT_TRUE(contains(PoseWithCovariance{}.log_summary(), "no frame"));
  EXPECT_EQ(horus::log_summary(m), s);
}

TEST(TwistWithCovariance, MakeHasZeroCovarianceAndTheTwistTimestamp) {
  Twist t = Twist::new_2d(0.5, 0.2);
  t.timestamp_ns = 7;
  const TwistWithCovariance m = TwistWithCovariance::make(t);
  EXPECT_EQ(m.twist, t);
  EXPECT_EQ(m.covariance, (std::array<double, 36>{}));
  EXPECT_EQ(m.timestamp_ns, 7u);
}

TEST(TwistWithCovariance, VariancesAreTheDiagonalOfTheRowMajorMatrix) {
  TwistWithCovariance m{};
  for (std::size_t i = 0; i < 36; ++i) m.covariance[i] = -static_cast<double>(i);
  EXPECT_EQ(m.linear_variance(), (std::array<double, 3>{0.0, -7.0, -14.0}));
  EXPECT_EQ(m.angular_variance(), (std::array<double, 3>{-21.0, -28.0, -35.0}));
}

TEST(TwistWithCovariance, FrameIdAndLogSummary) {
  const TwistWithCovariance m = TwistWithCovariance::make(Twist::new_2d(0.5, 0.2)).with_frame_id("base_link");
  EXPECT_EQ(m.frame_id_str(), "base_link");
  EXPECT_THROW((void)m.with_frame_id(std::string(32, 'b')), std::invalid_argument);
  const std::string s = m.log_summary();
  EXPECT_TRUE(contains(s, "base_link")) << s;
  EXPECT_TRUE(contains(s, "(0.50, 0.00, 0.00) m/s")) << s;
  EXPECT_TRUE(contains(s, "(0.00, 0.00, 0.20) rad/s")) << s;
}

// ===========================================================================
// Range

TEST(Range, SensorTypeConstantsMatchTheSpec) {
  EXPECT_EQ(Range::ULTRASONIC, 0);
  EXPECT_EQ(Range::INFRARED, 1);
}

TEST(Range, MakeUsesTheHorusDefaults) {
  const Range r = Range::make(Range::INFRARED, 0.8f);
  EXPECT_EQ(r.sensor_type, Range::INFRARED);
  EXPECT_EQ(r.range, 0.8f);
  EXPECT_EQ(r.field_of_view, 0.1f);
  EXPECT_EQ(r.min_range, 0.02f);
  EXPECT_EQ(r.max_range, 4.0f);
  EXPECT_EQ(r.timestamp_ns, 0u);
  EXPECT_TRUE(r.is_valid());
}

TEST(Range, IsValidIncludesBothLimitsAndRejectsValuesJustOutside) {
  Range r = Range::make(Range::ULTRASONIC, 0.02f);
  EXPECT_TRUE(r.is_valid());
  r.range = 4.0f;
  EXPECT_TRUE(r.is_valid());
  r.range = std::nextafter(0.02f, 0.0f);
  EXPECT_FALSE(r.is_valid());
  r.range = std::nextafter(4.0f, 5.0f);
  EXPECT_FALSE(r.is_valid());
  r.range = 0.0f;
  EXPECT_FALSE(r.is_valid());
  r.range = -1.0f;
  EXPECT_FALSE(r.is_valid());
}

TEST(Range, IsValidRejectsNaNAndInfinityInTheReadingOrTheLimits) {
  Range r = Range::make(Range::ULTRASONIC, kNaNf);
  EXPECT_FALSE(r.is_valid());
  r.range = kInff;
  r.max_range = kInff;
  EXPECT_FALSE(r.is_valid());
  r = Range::make(Range::ULTRASONIC, 1.0f);
  r.min_range = kNaNf;
  EXPECT_FALSE(r.is_valid());
  r = Range::make(Range::ULTRASONIC, 1.0f);
  r.max_range = kNaNf;
  EXPECT_FALSE(r.is_valid());
}

// ===========================================================================
// BatteryState

TEST(BatteryState, StatusConstantsMatchTheSpec) {
  EXPECT_EQ(BatteryState::STATUS_UNKNOWN, 0);
  EXPECT_EQ(BatteryState::STATUS_CHARGING, 1);
  EXPECT_EQ(BatteryState::STATUS_DISCHARGING, 2);
  EXPECT_EQ(BatteryState::STATUS_FULL, 3);
}

TEST(BatteryState, MakeSetsVoltageAndPercentageAndMarksChargeUnknown) {
  const BatteryState b = BatteryState::make(12.6f, 75.0f);
  EXPECT_EQ(b.voltage, 12.6f);
  EXPECT_EQ(b.percentage, 75.0f);
  EXPECT_EQ(b.current, 0.0f);
  EXPECT_TRUE(std::isnan(b.charge));
  EXPECT_TRUE(std::isnan(b.capacity));
  EXPECT_EQ(b.power_supply_status, BatteryState::STATUS_UNKNOWN);
  EXPECT_EQ(b.temperature, 25.0f);
  EXPECT_EQ(b.cell_count, 0u);
  EXPECT_EQ(b.cell_voltages, (std::array<float, 16>{}));
  EXPECT_EQ(b.timestamp_ns, 0u);
}

TEST(BatteryState, IsLowIsStrictlyBelowTheThreshold) {
  BatteryState b = BatteryState::make(12.0f, 20.0f);
  EXPECT_FALSE(b.is_low(20.0f));  // exactly at the threshold is not low
  b.percentage = std::nextafter(20.0f, 0.0f);
  EXPECT_TRUE(b.is_low(20.0f));
  b.percentage = 20.5f;
  EXPECT_FALSE(b.is_low(20.0f));
  b.percentage = 0.0f;
  EXPECT_TRUE(b.is_low(20.0f));
  EXPECT_FALSE(b.is_low(0.0f));
}

TEST(BatteryState, IsCriticalBelowTenPercent) {
  BatteryState b = BatteryState::make(11.0f, 10.0f);
  EXPECT_FALSE(b.is_critical());  // exactly 10 % is not critical
  EXPECT_TRUE(b.is_low(20.0f));
  b.percentage = std::nextafter(10.0f, 0.0f);
  EXPECT_TRUE(b.is_critical());
  b.percentage = 9.0f;
  EXPECT_TRUE(b.is_critical());
  b.percentage = 0.0f;
  EXPECT_TRUE(b.is_critical());
  b.percentage = 10.5f;
  EXPECT_FALSE(b.is_critical());
}

TEST(BatteryState, NaNPercentageIsNeitherLowNorCritical) {
  BatteryState b = BatteryState::make(12.0f, kNaNf);
  EXPECT_FALSE(b.is_low(20.0f));
  EXPECT_FALSE(b.is_critical());
  b.percentage = 5.0f;
  EXPECT_FALSE(b.is_low(kNaNf));
}

TEST(BatteryState, TimeRemainingIsChargeOverDischargeCurrentInSeconds) {
  BatteryState b = BatteryState::make(12.6f, 50.0f);
  b.charge = 5.0f;
  b.current = -2.5f;
  b.power_supply_status = BatteryState::STATUS_DISCHARGING;
  const auto t = b.time_remaining();
  ASSERT_TRUE(t.has_value());
  EXPECT_DOUBLE_EQ(*t, 7200.0);  // 5 Ah at 2.5 A: two hours
  b.current = -0.5f;
  EXPECT_DOUBLE_EQ(b.time_remaining().value(), 36000.0);
  b.charge = 0.0f;
  EXPECT_EQ(b.time_remaining(), std::optional<double>(0.0));
}

TEST(BatteryState, TimeRemainingIsNulloptWhenChargingOrCurrentIsZero) {
  BatteryState b = BatteryState::make(12.6f, 50.0f);
  b.charge = 5.0f;
  b.current = 1.5f;
  b.power_supply_status = BatteryState::STATUS_CHARGING;
  EXPECT_EQ(b.time_remaining(), std::nullopt);
  b.current = 0.0f;
  b.power_supply_status = BatteryState::STATUS_FULL;
  EXPECT_EQ(b.time_remaining(), std::nullopt);
  b.current = -0.0f;
  EXPECT_EQ(b.time_remaining(), std::nullopt);
}

TEST(BatteryState, TimeRemainingFollowsTheSignOfCurrentNotTheStatus) {
  BatteryState b = BatteryState::make(12.6f, 50.0f);
  b.charge = 1.0f;
  b.current = -1.0f;
  b.power_supply_status = BatteryState::STATUS_CHARGING;  // contradicts the current: the measurement wins
  EXPECT_EQ(b.time_remaining(), std::optional<double>(3600.0));
}

TEST(BatteryState, TimeRemainingIsNulloptForUnknownOrNonFiniteInputs) {
  BatteryState b = BatteryState::make(12.6f, 50.0f);
  b.current = -2.0f;
  EXPECT_EQ(b.time_remaining(), std::nullopt);  // charge NaN from make(): unknown
  b.charge = kInff;
  EXPECT_EQ(b.time_remaining(), std::nullopt);
  b.charge = -1.0f;
  EXPECT_EQ(b.time_remaining(), std::nullopt);
  b.charge = 2.0f;
  b.current = kNaNf;
  EXPECT_EQ(b.time_remaining(), std::nullopt);
  b.current = -kInff;
  EXPECT_EQ(b.time_remaining(), std::nullopt);
  b.current = -2.0f;
  EXPECT_EQ(b.time_remaining(), std::optional<double>(3600.0));
}

TEST(BatteryState, LogSummaryHasUnitsAndStatus) {
  BatteryState b = BatteryState::make(12.6f, 75.0f);
  b.current = -2.5f;
  b.temperature = 28.5f;
  b.power_supply_status = BatteryState::STATUS_DISCHARGING;
  b.cell_count = 3;
  EXPECT_EQ(b.log_summary(), "BatteryState(12.60 V, 75.0 %, -2.50 A, discharging, 28.5 degC, 3 cells)");
  b.power_supply_status = 9;
  EXPECT_TRUE(contains(b.log_summary(), "status 9")) << b.log_summary();
}

// ===========================================================================
// NavSatFix

TEST(NavSatFix, StatusConstantsMatchHorus) {
  EXPECT_EQ(NavSatFix::STATUS_NO_FIX, 0);
  EXPECT_EQ(NavSatFix::STATUS_FIX, 1);
  EXPECT_EQ(NavSatFix::STATUS_SBAS_FIX, 2);
  EXPECT_EQ(NavSatFix::STATUS_GBAS_FIX, 3);
}

TEST(NavSatFix, MakeHasNoFixAndUnknownPrecision) {
  const NavSatFix f = NavSatFix::make();
  EXPECT_EQ(f.status, NavSatFix::STATUS_NO_FIX);
  EXPECT_FALSE(f.has_fix());
  EXPECT_EQ(f.hdop, 99.9f);
  EXPECT_EQ(f.vdop, 99.9f);
  EXPECT_EQ(f.latitude, 0.0);
  EXPECT_EQ(f.timestamp_ns, 0u);
}

TEST(NavSatFix, FromCoordinatesIsAFixAtThatPosition) {
  const NavSatFix f = NavSatFix::from_coordinates(47.397742, 8.545594, 488.0);
  EXPECT_EQ(f.latitude, 47.397742);
  EXPECT_EQ(f.longitude, 8.545594);
  EXPECT_EQ(f.altitude, 488.0);
  EXPECT_EQ(f.status, NavSatFix::STATUS_FIX);
  EXPECT_TRUE(f.has_fix());
  EXPECT_TRUE(f.is_valid());
}

TEST(NavSatFix, HasFixForFixAndAugmentedFixes) {
  NavSatFix f{};
  for (std::uint8_t s : {NavSatFix::STATUS_FIX, NavSatFix::STATUS_SBAS_FIX, NavSatFix::STATUS_GBAS_FIX}) {
    f.status = s;
    EXPECT_TRUE(f.has_fix()) << int(s);
  }
  f.status = NavSatFix::STATUS_NO_FIX;
  EXPECT_FALSE(f.has_fix());
}

TEST(NavSatFix, IsValidChecksCoordinateRangesWithLimitsIncluded) {
  EXPECT_TRUE(NavSatFix::from_coordinates(90.0, 180.0, 0.0).is_valid());
  EXPECT_TRUE(NavSatFix::from_coordinates(-90.0, -180.0, -100.0).is_valid());
  EXPECT_FALSE(NavSatFix::from_coordinates(std::nextafter(90.0, 91.0), 0.0, 0.0).is_valid());
  EXPECT_FALSE(NavSatFix::from_coordinates(-90.5, 0.0, 0.0).is_valid());
  EXPECT_FALSE(NavSatFix::from_coordinates(0.0, 180.5, 0.0).is_valid());
  EXPECT_FALSE(NavSatFix::from_coordinates(0.0, -181.0, 0.0).is_valid());
}

TEST(NavSatFix, IsValidRejectsNaNAndInfinity) {
  EXPECT_FALSE(NavSatFix::from_coordinates(kNaN, 0.0, 0.0).is_valid());
  EXPECT_FALSE(NavSatFix::from_coordinates(0.0, kNaN, 0.0).is_valid());
  EXPECT_FALSE(NavSatFix::from_coordinates(0.0, 0.0, kNaN).is_valid());
  EXPECT_FALSE(NavSatFix::from_coordinates(0.0, 0.0, kInf).is_valid());
}

TEST(NavSatFix, DistanceToIsTheHaversineGreatCircleDistance) {
  const NavSatFix a = NavSatFix::from_coordinates(0.0, 0.0, 0.0);
  // One degree along a meridian is R * pi / 180.
  EXPECT_NEAR(a.distance_to(NavSatFix::from_coordinates(1.0, 0.0, 0.0)), NavSatFix::kEarthRadiusM * kPi / 180.0, 1e-6);
  // One degree of longitude at 60 degrees north: the haversine of the small circle chord.
  const NavSatFix n1 = NavSatFix::from_coordinates(60.0, 0.0, 0.0);
  const NavSatFix n2 = NavSatFix::from_coordinates(60.0, 1.0, 0.0);
  EXPECT_NEAR(n1.distance_to(n2), 55'596.93, 0.01);
  // Paris to London, about 343.5 km on the 6371 km sphere.
  const NavSatFix paris = NavSatFix::from_coordinates(48.8566, 2.3522, 35.0);
  const NavSatFix london = NavSatFix::from_coordinates(51.5074, -0.1278, 11.0);
  EXPECT_NEAR(paris.distance_to(london), 343'556.06, 0.01);
  EXPECT_DOUBLE_EQ(paris.distance_to(london), london.distance_to(paris));
}

TEST(NavSatFix, DistanceIsZeroToItselfHalfTheCircumferenceToTheAntipodeAndIgnoresAltitude) {
  const NavSatFix p = NavSatFix::from_coordinates(47.4, 8.5, 400.0);
  EXPECT_EQ(p.distance_to(p), 0.0);
  NavSatFix higher = p;
  higher.altitude = 9000.0;
  EXPECT_EQ(p.distance_to(higher), 0.0);
  const NavSatFix antipode = NavSatFix::from_coordinates(-47.4, 8.5 - 180.0, 0.0);
  EXPECT_NEAR(p.distance_to(antipode), kPi * NavSatFix::kEarthRadiusM, 1e-3);
  EXPECT_NEAR(NavSatFix::from_coordinates(90, 0, 0).distance_to(NavSatFix::from_coordinates(-90, 0, 0)),
              kPi * NavSatFix::kEarthRadiusM, 1e-3);
}

TEST(NavSatFix, DistanceWithNaNCoordinatesIsNaN) {
  const NavSatFix p = NavSatFix::from_coordinates(47.4, 8.5, 0.0);
  EXPECT_TRUE(std::isnan(p.distance_to(NavSatFix::from_coordinates(kNaN, 8.5, 0.0))));
  EXPECT_TRUE(std::isnan(NavSatFix::from_coordinates(47.4, kNaN, 0.0).distance_to(p)));
}

TEST(NavSatFix, HorizontalAccuracyIsFiveMetresPerHdop) {
  NavSatFix f = NavSatFix::make();
  f.hdop = 1.2f;
  EXPECT_FLOAT_EQ(f.horizontal_accuracy(), 6.0f);
  EXPECT_FLOAT_EQ(NavSatFix::make().horizontal_accuracy(), 499.5f);
}

TEST(NavSatFix, LogSummaryHasCoordinatesUnitsSatellitesAndFix) {
  NavSatFix f = NavSatFix::from_coordinates(47.397742, 8.545594, 488.0);
  f.satellites_visible = 9;
  f.hdop = 0.9f;
  EXPECT_EQ(f.log_summary(), "NavSatFix(lat 47.397742 deg, lon 8.545594 deg, alt 488.0 m, 9 sats, fix, hdop 0.9)");
  EXPECT_EQ(horus::log_summary(f), f.log_summary());
  f.status = NavSatFix::STATUS_NO_FIX;
  EXPECT_TRUE(contains(f.log_summary(), "no fix")) << f.log_summary();
  f.status = NavSatFix::STATUS_SBAS_FIX;
  EXPECT_TRUE(contains(f.log_summary(), "SBAS fix")) << f.log_summary();
  f.status = 7;
  EXPECT_TRUE(contains(f.log_summary(), "status 7")) << f.log_summary();
}

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

template <class T>
T sample();

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

template <class T>
class EveryMotionMessage : public ::testing::Test {};
using MotionMessages = ::testing::Types<Accel, AccelStamped, PoseWithCovariance, TwistWithCovariance, Range,
                                        BatteryState, NavSatFix, MotorCommand, DifferentialDriveCommand, ServoCommand,
                                        PidConfig, TrajectoryPoint, Clock, TimeReference, JoystickInput, KeyboardInput>;
TYPED_TEST_SUITE(EveryMotionMessage, MotionMessages);

TYPED_TEST(EveryMotionMessage, IsTriviallyCopyableStandardLayoutAggregate) {
  static_assert(std::is_trivially_copyable_v<TypeParam>);
  static_assert(std::is_standard_layout_v<TypeParam>);
  static_assert(horus::reflect::is_fixed_size<TypeParam>);
  static_assert(std::is_aggregate_v<TypeParam>);
  const TypeParam original = sample<TypeParam>();
  TypeParam copy{};
  std::memcpy(&copy, &original, sizeof(TypeParam));
  EXPECT_EQ(copy, original);
}

TYPED_TEST(EveryMotionMessage, DefaultValueIsAllZeros) {
  const auto zero = std::bit_cast<TypeParam>(std::array<unsigned char, sizeof(TypeParam)>{});
  EXPECT_EQ(TypeParam{}, zero);
}

TYPED_TEST(EveryMotionMessage, SampleSetsEveryFieldToANonDefaultValue) {
  const TypeParam s = sample<TypeParam>();
  const TypeParam d{};
  horus::reflect::for_each_field_desc<TypeParam>(
      [&](const auto& fd) { EXPECT_FALSE(fd.get(s) == fd.get(d)) << "field " << fd.name << " keeps its default"; });
}

TYPED_TEST(EveryMotionMessage, JsonRoundTripGivesAnEqualMessage) {
  const TypeParam original = sample<TypeParam>();
  const nlohmann::json j = horus::to_json(original);
  EXPECT_EQ(horus::from_json<TypeParam>(j), original) << j.dump();
  // And through text, as a file or a socket would carry it.
  EXPECT_EQ(horus::from_json<TypeParam>(nlohmann::json::parse(j.dump())), original) << j.dump();
}

TYPED_TEST(EveryMotionMessage, JsonHasOneKeyPerField) {
  const nlohmann::json j = horus::to_json(sample<TypeParam>());
  ASSERT_TRUE(j.is_object());
  EXPECT_EQ(j.size(), horus::reflect::field_count<TypeParam>);
  horus::reflect::for_each_field_desc<TypeParam>(
      [&](const auto& fd) { EXPECT_TRUE(j.contains(std::string(fd.name))) << fd.name << " in " << j.dump(); });
}

TYPED_TEST(EveryMotionMessage, FormatsWithItsTypeNameAndItsFields) {
  const TypeParam s = sample<TypeParam>();
  const std::string text = fmt::format("{}", s);
  const std::string_view qualified = horus::type_name<TypeParam>();
  EXPECT_EQ(qualified.rfind("horus::msg::", 0), 0u) << qualified;
  const std::string short_name(qualified.substr(qualified.rfind("::") + 2));
  EXPECT_EQ(text.rfind(short_name + " { ", 0), 0u) << text;
  horus::reflect::for_each_field_desc<TypeParam>(
      [&](const auto& fd) { EXPECT_TRUE(contains(text, std::string(fd.name) + ": ")) << fd.name << " in " << text; });
  EXPECT_EQ(text, horus::to_string(s));
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
