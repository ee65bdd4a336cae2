// Unit tests of the navigation goals and paths: Goal / NavGoal, GoalStatus / GoalResult,
// Waypoint, Path and NavPath, PathPlan (navigation.hpp).
#include "msg_navigation_test.hpp"

namespace {

// ===========================================================================
// Goal / NavGoal

TEST(Goal, NavGoalIsTheSameTypeAsGoal) {
  static_assert(std::is_same_v<NavGoal, Goal>);
  EXPECT_EQ(horus::type_name<NavGoal>(), "horus::msg::Goal");
}

TEST(Goal, DesignatedInitialiserNavGoalSetsTheTimestamp) {
  // The page's example, written with designated initialisers: fields not named
  // (priority, goal_id) stay zero and the stamp lands in timestamp_ns.
  const NavGoal goal{.target_pose = Pose2D::make(5.0, 3.0, 0.0),
                     .tolerance_position = 0.1,
                     .tolerance_angle = 0.05,
                     .timeout_seconds = 30.0,
                     .timestamp_ns = 1'700'000'000'000'000'123ULL};
  EXPECT_EQ(goal.timestamp_ns, 1'700'000'000'000'000'123ULL);
  EXPECT_EQ(goal.target_pose, Pose2D::make(5.0, 3.0, 0.0));
  EXPECT_EQ(goal.tolerance_position, 0.1);
  EXPECT_EQ(goal.tolerance_angle, 0.05);
  EXPECT_EQ(goal.timeout_seconds, 30.0);
  EXPECT_EQ(goal.priority, 0);
  EXPECT_EQ(goal.goal_id, 0u);
  // Goal's 7 fields, priority and goal_id before timestamp_ns.
  static_assert(horus::reflect::field_count<NavGoal> == 7);
  EXPECT_LT(offsetof(NavGoal, priority), offsetof(NavGoal, timestamp_ns));
  EXPECT_LT(offsetof(NavGoal, goal_id), offsetof(NavGoal, timestamp_ns));
}

TEST(Goal, HasTheRustLayout) {
  static_assert(sizeof(Goal) == 72);
  EXPECT_EQ(offsetof(Goal, priority), 56u);
  EXPECT_EQ(offsetof(Goal, goal_id), 60u);
  EXPECT_EQ(offsetof(Goal, timestamp_ns), 64u);
}

TEST(Goal, MakeSetsPoseAndTolerancesWithPriorityOneAndNoTimeout) {
  const Goal g = Goal::make(Pose2D::make(5.0, 3.0, 0.5), 0.1, 0.05);
  EXPECT_EQ(g.target_pose, Pose2D::make(5.0, 3.0, 0.5));
  EXPECT_EQ(g.tolerance_position, 0.1);
  EXPECT_EQ(g.tolerance_angle, 0.05);
  EXPECT_EQ(g.timeout_seconds, 0.0);
  EXPECT_EQ(g.priority, 1);
  EXPECT_EQ(g.goal_id, 0u);
  EXPECT_EQ(g.timestamp_ns, 0u);
}

TEST(Goal, WithTimeoutAndWithPriorityReturnModifiedCopies) {
  const Goal base = Goal::make(Pose2D::make(1.0, 2.0, 0.0), 0.2, 0.1);
  const Goal g = base.with_timeout(30.0).with_priority(0);
  EXPECT_EQ(g.timeout_seconds, 30.0);
  EXPECT_EQ(g.priority, 0);
  EXPECT_EQ(g.target_pose, base.target_pose);
  EXPECT_EQ(g.tolerance_position, 0.2);
  // The original is untouched.
  EXPECT_EQ(base.timeout_seconds, 0.0);
  EXPECT_EQ(base.priority, 1);
  EXPECT_EQ(base.with_priority(7).priority, 7);
}

TEST(Goal, PositionToleranceCountsExactlyAtTheBoundary) {
  // 0.375 and 0.5 are exact in binary: the distance is exactly 0.625.
  const Goal g = Goal::make(Pose2D::make(1.0, 2.0, 0.0), 0.625, 0.1);
  EXPECT_TRUE(g.is_position_reached(Pose2D::make(1.375, 2.5, 0.0)));
  EXPECT_TRUE(g.is_reached(Pose2D::make(1.375, 2.5, 0.0)));
  EXPECT_FALSE(g.is_position_reached(Pose2D::make(1.375, 2.5 + 1e-9, 0.0)));
  EXPECT_FALSE(g.is_reached(Pose2D::make(1.375 + 1e-9, 2.5, 0.0)));
}

TEST(Goal, HeadingToleranceCountsExactlyAtTheBoundary) {
  const Goal g = Goal::make(Pose2D::make(0.0, 0.0, 0.5), 1.0, 0.25);
  EXPECT_TRUE(g.is_orientation_reached(Pose2D::make(0.0, 0.0, 0.25)));
  EXPECT_TRUE(g.is_orientation_reached(Pose2D::make(0.0, 0.0, 0.75)));
  EXPECT_FALSE(g.is_orientation_reached(Pose2D::make(0.0, 0.0, 0.25 - 1e-9)));
  EXPECT_FALSE(g.is_orientation_reached(Pose2D::make(0.0, 0.0, 0.75 + 1e-9)));
}

TEST(Goal, HeadingDifferenceWrapsAcrossPi) {
  // 3.13 and -3.13 are 2 pi - 6.26 = 0.0232 rad apart, not 6.26.
  const Goal g = Goal::make(Pose2D::make(0.0, 0.0, 3.13), 0.1, 0.05);
  EXPECT_TRUE(g.is_reached(Pose2D::make(0.0, 0.0, -3.13)));
  EXPECT_FALSE(Goal::make(Pose2D::make(0.0, 0.0, 3.13), 0.1, 0.02).is_reached(Pose2D::make(0.0, 0.0, -3.13)));
  // And the other way round.
  EXPECT_TRUE(Goal::make(Pose2D::make(0.0, 0.0, -3.13), 0.1, 0.05).is_reached(Pose2D::make(0.0, 0.0, 3.13)));
  // Exactly opposite headings are pi apart.
  EXPECT_FALSE(Goal::make(Pose2D::make(0.0, 0.0, kPi / 2), 0.1, 3.0).is_reached(Pose2D::make(0.0, 0.0, -kPi / 2)));
  EXPECT_TRUE(Goal::make(Pose2D::make(0.0, 0.0, kPi / 2), 0.1, kPi).is_reached(Pose2D::make(0.0, 0.0, -kPi / 2)));
}

TEST(Goal, HeadingsOfAnySizeAreCompared) {
  const Goal g = Goal::make(Pose2D::make(0.0, 0.0, 0.1), 0.1, 0.01);
  EXPECT_TRUE(g.is_orientation_reached(Pose2D::make(0.0, 0.0, 0.1 + 4 * kPi)));
  EXPECT_TRUE(g.is_orientation_reached(Pose2D::make(0.0, 0.0, 0.1 - 6 * kPi)));
  // 2 pi + 3 is 3 rad from 0 (HORUS's single unwrap would call it reached).
  EXPECT_FALSE(Goal::make(Pose2D::origin(), 0.1, 0.5).is_orientation_reached(Pose2D::make(0.0, 0.0, 2 * kPi + 3.0)));
}

TEST(Goal, IsReachedNeedsBothPositionAndHeading) {
  const Goal g = Goal::make(Pose2D::make(5.0, 3.0, 0.0), 0.2, 0.1);
  EXPECT_TRUE(g.is_reached(Pose2D::make(5.1, 3.05, 0.05)));
  EXPECT_FALSE(g.is_reached(Pose2D::make(5.1, 3.05, 0.5)));  // heading off
  EXPECT_TRUE(g.is_position_reached(Pose2D::make(5.1, 3.05, 0.5)));
  EXPECT_FALSE(g.is_reached(Pose2D::make(6.0, 3.0, 0.0)));   // position off
  EXPECT_TRUE(g.is_orientation_reached(Pose2D::make(6.0, 3.0, 0.0)));
}

TEST(Goal, ZeroToleranceNeedsTheExactPose) {
  const Goal g = Goal::make(Pose2D::make(5.0, 3.0, 1.0), 0.0, 0.0);
  EXPECT_TRUE(g.is_reached(Pose2D::make(5.0, 3.0, 1.0)));
  EXPECT_FALSE(g.is_reached(Pose2D::make(5.0, 3.0 + 1e-12, 1.0)));
}

TEST(Goal, NaNPoseIsNeverReached) {
  const Goal g = Goal::make(Pose2D::make(0.0, 0.0, 0.0), 1e9, 10.0);
  EXPECT_FALSE(g.is_reached(Pose2D::make(kNaN, 0.0, 0.0)));
  EXPECT_FALSE(g.is_reached(Pose2D::make(0.0, 0.0, kNaN)));
  EXPECT_FALSE(g.is_reached(Pose2D::make(kInf, 0.0, 0.0)));
  EXPECT_TRUE(g.is_reached(Pose2D::make(1.0, 1.0, 1.0)));
}

// ===========================================================================
// GoalStatus / GoalResult

TEST(GoalStatus, HasTheHorusValuesAndNames) {
  EXPECT_EQ(static_cast<int>(GoalStatus::Pending), 0);
  EXPECT_EQ(static_cast<int>(GoalStatus::Active), 1);
  EXPECT_EQ(static_cast<int>(GoalStatus::Succeeded), 2);
  EXPECT_EQ(static_cast<int>(GoalStatus::Aborted), 3);
  EXPECT_EQ(static_cast<int>(GoalStatus::Cancelled), 4);
  EXPECT_EQ(static_cast<int>(GoalStatus::Preempted), 5);
  EXPECT_EQ(static_cast<int>(GoalStatus::TimedOut), 6);
  EXPECT_EQ(to_string(GoalStatus::TimedOut), "TimedOut");
  EXPECT_EQ(to_string(GoalStatus::Pending), "Pending");
  EXPECT_EQ(horus::reflect::enum_values<GoalStatus>().size(), 7u);
  static_assert(sizeof(GoalStatus) == 1);
}

TEST(GoalResult, HasTheRustLayout) {
  static_assert(sizeof(GoalResult) == 104);
  static_assert(std::tuple_size_v<decltype(GoalResult::error_message)> == 64);
  EXPECT_EQ(offsetof(GoalResult, error_message), 28u);
  EXPECT_EQ(offsetof(GoalResult, timestamp_ns), 96u);
}

TEST(GoalResult, MakeStoresTheStatusAsAByte) {
  const GoalResult r = GoalResult::make(42, GoalStatus::Aborted);
  EXPECT_EQ(r.goal_id, 42u);
  EXPECT_EQ(r.status, 3);
  EXPECT_EQ(r.status_enum(), GoalStatus::Aborted);
  EXPECT_EQ(GoalResult{}.status_enum(), GoalStatus::Pending);
}

TEST(GoalResult, TypedStatusAccessorsRoundTrip) {
  GoalResult r{};
  r.set_status(GoalStatus::Preempted);
  EXPECT_EQ(r.status, 5);
  EXPECT_EQ(r.status_enum(), GoalStatus::Preempted);
  r.status = 200;  // from a newer or broken sender
  EXPECT_EQ(to_string(r.status_enum()), "");
}

TEST(GoalResult, ErrorMessageUpTo63CharactersFits) {
  GoalResult r = GoalResult::make(1, GoalStatus::Aborted);
  EXPECT_TRUE(r.set_error_message("Obstacle detected"));
  EXPECT_EQ(r.error_message_str(), "Obstacle detected");
  const std::string max(63, 'x');
  EXPECT_TRUE(r.set_error_message(max));
  EXPECT_EQ(r.error_message_str(), max);
}

TEST(GoalResult, ErrorMessageThatDoesNotFitIsRefusedUnchanged) {
  GoalResult r{};
  ASSERT_TRUE(r.set_error_message("blocked"));
  EXPECT_FALSE(r.set_error_message(std::string(64, 'y')));
  EXPECT_FALSE(r.set_error_message(std::string_view("nul\0inside", 10)));
  EXPECT_EQ(r.error_message_str(), "blocked");
  EXPECT_TRUE(r.set_error_message(""));
  EXPECT_EQ(r.error_message_str(), "");
}

// ===========================================================================
// Waypoint

TEST(Waypoint, HasTheRustLayout) { static_assert(sizeof(Waypoint) == 104); }

TEST(Waypoint, MakeHasZeroVelocityAndNoStop) {
  const Waypoint w = Waypoint::make(Pose2D::make(1.0, 2.0, 0.5));
  EXPECT_EQ(w.pose, Pose2D::make(1.0, 2.0, 0.5));
  EXPECT_EQ(w.velocity, Twist{});
  EXPECT_EQ(w.time_from_start, 0.0);
  EXPECT_EQ(w.curvature, 0.0f);
  EXPECT_EQ(w.stop_required, 0);
}

TEST(Waypoint, WithVelocitySetsTheDesiredTwist) {
  const Waypoint w = Waypoint::make(Pose2D::origin()).with_velocity(Twist::new_2d(0.5, 0.1));
  EXPECT_EQ(w.velocity.linear[0], 0.5);
  EXPECT_EQ(w.velocity.angular[2], 0.1);
  EXPECT_EQ(w.stop_required, 0);
}

TEST(Waypoint, WithStopRequiresAStopAndZeroesTheVelocity) {
  const Waypoint moving = Waypoint::make(Pose2D::make(1.0, 2.0, 0.0)).with_velocity(Twist::new_2d(0.5, 0.0));
  const Waypoint w = moving.with_stop();
  EXPECT_EQ(w.stop_required, 1);
  EXPECT_EQ(w.velocity, Twist::stop());
  EXPECT_EQ(w.pose, moving.pose);
  EXPECT_EQ(moving.stop_required, 0);  // copy, not in place
}

TEST(Waypoint, XYThetaReadThePose) {
  constexpr Waypoint w = Waypoint::make(Pose2D::make(1.5, -2.25, 0.75));
  static_assert(w.x() == 1.5 && w.y() == -2.25 && w.theta() == 0.75);
  EXPECT_EQ(w.x(), 1.5);
  EXPECT_EQ(w.y(), -2.25);
  EXPECT_EQ(w.theta(), 0.75);
  Waypoint moved = w;
  moved.pose.x = 4.0;
  EXPECT_EQ(moved.x(), 4.0);
  EXPECT_EQ(Waypoint{}.x(), 0.0);
}

TEST(Waypoint, SpeedIsTheMagnitudeOfTheLinearVelocity) {
  const Waypoint w = Waypoint::make(Pose2D::origin());
  EXPECT_EQ(w.speed(), 0.0);
  EXPECT_EQ(w.with_velocity(Twist::new_2d(0.5, 1.0)).speed(), 0.5);      // angular part ignored
  EXPECT_EQ(w.with_velocity(Twist::new_2d(-0.75, 0.0)).speed(), 0.75);   // reversing: still a speed
  EXPECT_DOUBLE_EQ(w.with_velocity(Twist::make({3.0, 4.0, 0.0}, {})).speed(), 5.0);
  EXPECT_DOUBLE_EQ(w.with_velocity(Twist::make({2.0, 3.0, 6.0}, {})).speed(), 7.0);
  EXPECT_EQ(w.with_velocity(Twist::make({0.0, 0.0, 0.0}, {0.0, 0.0, 2.0})).speed(), 0.0);
  EXPECT_TRUE(std::isnan(w.with_velocity(Twist::make({kNaN, 0.0, 0.0}, {})).speed()));
  EXPECT_EQ(w.with_velocity(Twist::make({0.0, -kInf, 0.0}, {})).speed(), kInf);
  EXPECT_EQ(w.with_velocity(Twist::make({kNaN, 0.0, kInf}, {})).speed(), kInf);
  EXPECT_DOUBLE_EQ(w.with_velocity(Twist::make({3e200, 4e200, 0.0}, {})).speed(), 5e200);  // no overflow
  EXPECT_EQ(w.with_velocity(Twist::new_2d(0.5, 0.0)).with_stop().speed(), 0.0);
}

TEST(Waypoint, NavPathPageExampleReadsPositionHeadingAndSpeed) {
  NavPath path{};
  ASSERT_TRUE(path.add_waypoint(Waypoint::make(Pose2D::make(1.0, 2.0, 0.5)).with_velocity(Twist::new_2d(0.8, 0.1))));
  ASSERT_TRUE(path.add_waypoint(Waypoint::make(Pose2D::make(3.0, 2.0, 0.0)).with_stop()));
  std::vector<std::array<double, 4>> seen;
  for (std::size_t i = 0; i < path.waypoint_count; ++i) {
    const Waypoint& wp = path.waypoints[i];
    seen.push_back({wp.x(), wp.y(), wp.theta(), wp.speed()});
  }
  EXPECT_EQ(seen, (std::vector<std::array<double, 4>>{{1.0, 2.0, 0.5, 0.8}, {3.0, 2.0, 0.0, 0.0}}));
}

// ===========================================================================
// Path and NavPath (same behaviour, different time-field name)

template <class P>
class AnyPath : public ::testing::Test {};
using PathTypes = ::testing::Types<Path, NavPath>;
TYPED_TEST_SUITE(AnyPath, PathTypes);

TYPED_TEST(AnyPath, Holds256WaypointsInTheRustLayout) {
  static_assert(TypeParam::kMaxWaypoints == 256);
  static_assert(std::tuple_size_v<decltype(TypeParam::waypoints)> == 256);
  static_assert(sizeof(TypeParam) == 26720);
  EXPECT_EQ(offsetof(TypeParam, waypoint_count), 26624u);
  EXPECT_EQ(offsetof(TypeParam, timestamp_ns), 26712u);
}

TYPED_TEST(AnyPath, AddWaypointAccumulatesTheLength) {
  TypeParam p = TypeParam::make();
  EXPECT_TRUE(p.is_empty());
  EXPECT_TRUE(p.add_waypoint(Waypoint::make(Pose2D::make(0.0, 0.0, 0.0))));
  EXPECT_EQ(p.total_length, 0.0);
  EXPECT_TRUE(p.add_waypoint(Waypoint::make(Pose2D::make(3.0, 0.0, 0.0))));
  EXPECT_TRUE(p.add_waypoint(Waypoint::make(Pose2D::make(3.0, 4.0, 0.0))));
  EXPECT_EQ(p.waypoint_count, 3);
  EXPECT_DOUBLE_EQ(p.total_length, 7.0);
  EXPECT_DOUBLE_EQ(p.compute_length(), 7.0);
  ASSERT_EQ(p.valid_waypoints().size(), 3u);
  EXPECT_EQ(p.valid_waypoints()[2].pose.y, 4.0);
}

TYPED_TEST(AnyPath, ComputeLengthFollowsEditedWaypoints) {
  TypeParam p{};
  p.add_waypoint(Waypoint::make(Pose2D::make(0.0, 0.0, 0.0)));
  p.add_waypoint(Waypoint::make(Pose2D::make(1.0, 0.0, 0.0)));
  p.waypoints[1].pose.x = 2.5;
  EXPECT_DOUBLE_EQ(p.total_length, 1.0);  // only add_waypoint keeps it
  EXPECT_DOUBLE_EQ(p.compute_length(), 2.5);
  EXPECT_EQ(TypeParam{}.compute_length(), 0.0);
}

TYPED_TEST(AnyPath, IsFullAt256AndRefusesThe257thUnchanged) {
  TypeParam p{};
  for (int i = 0; i < 256; ++i)
    ASSERT_TRUE(p.add_waypoint(Waypoint::make(Pose2D::make(static_cast<double>(i), 0.0, 0.0)))) << i;
  EXPECT_TRUE(p.is_full());
  EXPECT_EQ(p.waypoint_count, 256);
  EXPECT_DOUBLE_EQ(p.total_length, 255.0);
  const TypeParam before = p;
  EXPECT_FALSE(p.add_waypoint(Waypoint::make(Pose2D::make(256.0, 0.0, 0.0))));
  EXPECT_EQ(p, before);
  EXPECT_EQ(p.valid_waypoints().size(), 256u);
}

TYPED_TEST(AnyPath, CorruptCountIsClampedTo256) {
  TypeParam p{};
  p.waypoint_count = 1000;
  EXPECT_EQ(p.count(), 256u);
  EXPECT_EQ(p.valid_waypoints().size(), 256u);
  EXPECT_FALSE(p.add_waypoint(Waypoint{}));
}

TYPED_TEST(AnyPath, ClearEmptiesThePathButKeepsItsNames) {
  TypeParam p{};
  ASSERT_TRUE(p.set_frame_id("map"));
  ASSERT_TRUE(p.set_algorithm("a_star"));
  p.timestamp_ns = 5;
  p.add_waypoint(Waypoint::make(Pose2D::make(0.0, 0.0, 0.0)));
  p.add_waypoint(Waypoint::make(Pose2D::make(0.0, 2.0, 0.0)));
  p.clear();
  EXPECT_TRUE(p.is_empty());
  EXPECT_EQ(p.total_length, 0.0);
  EXPECT_EQ(p.waypoints[1], Waypoint{});
  EXPECT_EQ(p.frame_id_str(), "map");
  EXPECT_EQ(p.algorithm_str(), "a_star");
  EXPECT_EQ(p.timestamp_ns, 5u);
  EXPECT_TRUE(p.add_waypoint(Waypoint::make(Pose2D::make(9.0, 9.0, 0.0))));
  EXPECT_EQ(p.total_length, 0.0);
}

TYPED_TEST(AnyPath, ClosestWaypointAndProgress) {
  TypeParam p{};
  EXPECT_EQ(p.closest_waypoint_index(Pose2D::origin()), std::nullopt);
  EXPECT_EQ(p.calculate_progress(Pose2D::origin()), 0.0f);
  for (int i = 0; i < 10; ++i) p.add_waypoint(Waypoint::make(Pose2D::make(10.0 * i, 0.0, 0.0)));
  EXPECT_EQ(p.closest_waypoint_index(Pose2D::make(9.0, 0.0, 0.0)), 1u);
  EXPECT_EQ(p.closest_waypoint_index(Pose2D::make(1000.0, 5.0, 0.0)), 9u);
  EXPECT_FLOAT_EQ(p.calculate_progress(Pose2D::make(50.0, 1.0, 0.0)), 0.5f);
  EXPECT_FLOAT_EQ(p.calculate_progress(Pose2D::make(90.0, 0.0, 0.0)), 0.9f);
}

TYPED_TEST(AnyPath, TextFieldsRefuseNamesThatDoNotFit) {
  TypeParam p{};
  EXPECT_TRUE(p.set_frame_id(std::string(31, 'f')));
  EXPECT_FALSE(p.set_frame_id(std::string(32, 'g')));
  EXPECT_EQ(p.frame_id_str(), std::string(31, 'f'));
  EXPECT_TRUE(p.set_algorithm("rrt_star"));
  EXPECT_FALSE(p.set_algorithm(std::string(40, 'h')));
  EXPECT_EQ(p.algorithm_str(), "rrt_star");
}

TEST(Path, LogSummaryGivesCountAndLength) {
  Path p = Path::make();
  for (int i = 0; i < 42; ++i) p.add_waypoint(Waypoint::make(Pose2D::make(0.3 * i, 0.0, 0.0)));
  EXPECT_EQ(p.log_summary(), "Path(42 waypoints, 12.3 m)");
  EXPECT_EQ(horus::log_summary(p), "Path(42 waypoints, 12.3 m)");
  EXPECT_EQ(Path{}.log_summary(), "Path(0 waypoints, 0.0 m)");
}

TEST(NavPath, LogSummaryGivesCountAndLength) {
  NavPath p{};
  p.add_waypoint(Waypoint::make(Pose2D::make(0.0, 0.0, 0.0)));
  p.add_waypoint(Waypoint::make(Pose2D::make(3.0, 4.0, 0.0)));
  EXPECT_EQ(p.log_summary(), "NavPath(2 waypoints, 5.0 m)");
}

TEST(NavPath, DiffersFromPathOnlyByTheTimeFieldName) {
  static_assert(!std::is_same_v<NavPath, Path>);
  EXPECT_EQ(offsetof(NavPath, estimated_time), offsetof(Path, duration_seconds));
  EXPECT_NE(horus::type_hash<NavPath>, horus::type_hash<Path>);
  EXPECT_NE(horus::reflect::type_signature<NavPath>().find("f64 estimated_time;"), std::string::npos);
  EXPECT_NE(horus::reflect::type_signature<Path>().find("f64 duration_seconds;"), std::string::npos);
}

// ===========================================================================
// PathPlan

TEST(PathPlan, Holds768FloatsInTheRustLayout) {
  static_assert(std::tuple_size_v<decltype(PathPlan::waypoint_data)> == 768);
  static_assert(std::tuple_size_v<decltype(PathPlan::goal_pose)> == 3);
  static_assert(sizeof(PathPlan) == 3096);
  EXPECT_EQ(offsetof(PathPlan, waypoint_count), 3084u);
}

TEST(PathPlan, PacksWaypointsAsXYThetaTriples) {
  PathPlan plan = PathPlan::make();
  EXPECT_TRUE(plan.is_empty());
  EXPECT_TRUE(plan.add_waypoint(1.0f, 2.0f, 3.0f));
  EXPECT_TRUE(plan.add_waypoint(4.0f, 5.0f, 6.0f));
  EXPECT_EQ(plan.waypoint_count, 2);
  const std::array<float, 7> expected{1.0f, 2.0f, 3.0f, 4.0f, 5.0f, 6.0f, 0.0f};
  for (std::size_t i = 0; i < expected.size(); ++i) EXPECT_EQ(plan.waypoint_data[i], expected[i]) << i;
  EXPECT_EQ(plan.waypoint(0), (std::array<float, 3>{1.0f, 2.0f, 3.0f}));
  EXPECT_EQ(plan.waypoint(1), (std::array<float, 3>{4.0f, 5.0f, 6.0f}));
  EXPECT_EQ(plan.waypoint(2), std::nullopt);
  EXPECT_EQ(PathPlan{}.waypoint(0), std::nullopt);
}

TEST(PathPlan, IsFullAt256AndRefusesThe257thUnchanged) {
  PathPlan plan{};
  for (int i = 0; i < 256; ++i) ASSERT_TRUE(plan.add_waypoint(static_cast<float>(i), 1.0f, 2.0f)) << i;
  const PathPlan before = plan;
  EXPECT_FALSE(plan.add_waypoint(256.0f, 0.0f, 0.0f));
  EXPECT_EQ(plan, before);
  EXPECT_EQ(plan.waypoint(255), (std::array<float, 3>{255.0f, 1.0f, 2.0f}));
  EXPECT_EQ(plan.waypoint_data[767], 2.0f);
  EXPECT_EQ(plan.waypoint(256), std::nullopt);
}

TEST(PathPlan, FromWaypointsKeepsTheFirst256AndTheGoal) {
  const std::vector<std::array<float, 3>> three{{0.0f, 0.0f, 0.0f}, {1.0f, 0.0f, 0.0f}, {2.0f, 1.0f, 0.5f}};
  const PathPlan plan = PathPlan::from_waypoints(three, {5.0f, 5.0f, 1.57f});
  EXPECT_EQ(plan.waypoint_count, 3);
  EXPECT_EQ(plan.goal_pose, (std::array<float, 3>{5.0f, 5.0f, 1.57f}));
  EXPECT_EQ(plan.waypoint(2), (std::array<float, 3>{2.0f, 1.0f, 0.5f}));

  std::vector<std::array<float, 3>> many(300);
  for (std::size_t i = 0; i < many.size(); ++i) many[i] = {static_cast<float>(i), 0.0f, 0.0f};
  const PathPlan clipped = PathPlan::from_waypoints(many, {});
  EXPECT_EQ(clipped.waypoint_count, 256);
  EXPECT_EQ(clipped.waypoint(255), (std::array<float, 3>{255.0f, 0.0f, 0.0f}));
}

TEST(PathPlan, LogSummaryGivesCountAndGoal) {
  PathPlan plan{};
  plan.add_waypoint(0.0f, 0.0f, 0.0f);
  plan.goal_pose = {5.0f, 3.0f, 0.5f};
  EXPECT_EQ(plan.log_summary(), "PathPlan(1 waypoints, goal (5.00, 3.00, 0.50))");
}

}  // namespace
