// Unit tests of the standard messages: helpers, layout guarantees, printing,
// JSON round trips and Eigen interop.
#include <gtest/gtest.h>

#include <array>
#include <bit>
#include <cmath>
#include <cstring>
#include <limits>
#include <numbers>
#include <ostream>
#include <stdexcept>
#include <string>
#include <type_traits>

#include <fmt/format.h>

#include "horus/format.hpp"
#include "horus/json.hpp"
#include "horus/messages.hpp"
#include "horus/msg/eigen.hpp"
#include "message_test_support.hpp"

namespace {

using namespace horus_test::values;

using namespace horus::msg;

// Two quaternions describe the same rotation when q1 = +-q2.
::testing::AssertionResult SameRotation(const Quaternion& a, const Quaternion& b, double tol = 1e-12) {
  const double dot = a.x * b.x + a.y * b.y + a.z * b.z + a.w * b.w;
  if (std::abs(std::abs(dot) - 1.0) <= tol) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << horus::to_string(a) << " and " << horus::to_string(b)
                                       << " differ (|dot| = " << std::abs(dot) << ")";
}

// ===========================================================================
// Angles and Pose2D

TEST(NormalizeAngle, WrapsIntoMinusPiToPi) {
  EXPECT_DOUBLE_EQ(normalize_angle(0.0), 0.0);
  EXPECT_DOUBLE_EQ(normalize_angle(1.0), 1.0);
  EXPECT_NEAR(normalize_angle(3.5), 3.5 - 2 * kPi, 1e-15);
  EXPECT_NEAR(normalize_angle(-3.5), -3.5 + 2 * kPi, 1e-15);
  EXPECT_NEAR(normalize_angle(2 * kPi), 0.0, 1e-15);
  EXPECT_NEAR(normalize_angle(-2 * kPi + 0.25), 0.25, 1e-15);
}

TEST(NormalizeAngle, KeepsPiAndMinusPiAtTheBoundary) {
  EXPECT_EQ(normalize_angle(kPi), kPi);
  EXPECT_EQ(normalize_angle(-kPi), -kPi);
}

TEST(NormalizeAngle, StaysExactForLargeMultiplesOfTwoPi) {
  EXPECT_NEAR(normalize_angle(0.3 + 1000 * 2 * kPi), 0.3, 1e-9);
  EXPECT_NEAR(normalize_angle(-0.3 - 1000 * 2 * kPi), -0.3, 1e-9);
  for (double a : {1e6, -1e6, 1e10, -1e10, 123456789.123, 1e300, -1e300}) {
    const double n = normalize_angle(a);
    EXPECT_GE(n, -kPi) << a;
    EXPECT_LE(n, kPi) << a;
  }
  // Same direction as the input (checked where cos/sin of the input are still meaningful).
  for (double a : {1e6 + 0.5, -1e6 - 0.5, 12345.678}) {
    EXPECT_NEAR(std::cos(normalize_angle(a)), std::cos(a), 1e-9) << a;
    EXPECT_NEAR(std::sin(normalize_angle(a)), std::sin(a), 1e-9) << a;
  }
}

TEST(NormalizeAngle, GivesNaNForNonFiniteAngles) {
  EXPECT_TRUE(std::isnan(normalize_angle(kInf)));
  EXPECT_TRUE(std::isnan(normalize_angle(-kInf)));
  EXPECT_TRUE(std::isnan(normalize_angle(kNaN)));
}

TEST(Pose2D, NormalizeAngleWrapsThetaAndLeavesPositionAlone) {
  Pose2D p = Pose2D::make(1.0, 2.0, 3.5);
  p.timestamp_ns = 42;
  p.normalize_angle();
  EXPECT_NEAR(p.theta, 3.5 - 2 * kPi, 1e-15);
  EXPECT_EQ(p.x, 1.0);
  EXPECT_EQ(p.y, 2.0);
  EXPECT_EQ(p.timestamp_ns, 42u);

  Pose2D q = Pose2D::make(0, 0, -7 * kPi - 0.1);
  q.normalize_angle();
  EXPECT_NEAR(q.theta, kPi - 0.1, 1e-12);
}

TEST(Pose2D, MakeSetsFieldsAndOriginIsZero) {
  const Pose2D p = Pose2D::make(1.0, 2.0, 0.5);
  EXPECT_EQ(p, (Pose2D{1.0, 2.0, 0.5, 0}));
  EXPECT_EQ(Pose2D::origin(), Pose2D{});
}

TEST(Pose2D, DistanceIsEuclideanAndIgnoresHeading) {
  EXPECT_DOUBLE_EQ(Pose2D::make(3, 4, 1.0).distance_to(Pose2D::origin()), 5.0);
  EXPECT_DOUBLE_EQ(Pose2D::make(-1, -1, 0).distance_to(Pose2D::make(2, 3, 2.0)), 5.0);
  EXPECT_EQ(Pose2D::make(1, 1, 0).distance_to(Pose2D::make(1, 1, 3)), 0.0);
}

TEST(Pose2D, IsValidRejectsNaNAndInfinity) {
  EXPECT_TRUE(Pose2D::make(1, 2, 3).is_valid());
  EXPECT_FALSE(Pose2D::make(kNaN, 0, 0).is_valid());
  EXPECT_FALSE(Pose2D::make(0, kInf, 0).is_valid());
  EXPECT_FALSE(Pose2D::make(0, 0, -kInf).is_valid());
}

// ===========================================================================
// CmdVel, Twist

TEST(CmdVel, FactoriesSetVelocitiesAndTimestamp) {
  EXPECT_EQ(CmdVel::make(1.0f, 0.5f), (CmdVel{0, 1.0f, 0.5f}));
  EXPECT_EQ(CmdVel::zero(), CmdVel{});
  const CmdVel c = CmdVel::with_timestamp(1.0f, -0.5f, 123456789);
  EXPECT_EQ(c.stamp_nanos, 123456789u);
  EXPECT_EQ(c.linear, 1.0f);
  EXPECT_EQ(c.angular, -0.5f);
}

TEST(Twist, New2dSetsForwardSpeedAndYawRateOnly) {
  const Twist t = Twist::new_2d(1.0, 0.5);
  EXPECT_EQ(t.linear, (std::array<double, 3>{1.0, 0.0, 0.0}));
  EXPECT_EQ(t.angular, (std::array<double, 3>{0.0, 0.0, 0.5}));
  EXPECT_EQ(t.timestamp_ns, 0u);
}

TEST(Twist, MakeAndStop) {
  const Twist t = Twist::make({1.0, 0.5, 0.0}, {0.0, 0.0, 0.5});
  EXPECT_EQ(t.linear[1], 0.5);
  EXPECT_EQ(t.angular[2], 0.5);
  EXPECT_EQ(Twist::stop(), Twist{});
}

TEST(Twist, IsValidRequiresAllComponentsFinite) {
  EXPECT_TRUE(Twist::new_2d(1, 2).is_valid());
  EXPECT_TRUE(Twist::stop().is_valid());
  for (std::size_t i = 0; i < 3; ++i) {
    Twist a = Twist::stop();
    a.linear[i] = kNaN;
    EXPECT_FALSE(a.is_valid());
    Twist b = Twist::stop();
    b.angular[i] = kInf;
    EXPECT_FALSE(b.is_valid());
  }
}

// ===========================================================================
// Point3, Vector3

TEST(Point3, DistanceToOrigin) {
  EXPECT_DOUBLE_EQ(Point3::make(3, 4, 12).distance_to(Point3::origin()), 13.0);
  EXPECT_EQ(Point3::origin(), Point3{});
  EXPECT_EQ(Point3::make(1, 2, 3).distance_to(Point3::make(1, 2, 3)), 0.0);
}

TEST(Vector3, MagnitudeDotAndCross) {
  const Vector3 x = Vector3::make(1, 0, 0), y = Vector3::make(0, 1, 0), z = Vector3::make(0, 0, 1);
  EXPECT_DOUBLE_EQ(Vector3::make(2, 3, 6).magnitude(), 7.0);
  EXPECT_EQ(x.dot(y), 0.0);
  EXPECT_EQ(Vector3::make(1, 2, 3).dot(Vector3::make(4, -5, 6)), 12.0);
  EXPECT_EQ(x.cross(y), z);
  EXPECT_EQ(y.cross(z), x);
  EXPECT_EQ(z.cross(x), y);
  EXPECT_EQ(y.cross(x), Vector3::make(0, 0, -1));
  EXPECT_EQ(x.cross(x), Vector3::zero());
  // The cross product is orthogonal to both inputs.
  const Vector3 a = Vector3::make(1, 2, 3), b = Vector3::make(-2, 0.5, 4);
  EXPECT_NEAR(a.cross(b).dot(a), 0.0, 1e-12);
  EXPECT_NEAR(a.cross(b).dot(b), 0.0, 1e-12);
}

TEST(Vector3, NormalizeGivesUnitLengthAndKeepsZeroVectorZero) {
  Vector3 v = Vector3::make(3, 4, 0);
  v.normalize();
  EXPECT_DOUBLE_EQ(v.x, 0.6);
  EXPECT_DOUBLE_EQ(v.y, 0.8);
  EXPECT_EQ(v.z, 0.0);
  EXPECT_DOUBLE_EQ(v.magnitude(), 1.0);

  Vector3 zero = Vector3::zero();
  zero.normalize();
  EXPECT_EQ(zero, Vector3::zero());
  EXPECT_EQ(Vector3::zero().normalized(), Vector3::zero());
}

// ===========================================================================
// Quaternion

TEST(Quaternion, IdentityIsUnitAndDefaultIsZero) {
  EXPECT_EQ(Quaternion::identity(), (Quaternion{0, 0, 0, 1}));
  EXPECT_TRUE(Quaternion::identity().is_valid());
  EXPECT_EQ(Quaternion{}.norm(), 0.0);
  EXPECT_FALSE(Quaternion{}.is_valid());
}

TEST(Quaternion, FromEulerYawQuarterTurnRotatesAboutZ) {
  const Quaternion q = Quaternion::from_euler(0.0, 0.0, kPi / 2);
  EXPECT_NEAR(q.x, 0.0, 1e-15);
  EXPECT_NEAR(q.y, 0.0, 1e-15);
  EXPECT_NEAR(q.z, std::sqrt(0.5), 1e-15);
  EXPECT_NEAR(q.w, std::sqrt(0.5), 1e-15);
  EXPECT_TRUE(q.is_valid());
}

TEST(Quaternion, FromEulerRollAndPitchUseXAndYAxes) {
  const Quaternion r = Quaternion::from_euler(kPi / 2, 0.0, 0.0);
  EXPECT_NEAR(r.x, std::sqrt(0.5), 1e-15);
  EXPECT_NEAR(r.w, std::sqrt(0.5), 1e-15);
  const Quaternion p = Quaternion::from_euler(0.0, kPi / 2, 0.0);
  EXPECT_NEAR(p.y, std::sqrt(0.5), 1e-15);
  EXPECT_NEAR(p.w, std::sqrt(0.5), 1e-15);
}

TEST(Quaternion, EulerRoundTripReturnsTheSameAngles) {
  const std::array<EulerAngles, 8> cases{{
      {0.0, 0.0, 0.0},
      {0.1, 0.2, 1.5},
      {-0.5, 0.3, -2.0},
      {3.0, -1.2, 3.1},
      {-3.0, 1.4, -3.1},
      {1.0, -0.1, 0.0},
      {0.0, 1.5, 0.0},
      {2.5, 0.0, -0.7},
  }};
  for (const auto& e : cases) {
    const EulerAngles back = Quaternion::from_euler(e.roll, e.pitch, e.yaw).to_euler();
    EXPECT_NEAR(back.roll, e.roll, 1e-12) << e.roll << " " << e.pitch << " " << e.yaw;
    EXPECT_NEAR(back.pitch, e.pitch, 1e-12) << e.roll << " " << e.pitch << " " << e.yaw;
    EXPECT_NEAR(back.yaw, e.yaw, 1e-12) << e.roll << " " << e.pitch << " " << e.yaw;
  }
}

TEST(Quaternion, ToEulerAtGimbalLockGivesAnEquivalentRotation) {
  for (double pitch : {kPi / 2, -kPi / 2}) {
    const Quaternion q = Quaternion::from_euler(0.3, pitch, 0.2);
    const auto [roll, p, yaw] = q.to_euler();
    EXPECT_NEAR(p, pitch, 1e-9);
    EXPECT_EQ(roll, 0.0);
    EXPECT_TRUE(SameRotation(Quaternion::from_euler(roll, p, yaw), q, 1e-12));
  }
}

TEST(Quaternion, ToEulerOfNonUnitQuaternionUsesItsDirection) {
  Quaternion q = Quaternion::from_euler(0.1, 0.2, 0.3);
  q = Quaternion{q.x * 3, q.y * 3, q.z * 3, q.w * 3};
  const auto e = q.to_euler();
  EXPECT_NEAR(e.roll, 0.1, 1e-12);
  EXPECT_NEAR(e.pitch, 0.2, 1e-12);
  EXPECT_NEAR(e.yaw, 0.3, 1e-12);
}

TEST(Quaternion, NormalizeMakesUnitAndTurnsZeroIntoIdentity) {
  Quaternion q{0, 0, 0, 2};
  q.normalize();
  EXPECT_EQ(q, Quaternion::identity());

  Quaternion r{1, 1, 1, 1};
  r.normalize();
  EXPECT_EQ(r, (Quaternion{0.5, 0.5, 0.5, 0.5}));
  EXPECT_DOUBLE_EQ(r.norm(), 1.0);

  Quaternion zero{};
  zero.normalize();
  EXPECT_EQ(zero, Quaternion::identity());
  EXPECT_EQ(Quaternion{}.normalized(), Quaternion::identity());
}

TEST(Quaternion, IsValidRequiresFiniteUnitLength) {
  EXPECT_TRUE(Quaternion::from_euler(1, 2, 3).is_valid());
  EXPECT_FALSE((Quaternion{0, 0, 0, 2}).is_valid());
  EXPECT_FALSE((Quaternion{kNaN, 0, 0, 1}).is_valid());
  EXPECT_FALSE((Quaternion{0, 0, kInf, 1}).is_valid());
  EXPECT_DOUBLE_EQ((Quaternion{1, 2, 2, 4}).norm(), 5.0);
}

// ===========================================================================
// Pose3D, TransformStamped

TEST(Pose3D, IdentityFromPose2DAndDistance) {
  EXPECT_EQ(Pose3D::identity(), (Pose3D{Point3{}, Quaternion::identity(), 0}));
  Pose2D p2 = Pose2D::make(1, 2, kPi / 2);
  p2.timestamp_ns = 99;
  const Pose3D p = Pose3D::from_pose_2d(p2);
  EXPECT_EQ(p.position, Point3::make(1, 2, 0));
  EXPECT_TRUE(SameRotation(p.orientation, Quaternion::from_euler(0, 0, kPi / 2)));
  EXPECT_EQ(p.timestamp_ns, 99u);
  EXPECT_DOUBLE_EQ(p.distance_to(Pose3D::identity()), std::sqrt(5.0));
}

TEST(TransformStamped, IdentityAndMake) {
  const auto id = TransformStamped::identity();
  EXPECT_EQ(id.translation, (std::array<double, 3>{0, 0, 0}));
  EXPECT_EQ(id.rotation, (std::array<double, 4>{0, 0, 0, 1}));
  EXPECT_TRUE(id.is_valid());
  const auto tf = TransformStamped::make({1.0, 2.0, 3.0}, {0.0, 0.0, 0.0, 1.0});
  EXPECT_EQ(tf.translation, (std::array<double, 3>{1, 2, 3}));
  EXPECT_TRUE(tf.is_valid());
}

TEST(TransformStamped, FromPose2DUsesYawAndKeepsTimestamp) {
  Pose2D p = Pose2D::make(1.0, 2.0, 0.5);
  p.timestamp_ns = 7;
  const auto tf = TransformStamped::from_pose_2d(p);
  EXPECT_EQ(tf.translation, (std::array<double, 3>{1.0, 2.0, 0.0}));
  EXPECT_NEAR(tf.rotation[2], std::sin(0.25), 1e-15);
  EXPECT_NEAR(tf.rotation[3], std::cos(0.25), 1e-15);
  EXPECT_EQ(tf.rotation[0], 0.0);
  EXPECT_EQ(tf.rotation[1], 0.0);
  EXPECT_EQ(tf.timestamp_ns, 7u);
  EXPECT_TRUE(tf.is_valid());
}

TEST(TransformStamped, NormalizeRotationScalesToUnitAndZeroBecomesIdentity) {
  auto tf = TransformStamped::make({1, 2, 3}, {0, 0, 3, 4});
  EXPECT_FALSE(tf.is_valid());
  tf.normalize_rotation();
  EXPECT_EQ(tf.rotation, (std::array<double, 4>{0, 0, 0.6, 0.8}));
  EXPECT_TRUE(tf.is_valid());

  TransformStamped zero{};
  EXPECT_FALSE(zero.is_valid());
  zero.normalize_rotation();
  EXPECT_EQ(zero.rotation, (std::array<double, 4>{0, 0, 0, 1}));
  EXPECT_TRUE(zero.is_valid());
}

TEST(TransformStamped, IsValidRejectsNonFiniteTranslation) {
  auto tf = TransformStamped::identity();
  tf.translation[1] = kNaN;
  EXPECT_FALSE(tf.is_valid());
}

// ===========================================================================
// Imu

TEST(Imu, MakeHasIdentityOrientationAndZeroData) {
  const Imu imu = Imu::make();
  EXPECT_EQ(imu.orientation, (std::array<double, 4>{0, 0, 0, 1}));
  EXPECT_EQ(imu.angular_velocity, (std::array<double, 3>{}));
  EXPECT_EQ(imu.linear_acceleration, (std::array<double, 3>{}));
  EXPECT_EQ(imu.orientation_covariance, (std::array<double, 9>{}));
  EXPECT_TRUE(imu.has_orientation());
  EXPECT_TRUE(imu.is_valid());
  EXPECT_EQ(imu.timestamp_ns, 0u);
}

TEST(Imu, SetOrientationFromEulerMatchesQuaternionFromEuler) {
  Imu imu = Imu::make();
  imu.set_orientation_from_euler(0.1, 0.2, 1.5);
  const Quaternion q = Quaternion::from_euler(0.1, 0.2, 1.5);
  EXPECT_EQ(imu.orientation, (std::array<double, 4>{q.x, q.y, q.z, q.w}));
}

TEST(Imu, HasOrientationIsFalseWhenCovarianceStartsWithMinusOne) {
  Imu imu = Imu::make();
  imu.orientation_covariance[0] = -1.0;
  EXPECT_FALSE(imu.has_orientation());
  EXPECT_TRUE(imu.is_valid());
}

TEST(Imu, HasOrientationNeedsANonNegativeFirstCovariance) {
  Imu imu = Imu::make();
  imu.orientation_covariance[0] = 0.0;
  EXPECT_TRUE(imu.has_orientation());
  imu.orientation_covariance[0] = 0.02;
  EXPECT_TRUE(imu.has_orientation());
  imu.orientation_covariance[0] = -1.0;  // the ROS sentinel
  EXPECT_FALSE(imu.has_orientation());
  imu.orientation_covariance[0] = -2.0;  // any other negative sentinel
  EXPECT_FALSE(imu.has_orientation());
  imu.orientation_covariance[0] = -1e-300;
  EXPECT_FALSE(imu.has_orientation());
  imu.orientation_covariance[0] = kNaN;
  EXPECT_FALSE(imu.has_orientation());
  imu.orientation_covariance[0] = -kInf;
  EXPECT_FALSE(imu.has_orientation());
  // Only the first element decides.
  imu.orientation_covariance = {};
  imu.orientation_covariance[4] = -1.0;
  EXPECT_TRUE(imu.has_orientation());
}

TEST(Imu, IsValidRejectsAnyNonFiniteNumber) {
  Imu a = Imu::make();
  a.linear_acceleration[2] = kNaN;
  EXPECT_FALSE(a.is_valid());
  Imu b = Imu::make();
  b.angular_velocity_covariance[8] = kInf;
  EXPECT_FALSE(b.is_valid());
  Imu c = Imu::make();
  c.orientation[0] = kNaN;
  EXPECT_FALSE(c.is_valid());
}

// ===========================================================================
// LaserScan

TEST(LaserScan, MakeCoversAFullTurnAtOneDegree) {
  const LaserScan s = LaserScan::make();
  EXPECT_FLOAT_EQ(s.angle_min, -std::numbers::pi_v<float>);
  EXPECT_FLOAT_EQ(s.angle_max, std::numbers::pi_v<float>);
  EXPECT_FLOAT_EQ(s.angle_increment, 2.0f * std::numbers::pi_v<float> / 360.0f);
  EXPECT_FLOAT_EQ(s.range_min, 0.1f);
  EXPECT_FLOAT_EQ(s.range_max, 30.0f);
  EXPECT_EQ(s.ranges.size(), 360u);
  EXPECT_EQ(s.valid_count(), 0u);
}

TEST(LaserScan, MakeHasHorusScanTimeOfATenthOfASecond) {
  const LaserScan s = LaserScan::make();
  EXPECT_EQ(s.scan_time, 0.1f);
  EXPECT_EQ(s.time_increment, 0.0f);
  EXPECT_EQ(s.timestamp_ns, 0u);
  EXPECT_NE(s, LaserScan{});
}

TEST(LaserScan, AngleAtStartsAtAngleMinAndStepsByIncrement) {
  const LaserScan s = LaserScan::make();
  EXPECT_EQ(s.angle_at(0), s.angle_min);
  EXPECT_NEAR(s.angle_at(90), -kPi / 2, 1e-5);
  EXPECT_NEAR(s.angle_at(180), 0.0, 1e-5);
  EXPECT_NEAR(s.angle_at(359), kPi - 2 * kPi / 360, 1e-5);

  LaserScan custom{};
  custom.angle_min = 0.5f;
  custom.angle_increment = 0.25f;
  EXPECT_FLOAT_EQ(custom.angle_at(4), 1.5f);
}

TEST(LaserScan, IsRangeValidRejectsZeroNonFiniteOutOfLimitsAndOutOfBounds) {
  LaserScan s = LaserScan::make();  // limits [0.1, 30]
  s.ranges[0] = 5.2f;
  s.ranges[1] = 0.0f;
  s.ranges[2] = std::numeric_limits<float>::quiet_NaN();
  s.ranges[3] = std::numeric_limits<float>::infinity();
  s.ranges[4] = 0.05f;   // below range_min
  s.ranges[5] = 30.5f;   // above range_max
  s.ranges[6] = 0.1f;    // exactly range_min
  s.ranges[7] = 30.0f;   // exactly range_max
  s.ranges[8] = -1.0f;
  s.ranges[359] = 1.0f;  // last beam
  EXPECT_TRUE(s.is_range_valid(0));
  EXPECT_FALSE(s.is_range_valid(1));
  EXPECT_FALSE(s.is_range_valid(2));
  EXPECT_FALSE(s.is_range_valid(3));
  EXPECT_FALSE(s.is_range_valid(4));
  EXPECT_FALSE(s.is_range_valid(5));
  EXPECT_TRUE(s.is_range_valid(6));
  EXPECT_TRUE(s.is_range_valid(7));
  EXPECT_FALSE(s.is_range_valid(8));
  EXPECT_TRUE(s.is_range_valid(359));
  EXPECT_FALSE(s.is_range_valid(360));
  EXPECT_FALSE(s.is_range_valid(static_cast<std::size_t>(-1)));
  EXPECT_EQ(s.valid_count(), 4u);
}

TEST(LaserScan, ZeroIsInvalidEvenWhenRangeMinIsZero) {
  LaserScan s{};
  s.range_max = 10.0f;
  s.ranges[0] = 0.0f;
  s.ranges[1] = 0.5f;
  EXPECT_FALSE(s.is_range_valid(0));
  EXPECT_TRUE(s.is_range_valid(1));
  EXPECT_EQ(s.valid_count(), 1u);
}

TEST(LaserScan, MinRangeIsNulloptForAnEmptyScan) {
  EXPECT_EQ(LaserScan::make().min_range(), std::nullopt);
  EXPECT_EQ(LaserScan{}.min_range(), std::nullopt);
  LaserScan all_bad = LaserScan::make();
  all_bad.ranges.fill(std::numeric_limits<float>::infinity());
  EXPECT_EQ(all_bad.min_range(), std::nullopt);
}

TEST(LaserScan, MinRangeIgnoresInvalidReadings) {
  LaserScan s = LaserScan::make();
  s.ranges[10] = 2.0f;
  s.ranges[20] = 0.45f;
  s.ranges[30] = 0.05f;  // below range_min: ignored
  s.ranges[40] = std::numeric_limits<float>::quiet_NaN();
  s.ranges[50] = 7.0f;
  ASSERT_TRUE(s.min_range().has_value());
  EXPECT_EQ(*s.min_range(), 0.45f);
}

TEST(LaserScan, LogSummaryIsShortAndHasUnits) {
  LaserScan s = LaserScan::make();
  for (std::size_t i = 0; i < 120; ++i) s.ranges[i * 3] = 0.45f + 0.1f * static_cast<float>(i);
  const std::string summary = s.log_summary();
  EXPECT_EQ(summary, "LaserScan(360 ranges, 120 valid, min 0.45 m, fov 6.28 rad)");
  EXPECT_LT(summary.size(), 200u);
  EXPECT_EQ(horus::log_summary(s), summary);
  EXPECT_EQ(LaserScan::make().log_summary(), "LaserScan(360 ranges, 0 valid, min none, fov 6.28 rad)");
}

// ===========================================================================
// Odometry

TEST(Odometry, SetFramesStoresBothNames) {
  Odometry odom{};
  EXPECT_TRUE(odom.set_frames("odom", "base_link"));
  EXPECT_EQ(odom.frame_id_str(), "odom");
  EXPECT_EQ(odom.child_frame_id_str(), "base_link");
  // Shorter names replace longer ones completely.
  EXPECT_TRUE(odom.set_frames("map", "b"));
  EXPECT_EQ(odom.frame_id_str(), "map");
  EXPECT_EQ(odom.child_frame_id_str(), "b");
}

TEST(Odometry, SetFramesRejectsNamesThatDoNotFitAndLeavesBothUnchanged) {
  Odometry odom{};
  ASSERT_TRUE(odom.set_frames("odom", "base_link"));
  const std::string max_len(31, 'a');
  const std::string too_long(32, 'a');
  EXPECT_FALSE(odom.set_frames(too_long, "child"));
  EXPECT_EQ(odom.frame_id_str(), "odom");
  EXPECT_EQ(odom.child_frame_id_str(), "base_link");
  EXPECT_FALSE(odom.set_frames("frame", too_long));
  EXPECT_EQ(odom.frame_id_str(), "odom");
  EXPECT_EQ(odom.child_frame_id_str(), "base_link");
  EXPECT_FALSE(odom.set_frames(std::string_view("od\0m", 4), "child"));
  EXPECT_EQ(odom.frame_id_str(), "odom");

  EXPECT_TRUE(odom.set_frames(max_len, max_len));
  EXPECT_EQ(odom.frame_id_str(), max_len);
  EXPECT_EQ(odom.child_frame_id_str(), max_len);
}

TEST(Odometry, UpdateReplacesPoseAndTwist) {
  Odometry odom{};
  odom.timestamp_ns = 5;
  odom.update(Pose2D::make(1, 2, 0.5), Twist::new_2d(0.5, 0.2));
  EXPECT_EQ(odom.pose, Pose2D::make(1, 2, 0.5));
  EXPECT_EQ(odom.twist, Twist::new_2d(0.5, 0.2));
  EXPECT_EQ(odom.timestamp_ns, 5u);
  odom.update(Pose2D::make(3, 4, 0), Twist::stop(), 77);
  EXPECT_EQ(odom.pose.x, 3.0);
  EXPECT_EQ(odom.timestamp_ns, 77u);
}

TEST(Odometry, MakeIsAtTheOriginAtRestWithNoFrames) {
  constexpr Odometry odom = Odometry::make();
  static_assert(odom.pose == Pose2D::origin());
  EXPECT_EQ(odom.pose, Pose2D::origin());
  EXPECT_EQ(odom.twist, Twist::stop());
  EXPECT_EQ(odom.pose_covariance, (std::array<double, 36>{}));
  EXPECT_EQ(odom.twist_covariance, (std::array<double, 36>{}));
  EXPECT_EQ(odom.frame_id_str(), "");
  EXPECT_EQ(odom.child_frame_id_str(), "");
  EXPECT_EQ(odom.timestamp_ns, 0u);
  EXPECT_EQ(odom, Odometry{});
  EXPECT_TRUE(odom.is_valid());
}

TEST(Odometry, IsValidNeedsFinitePoseTwistAndCovariances) {
  Odometry odom = Odometry::make();
  odom.update(Pose2D::make(1e6, -2.0, 3.0), Twist::new_2d(-0.5, 0.2));
  odom.pose_covariance[0] = 0.01;
  odom.twist_covariance[35] = 0.02;
  EXPECT_TRUE(odom.is_valid());

  Odometry a = odom;
  a.pose.x = kNaN;
  EXPECT_FALSE(a.is_valid());
  Odometry b = odom;
  b.pose.theta = kInf;
  EXPECT_FALSE(b.is_valid());
  Odometry c = odom;
  c.twist.linear[1] = kNaN;
  EXPECT_FALSE(c.is_valid());
  Odometry d = odom;
  d.twist.angular[2] = -kInf;
  EXPECT_FALSE(d.is_valid());
  Odometry e = odom;
  e.pose_covariance[35] = kNaN;
  EXPECT_FALSE(e.is_valid());
  Odometry f = odom;
  f.twist_covariance[0] = kInf;
  EXPECT_FALSE(f.is_valid());
  // Timestamps are not checked.
  Odometry g = odom;
  g.timestamp_ns = ~0ULL;
  g.pose.timestamp_ns = ~0ULL;
  EXPECT_TRUE(g.is_valid());
}

TEST(Odometry, LogSummaryNamesFramesWithUnits) {
  Odometry odom{};
  odom.set_frames("odom", "base_link");
  odom.update(Pose2D::make(1, 2, 0.5), Twist::new_2d(0.5, 0.2));
  EXPECT_EQ(odom.log_summary(),
            "Odometry(odom -> base_link, x 1.00 m, y 2.00 m, theta 0.50 rad, v 0.50 m/s, w 0.20 rad/s)");
}

// ===========================================================================
// JointState

TEST(JointState, AddJointAppendsNamesAndValues) {
  JointState js{};
  EXPECT_TRUE(js.add_joint("shoulder", 0.5));
  EXPECT_TRUE(js.add_joint("elbow", -1.2, 0.3, 4.0));
  EXPECT_EQ(js.joint_count, 2u);
  EXPECT_EQ(js.name_at(0), "shoulder");
  EXPECT_EQ(js.name_at(1), "elbow");
  EXPECT_EQ(js.positions[1], -1.2);
  EXPECT_EQ(js.velocities[1], 0.3);
  EXPECT_EQ(js.efforts[1], 4.0);
  EXPECT_EQ(js.velocities[0], 0.0);
  EXPECT_EQ(js.position_of("shoulder"), 0.5);
  EXPECT_EQ(js.position_of("elbow"), -1.2);
  EXPECT_EQ(js.position_of("wrist"), std::nullopt);
  EXPECT_EQ(js.position_of(""), std::nullopt);
}

TEST(JointState, IsFullAtSixteenJoints) {
  JointState js{};
  for (int i = 0; i < 16; ++i) EXPECT_TRUE(js.add_joint(fmt::format("j{}", i), i)) << i;
  EXPECT_EQ(js.joint_count, 16u);
  const JointState before = js;
  EXPECT_FALSE(js.add_joint("j16", 16.0));
  EXPECT_EQ(js, before);
  EXPECT_EQ(js.position_of("j15"), 15.0);
}

TEST(JointState, AddJointRejectsNamesThatDoNotFitDuplicatesAndEmptyNames) {
  JointState js{};
  ASSERT_TRUE(js.add_joint("elbow", 1.0));
  const JointState before = js;
  EXPECT_FALSE(js.add_joint(std::string(32, 'n'), 2.0));
  EXPECT_FALSE(js.add_joint("elbow", 2.0));
  EXPECT_FALSE(js.add_joint("", 2.0));
  EXPECT_EQ(js, before);
  EXPECT_TRUE(js.add_joint(std::string(31, 'n'), 2.0));
  EXPECT_EQ(js.name_at(1), std::string(31, 'n'));
}

TEST(JointState, NameAtOutsideTheActiveJointsIsEmpty) {
  JointState js{};
  js.add_joint("a", 0);
  EXPECT_EQ(js.name_at(1), "");
  EXPECT_EQ(js.name_at(100), "");
}

TEST(JointState, CorruptJointCountIsClampedToSixteen) {
  JointState js{};
  js.joint_count = 200;
  EXPECT_EQ(js.count(), 16u);
  EXPECT_EQ(js.name_at(20), "");
  EXPECT_FALSE(js.add_joint("x", 0));
  EXPECT_LT(js.log_summary().size(), 200u);
}

TEST(JointState, LogSummaryIsShortAndHasUnits) {
  JointState js{};
  js.add_joint("shoulder", 0.5);
  js.add_joint("elbow", -1.2);
  js.add_joint("wrist", 0.0);
  EXPECT_EQ(js.log_summary(), "JointState(3 joints, positions in rad or m: shoulder=0.5, elbow=-1.2, wrist=0)");
  EXPECT_EQ(horus::log_summary(js), js.log_summary());
  EXPECT_EQ(JointState{}.log_summary(), "JointState(0 joints)");

  // Worst case: 16 joints with 31-character names and very long numbers.
  JointState big{};
  for (int i = 0; i < 16; ++i)
    ASSERT_TRUE(big.add_joint(fmt::format("{:c}{}", 'a' + i, std::string(30, 'x')), -1.234567e300));
  const std::string summary = big.log_summary();
  EXPECT_LT(summary.size(), 200u) << summary;
  EXPECT_NE(summary.find("rad"), std::string::npos);
  EXPECT_NE(summary.find("16 joints"), std::string::npos);
  EXPECT_NE(summary.find("more)"), std::string::npos);
}

// ===========================================================================
// JointCommand

TEST(JointCommand, ModeConstantsMatchTheSpec) {
  EXPECT_EQ(JointCommand::MODE_POSITION, 0);
  EXPECT_EQ(JointCommand::MODE_VELOCITY, 1);
  EXPECT_EQ(JointCommand::MODE_EFFORT, 2);
}

TEST(JointCommand, AddPositionAndVelocitySetTargetAndMode) {
  JointCommand cmd{};
  EXPECT_TRUE(cmd.add_position("shoulder", 1.0));
  EXPECT_TRUE(cmd.add_velocity("wheel", 0.5));
  EXPECT_TRUE(cmd.add_effort("gripper", 2.0));
  EXPECT_EQ(cmd.joint_count, 3u);
  EXPECT_EQ(cmd.name_at(0), "shoulder");
  EXPECT_EQ(cmd.positions[0], 1.0);
  EXPECT_EQ(cmd.modes[0], JointCommand::MODE_POSITION);
  EXPECT_EQ(cmd.name_at(1), "wheel");
  EXPECT_EQ(cmd.velocities[1], 0.5);
  EXPECT_EQ(cmd.modes[1], JointCommand::MODE_VELOCITY);
  EXPECT_EQ(cmd.efforts[2], 2.0);
  EXPECT_EQ(cmd.modes[2], JointCommand::MODE_EFFORT);
}

TEST(JointCommand, AddingAKnownJointUpdatesItInPlace) {
  JointCommand cmd{};
  ASSERT_TRUE(cmd.add_position("elbow", 1.0));
  EXPECT_TRUE(cmd.add_velocity("elbow", 0.25));
  EXPECT_EQ(cmd.joint_count, 1u);
  EXPECT_EQ(cmd.positions[0], 1.0);
  EXPECT_EQ(cmd.velocities[0], 0.25);
  EXPECT_EQ(cmd.modes[0], JointCommand::MODE_VELOCITY);
}

TEST(JointCommand, RejectsNewJointsWhenFullOrWhenTheNameDoesNotFit) {
  JointCommand cmd{};
  for (int i = 0; i < 16; ++i) ASSERT_TRUE(cmd.add_position(fmt::format("j{}", i), i));
  const JointCommand before = cmd;
  EXPECT_FALSE(cmd.add_position("j16", 1.0));
  EXPECT_FALSE(cmd.add_velocity("j17", 1.0));
  EXPECT_EQ(cmd, before);
  EXPECT_TRUE(cmd.add_position("j3", 33.0));  // known joint: still updatable
  EXPECT_EQ(cmd.positions[3], 33.0);

  JointCommand small{};
  EXPECT_FALSE(small.add_position(std::string(32, 'n'), 1.0));
  EXPECT_FALSE(small.add_position("", 1.0));
  EXPECT_EQ(small, JointCommand{});
}

TEST(JointCommand, LogSummaryIsShortAndHasUnits) {
  JointCommand cmd{};
  cmd.add_position("shoulder", 1.0);
  cmd.add_velocity("wheel", 0.5);
  EXPECT_EQ(cmd.log_summary(), "JointCommand(2 joints: shoulder pos 1 rad|m, wheel vel 0.5 rad/s|m/s)");
  JointCommand big{};
  for (int i = 0; i < 16; ++i)
    ASSERT_TRUE(big.add_velocity(fmt::format("{:c}{}", 'a' + i, std::string(30, 'x')), -1.234567e300));
  EXPECT_LT(big.log_summary().size(), 200u) << big.log_summary();
}

// ===========================================================================
// Heartbeat

TEST(Heartbeat, CreateSetsNameIdAndAlive) {
  const auto hb = Heartbeat::create("planner", 7);
  ASSERT_TRUE(hb.has_value());
  EXPECT_EQ(hb->node_name_str(), "planner");
  EXPECT_EQ(hb->node_id, 7u);
  EXPECT_EQ(hb->alive, 1u);
  EXPECT_EQ(hb->sequence, 0u);
  EXPECT_EQ(Heartbeat::make("planner", 7), *hb);
}

TEST(Heartbeat, NamesThatDoNotFitAreRejected) {
  const std::string too_long(32, 'n');
  EXPECT_EQ(Heartbeat::create(too_long, 1), std::nullopt);
  EXPECT_THROW((void)Heartbeat::make(too_long, 1), std::invalid_argument);
  EXPECT_TRUE(Heartbeat::create(std::string(31, 'n'), 1).has_value());

  Heartbeat hb = Heartbeat::make("node", 1);
  EXPECT_FALSE(hb.set_node_name(too_long));
  EXPECT_EQ(hb.node_name_str(), "node");
  EXPECT_TRUE(hb.set_node_name("other"));
  EXPECT_EQ(hb.node_name_str(), "other");
}

TEST(Heartbeat, UpdateIncrementsSequenceAndMarksAlive) {
  Heartbeat hb{};
  hb.update(1.5);
  EXPECT_EQ(hb.sequence, 1u);
  EXPECT_EQ(hb.alive, 1u);
  EXPECT_EQ(hb.uptime, 1.5);
  hb.alive = 0;
  hb.update(2.5);
  EXPECT_EQ(hb.sequence, 2u);
  EXPECT_EQ(hb.alive, 1u);
  EXPECT_EQ(hb.uptime, 2.5);
}

// ===========================================================================
// Properties of every message

template <class T>
T sample();

template <>
Point3 sample<Point3>() { return Point3::make(1.5, -2.25, 3.0); }
template <>
Vector3 sample<Vector3>() { return Vector3::make(0.1, 0.2, -0.3); }
template <>
Quaternion sample<Quaternion>() { return Quaternion::from_euler(0.1, 0.2, 0.3); }
template <>
CmdVel sample<CmdVel>() { return CmdVel::with_timestamp(1.25f, -0.1f, 1'700'000'000'123'456'789ULL); }
template <>
Twist sample<Twist>() {
  Twist t = Twist::make({1.0, 0.5, -0.25}, {0.1, 0.2, 0.3});
  t.timestamp_ns = 18'446'744'073'709'551'615ULL;  // u64 max survives JSON
  return t;
}
template <>
Pose2D sample<Pose2D>() {
  Pose2D p = Pose2D::make(1.0, 2.0, 0.5);
  p.timestamp_ns = 123;
  return p;
}
template <>
Pose3D sample<Pose3D>() {
  Pose3D p = Pose3D::from_pose_2d(sample<Pose2D>());
  p.position.z = -0.75;
  return p;
}
template <>
TransformStamped sample<TransformStamped>() {
  TransformStamped tf = TransformStamped::make({1.0, 2.0, 3.0}, {0.0, 0.0, 0.6, 0.8});
  tf.timestamp_ns = 55;
  return tf;
}
template <>
Imu sample<Imu>() {
  Imu imu = Imu::make();
  imu.set_orientation_from_euler(0.1, 0.2, 1.5);
  imu.orientation_covariance[0] = -1.0;
  imu.angular_velocity = {0.1, 0.2, 0.3};
  imu.linear_acceleration = {0.0, 0.0, 9.81};
  imu.linear_acceleration_covariance[4] = 0.01;
  imu.timestamp_ns = 9;
  return imu;
}
template <>
LaserScan sample<LaserScan>() {
  LaserScan s = LaserScan::make();
  for (std::size_t i = 0; i < s.ranges.size(); ++i) s.ranges[i] = 0.1f * static_cast<float>(i % 50);
  s.time_increment = 1e-4f;
  s.scan_time = 0.125f;  // not make()'s 0.1 s
  s.timestamp_ns = 1000;
  return s;
}
template <>
Odometry sample<Odometry>() {
  Odometry o{};
  o.set_frames("odom", "base_link");
  o.update(sample<Pose2D>(), Twist::new_2d(0.5, 0.2), 77);
  o.pose_covariance[0] = 0.01;
  o.twist_covariance[35] = 0.02;
  return o;
}
template <>
JointState sample<JointState>() {
  JointState js{};
  js.add_joint("shoulder", 0.5, 0.1, 2.0);
  js.add_joint("elbow", -1.2);
  js.timestamp_ns = 3;
  return js;
}
template <>
JointCommand sample<JointCommand>() {
  JointCommand c{};
  c.add_position("shoulder", 1.0);
  c.add_velocity("wheel", 0.5);
  c.efforts[0] = 10.0;
  c.timestamp_ns = 4;
  return c;
}
template <>
Heartbeat sample<Heartbeat>() {
  Heartbeat hb = Heartbeat::make("planner", 42);
  hb.update(12.5);
  hb.timestamp_ns = 8;
  return hb;
}

template <class T>
class EveryMessage : public ::testing::Test {};
using AllMessages = ::testing::Types<Point3, Vector3, Quaternion, CmdVel, Twist, Pose2D, Pose3D, TransformStamped, Imu,
                                     LaserScan, Odometry, JointState, JointCommand, Heartbeat>;
TYPED_TEST_SUITE(EveryMessage, AllMessages);

TYPED_TEST(EveryMessage, IsTriviallyCopyableAndStandardLayout) {
  static_assert(std::is_trivially_copyable_v<TypeParam>);
  static_assert(std::is_standard_layout_v<TypeParam>);
  static_assert(horus::reflect::is_fixed_size<TypeParam>);
  static_assert(std::is_aggregate_v<TypeParam>);
  // A memcpy is a full copy.
  const TypeParam original = sample<TypeParam>();
  TypeParam copy{};
  std::memcpy(&copy, &original, sizeof(TypeParam));
  EXPECT_EQ(copy, original);
}

TYPED_TEST(EveryMessage, DefaultValueIsAllZeros) {
  const auto zero = std::bit_cast<TypeParam>(std::array<unsigned char, sizeof(TypeParam)>{});
  EXPECT_EQ(TypeParam{}, zero);
}

TYPED_TEST(EveryMessage, JsonRoundTripGivesAnEqualMessage) {
  const TypeParam original = sample<TypeParam>();
  ASSERT_NE(original, TypeParam{}) << "the sample should exercise non-default values";
  const nlohmann::json j = horus::to_json(original);
  EXPECT_EQ(horus::from_json<TypeParam>(j), original);
  // And through text, as a file or a socket would carry it.
  EXPECT_EQ(horus::from_json<TypeParam>(nlohmann::json::parse(j.dump())), original) << j.dump();
}

TYPED_TEST(EveryMessage, FormatsWithItsShortTypeName) {
  const std::string text = fmt::format("{}", sample<TypeParam>());
  const std::string_view qualified = horus::type_name<TypeParam>();
  const std::string short_name(qualified.substr(qualified.rfind("::") + 2));
  EXPECT_EQ(text.rfind(short_name + " { ", 0), 0u) << text;
  EXPECT_EQ(text, horus::to_string(sample<TypeParam>()));
}

TYPED_TEST(EveryMessage, LivesInHorusMsgNamespace) {
  EXPECT_EQ(horus::type_name<TypeParam>().rfind("horus::msg::", 0), 0u) << horus::type_name<TypeParam>();
}

// ===========================================================================
// Printing

TEST(Formatting, Pose2DPrintsEveryField) {
  EXPECT_EQ(fmt::format("{}", sample<Pose2D>()), "Pose2D { x: 1, y: 2, theta: 0.5, timestamp_ns: 123 }");
}

TEST(Formatting, CmdVelPrintsFloatsShortest) {
  EXPECT_EQ(fmt::format("{}", CmdVel::with_timestamp(1.5f, -0.25f, 123)),
            "CmdVel { stamp_nanos: 123, linear: 1.5, angular: -0.25 }");
}

TEST(Formatting, ArraysNestedMessagesAndTextFields) {
  EXPECT_EQ(fmt::format("{}", Twist::new_2d(1.0, 0.5)),
            "Twist { linear: [1, 0, 0], angular: [0, 0, 0.5], timestamp_ns: 0 }");
  Pose3D p = Pose3D::identity();
  p.position = Point3::make(1, 2, 3);
  EXPECT_EQ(fmt::format("{}", p),
            "Pose3D { position: Point3 { x: 1, y: 2, z: 3 }, orientation: Quaternion { x: 0, y: 0, z: 0, w: 1 }, "
            "timestamp_ns: 0 }");
  EXPECT_EQ(fmt::format("{}", Heartbeat::make("planner", 7)),
            "Heartbeat { node_name: \"planner\", node_id: 7, sequence: 0, alive: 1, uptime: 0, timestamp_ns: 0 }");
}

TEST(Formatting, LogSummaryFallsBackToTheFullFormat) {
  EXPECT_EQ(horus::log_summary(sample<Pose2D>()), "Pose2D { x: 1, y: 2, theta: 0.5, timestamp_ns: 123 }");
}

// ===========================================================================
// Eigen interop

TEST(Eigen, PointAndVectorRoundTripExactly) {
  const Point3 p = Point3::make(1.5, -2.0, 3.25);
  const Eigen::Vector3d ep = to_eigen(p);
  EXPECT_EQ(ep, Eigen::Vector3d(1.5, -2.0, 3.25));
  EXPECT_EQ(point3_from_eigen(ep), p);
  const Vector3 v = Vector3::make(0.1, 0.2, 0.3);
  EXPECT_EQ(vector3_from_eigen(to_eigen(v)), v);
}

TEST(Eigen, QuaternionKeepsComponentOrder) {
  const Quaternion q{0.1, 0.2, 0.3, 0.9};
  const Eigen::Quaterniond e = to_eigen(q);
  EXPECT_EQ(e.x(), 0.1);
  EXPECT_EQ(e.y(), 0.2);
  EXPECT_EQ(e.z(), 0.3);
  EXPECT_EQ(e.w(), 0.9);
  EXPECT_EQ(quaternion_from_eigen(e), q);
}

TEST(Eigen, FromEulerAgreesWithEigenAngleAxisZYX) {
  for (const auto& e : {EulerAngles{0.1, 0.2, 1.5}, EulerAngles{-2.0, 0.7, 3.0}, EulerAngles{1.0, -1.4, -0.3}}) {
    const Eigen::Quaterniond expected = Eigen::AngleAxisd(e.yaw, Eigen::Vector3d::UnitZ()) *
                                        Eigen::AngleAxisd(e.pitch, Eigen::Vector3d::UnitY()) *
                                        Eigen::AngleAxisd(e.roll, Eigen::Vector3d::UnitX());
    EXPECT_TRUE(SameRotation(Quaternion::from_euler(e.roll, e.pitch, e.yaw), quaternion_from_eigen(expected)));
  }
}

TEST(Eigen, Pose3DRoundTripWithinTolerance) {
  Pose3D p{Point3::make(1, -2, 3), Quaternion::from_euler(0.3, -0.2, 2.5), 0};
  const Eigen::Isometry3d t = to_eigen(p);
  const Pose3D back = pose3d_from_eigen(t, 1234);
  EXPECT_NEAR(back.position.x, 1.0, 1e-12);
  EXPECT_NEAR(back.position.y, -2.0, 1e-12);
  EXPECT_NEAR(back.position.z, 3.0, 1e-12);
  EXPECT_TRUE(SameRotation(back.orientation, p.orientation));
  EXPECT_NEAR(back.orientation.norm(), 1.0, 1e-12);
  EXPECT_EQ(back.timestamp_ns, 1234u);
}

TEST(Eigen, Pose3DIsometryMovesPointsLikeThePose) {
  const Pose3D p = Pose3D::from_pose_2d(Pose2D::make(1, 2, kPi / 2));
  const Eigen::Vector3d moved = to_eigen(p) * Eigen::Vector3d(1, 0, 0);
  EXPECT_NEAR(moved.x(), 1.0, 1e-12);
  EXPECT_NEAR(moved.y(), 3.0, 1e-12);
  EXPECT_NEAR(moved.z(), 0.0, 1e-12);
}

TEST(Eigen, ZeroRotationBecomesIdentityIsometry) {
  const Pose3D p{Point3::make(1, 2, 3), Quaternion{}, 0};
  EXPECT_TRUE(to_eigen(p).linear().isApprox(Eigen::Matrix3d::Identity()));
  const TransformStamped tf{{0, 0, 0}, {0, 0, 0, 0}, 0};
  EXPECT_TRUE(to_eigen(tf).linear().isApprox(Eigen::Matrix3d::Identity()));
}

TEST(Eigen, TransformRoundTripWithinTolerance) {
  const Quaternion q = Quaternion::from_euler(-1.0, 0.4, 0.2);
  const TransformStamped tf = TransformStamped::make({0.5, 1.5, -2.5}, {q.x, q.y, q.z, q.w});
  const TransformStamped back = transform_from_eigen(to_eigen(tf), 9);
  for (std::size_t i = 0; i < 3; ++i) EXPECT_NEAR(back.translation[i], tf.translation[i], 1e-12);
  EXPECT_TRUE(SameRotation(back.rotation_quaternion(), q));
  EXPECT_EQ(back.timestamp_ns, 9u);
  // Composition in Eigen matches applying the transforms one after the other.
  const Eigen::Isometry3d twice = to_eigen(tf) * to_eigen(tf);
  const Eigen::Vector3d a = twice * Eigen::Vector3d(1, 2, 3);
  const Eigen::Vector3d b = to_eigen(tf) * (to_eigen(tf) * Eigen::Vector3d(1, 2, 3));
  EXPECT_TRUE(a.isApprox(b, 1e-12));
}

TEST(Eigen, Pose2DRoundTripWrapsTheta) {
  const Pose2D p = Pose2D::make(1.0, -2.0, 0.75);
  const Pose2D back = pose2d_from_eigen(to_eigen(p));
  EXPECT_NEAR(back.x, 1.0, 1e-12);
  EXPECT_NEAR(back.y, -2.0, 1e-12);
  EXPECT_NEAR(back.theta, 0.75, 1e-12);

  const Pose2D wrapped = pose2d_from_eigen(to_eigen(Pose2D::make(0, 0, 4.0)), 5);
  EXPECT_NEAR(wrapped.theta, normalize_angle(4.0), 1e-12);
  EXPECT_EQ(wrapped.timestamp_ns, 5u);

  const Eigen::Vector2d moved = to_eigen(Pose2D::make(1, 2, kPi / 2)) * Eigen::Vector2d(1, 0);
  EXPECT_NEAR(moved.x(), 1.0, 1e-12);
  EXPECT_NEAR(moved.y(), 3.0, 1e-12);
}

}  // namespace
