// Unit tests of the geometry messages (angles, Pose2D, CmdVel, Twist, Point3, Vector3, Quaternion,
// Pose3D, TransformStamped), the properties of every core message, printing and Eigen interop.
// The sensor, joint and heartbeat messages are in test_msg_sensors.cpp.
#include "msg_core_test.hpp"
#include "msg_properties_test.hpp"

#include "horus/msg/eigen.hpp"

namespace {

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
// Properties of every core message: samples with non-default values, and the typed suite

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

// The core family's types: the properties every message has (msg_properties_test.hpp).
using CoreMessages = ::testing::Types<Point3, Vector3, Quaternion, CmdVel, Twist, Pose2D, Pose3D, TransformStamped,
                                      Imu, LaserScan, Odometry, JointState, JointCommand, Heartbeat>;
INSTANTIATE_TYPED_TEST_SUITE_P(Core, MessageProperties, CoreMessages);

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
