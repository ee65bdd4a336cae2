// Unit tests of the sensor, joint and heartbeat messages of the core family: Imu, LaserScan,
// Odometry, JointState (sensor.hpp), JointCommand (control.hpp), Heartbeat (diagnostics.hpp).
// Their samples and the properties of every core message are in test_messages.cpp.
#include "msg_core_test.hpp"

namespace {

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

}  // namespace
