// Unit tests of the motion and sensor messages: Accel, AccelStamped, PoseWithCovariance,
// TwistWithCovariance (geometry.hpp), Range, BatteryState, NavSatFix (sensor.hpp).
#include "msg_motion_test.hpp"

namespace {

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

}  // namespace
