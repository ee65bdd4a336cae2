// Unit tests of the navigation messages (horus/msg/navigation.hpp): goal
// tolerances, paths, compact plans, occupancy grids, cost maps, velocity
// obstacles, layout guarantees, printing and JSON round trips.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <limits>
#include <numbers>
#include <ostream>
#include <string>
#include <type_traits>
#include <vector>

#include <fmt/format.h>

#include "horus/format.hpp"
#include "horus/json.hpp"
#include "horus/messages.hpp"
#include "message_test_support.hpp"

namespace {

using namespace horus_test::values;

using namespace horus::msg;

using Cell = std::pair<std::uint32_t, std::uint32_t>;

// A grid whose cells are all known free (0).
OccupancyGrid free_grid(std::uint32_t w, std::uint32_t h, float res, const Pose2D& origin = Pose2D::origin()) {
  OccupancyGrid g = OccupancyGrid::make(w, h, res, origin);
  std::fill(g.data.begin(), g.data.end(), std::int8_t{0});
  return g;
}

std::uint8_t cost_at(const CostMap& m, std::uint32_t gx, std::uint32_t gy) {
  return m.costs.at(static_cast<std::size_t>(gy) * m.occupancy_grid.width + gx);
}

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

// ===========================================================================
// OccupancyGrid

TEST(OccupancyGrid, MakeFillsEveryCellWithUnknown) {
  const OccupancyGrid g = OccupancyGrid::make(4, 3, 0.1f, Pose2D::origin());
  EXPECT_EQ(g.width, 4u);
  EXPECT_EQ(g.height, 3u);
  EXPECT_EQ(g.resolution, 0.1f);
  ASSERT_EQ(g.data.size(), 12u);
  for (std::int8_t v : g.data) EXPECT_EQ(v, -1);
  EXPECT_EQ(g.occupancy(3, 2), std::optional<std::int8_t>(-1));
  EXPECT_TRUE(OccupancyGrid::make(0, 0, 0.1f, Pose2D::origin()).data.empty());
}

TEST(OccupancyGrid, DefaultResolutionIsFiveCentimetres) { EXPECT_EQ(OccupancyGrid{}.resolution, 0.05f); }

TEST(OccupancyGrid, WorldToGridPutsCellBoundariesInTheUpperCell) {
  const OccupancyGrid g = OccupancyGrid::make(100, 100, 0.1f, Pose2D::origin());
  // 0.5 / 0.1f is 4.99999993: the 1e-6 cell epsilon gives cell 5.
  EXPECT_EQ(g.world_to_grid(0.5, 0.5), (Cell{5, 5}));
  EXPECT_EQ(g.world_to_grid(0.0, 0.0), (Cell{0, 0}));
  EXPECT_EQ(g.world_to_grid(0.449, 0.05), (Cell{4, 0}));
  EXPECT_EQ(g.world_to_grid(9.95, 0.0), (Cell{99, 0}));
}

TEST(OccupancyGrid, NegativeWorldCoordinatesAreOutsideAGridAtTheOrigin) {
  const OccupancyGrid g = OccupancyGrid::make(10, 10, 0.25f, Pose2D::origin());
  EXPECT_EQ(g.world_to_grid(-0.01, 0.5), std::nullopt);
  EXPECT_EQ(g.world_to_grid(0.5, -0.01), std::nullopt);
  EXPECT_EQ(g.world_to_grid(-100.0, -100.0), std::nullopt);
  EXPECT_EQ(g.world_to_grid(0.01, 0.01), (Cell{0, 0}));
}

TEST(OccupancyGrid, ExactlyAtTheWidthOrHeightEdgeIsOutside) {
  const OccupancyGrid g = OccupancyGrid::make(10, 8, 0.25f, Pose2D::origin());
  EXPECT_EQ(g.world_to_grid(2.5, 1.0), std::nullopt);  // x = width * resolution
  EXPECT_EQ(g.world_to_grid(2.4999, 1.0), (Cell{9, 4}));
  EXPECT_EQ(g.world_to_grid(1.0, 2.0), std::nullopt);  // y = height * resolution
  EXPECT_EQ(g.world_to_grid(1.0, 1.9999), (Cell{4, 7}));
}

TEST(OccupancyGrid, OriginOffsetShiftsTheCells) {
  const OccupancyGrid g = OccupancyGrid::make(10, 10, 0.25f, Pose2D::make(-1.0, -2.0, 0.0));
  EXPECT_EQ(g.world_to_grid(-1.0, -2.0), (Cell{0, 0}));
  EXPECT_EQ(g.world_to_grid(0.0, 0.0), (Cell{4, 8}));
  EXPECT_EQ(g.world_to_grid(-0.5, -1.5), (Cell{2, 2}));
  EXPECT_EQ(g.world_to_grid(-1.01, -2.0), std::nullopt);
  EXPECT_EQ(g.world_to_grid(1.5, 0.0), std::nullopt);  // -1 + 10 * 0.25
  EXPECT_EQ(g.world_to_grid(0.0, 0.5), std::nullopt);  // -2 + 10 * 0.25
  EXPECT_EQ(g.grid_to_world(0, 0), (std::pair{-0.875, -1.875}));
}

TEST(OccupancyGrid, OriginRotationIsIgnoredAsInHorus) {
  const OccupancyGrid straight = OccupancyGrid::make(10, 10, 0.25f, Pose2D::make(1.0, 1.0, 0.0));
  const OccupancyGrid turned = OccupancyGrid::make(10, 10, 0.25f, Pose2D::make(1.0, 1.0, kPi / 2));
  for (double x : {1.1, 2.0, 3.3})
    for (double y : {1.2, 2.6})
      EXPECT_EQ(turned.world_to_grid(x, y), straight.world_to_grid(x, y)) << x << ", " << y;
  EXPECT_EQ(turned.grid_to_world(3, 4), straight.grid_to_world(3, 4));
}

TEST(OccupancyGrid, NonFiniteCoordinatesAndBadResolutionGiveNoCell) {
  OccupancyGrid g = OccupancyGrid::make(10, 10, 0.25f, Pose2D::origin());
  EXPECT_EQ(g.world_to_grid(kNaN, 0.5), std::nullopt);
  EXPECT_EQ(g.world_to_grid(0.5, kInf), std::nullopt);
  EXPECT_EQ(g.world_to_grid(-kInf, 0.5), std::nullopt);
  EXPECT_EQ(g.world_to_grid(1e300, 0.5), std::nullopt);
  g.resolution = 0.0f;
  EXPECT_EQ(g.world_to_grid(0.0, 0.0), std::nullopt);
  g.resolution = -0.25f;
  EXPECT_EQ(g.world_to_grid(-0.5, -0.5), std::nullopt);
  g.resolution = std::numeric_limits<float>::quiet_NaN();
  EXPECT_EQ(g.world_to_grid(0.0, 0.0), std::nullopt);
}

TEST(OccupancyGrid, GridToWorldGivesCellCentresAndRoundTrips) {
  const OccupancyGrid g = OccupancyGrid::make(10, 6, 0.25f, Pose2D::make(2.0, -1.0, 0.0));
  EXPECT_EQ(g.grid_to_world(0, 0), (std::pair{2.125, -0.875}));
  EXPECT_EQ(g.grid_to_world(9, 5), (std::pair{4.375, 0.375}));
  EXPECT_EQ(g.grid_to_world(10, 0), std::nullopt);
  EXPECT_EQ(g.grid_to_world(0, 6), std::nullopt);
  for (std::uint32_t gx = 0; gx < 10; ++gx)
    for (std::uint32_t gy = 0; gy < 6; ++gy) {
      const auto w = g.grid_to_world(gx, gy);
      ASSERT_TRUE(w);
      EXPECT_EQ(g.world_to_grid(w->first, w->second), (Cell{gx, gy}));
    }
}

TEST(OccupancyGrid, SetOccupancyStoresValuesFromMinusOneTo100) {
  OccupancyGrid g = OccupancyGrid::make(5, 4, 0.1f, Pose2D::origin());
  EXPECT_TRUE(g.set_occupancy(4, 3, 100));
  EXPECT_TRUE(g.set_occupancy(0, 0, 0));
  EXPECT_TRUE(g.set_occupancy(2, 1, 37));
  EXPECT_EQ(g.occupancy(4, 3), std::optional<std::int8_t>(100));
  EXPECT_EQ(g.occupancy(0, 0), std::optional<std::int8_t>(0));
  EXPECT_EQ(g.data[1 * 5 + 2], 37);  // row-major: gy * width + gx
  EXPECT_TRUE(g.set_occupancy(4, 3, -1));
  EXPECT_EQ(g.occupancy(4, 3), std::optional<std::int8_t>(-1));
}

TEST(OccupancyGrid, SetOccupancyRejectsOutOfRangeValuesUnchanged) {
  OccupancyGrid g = OccupancyGrid::make(5, 5, 0.1f, Pose2D::origin());
  ASSERT_TRUE(g.set_occupancy(2, 2, 40));
  for (std::int8_t bad : {std::int8_t{101}, std::int8_t{127}, std::int8_t{-2}, std::int8_t{-128}}) {
    EXPECT_FALSE(g.set_occupancy(2, 2, bad)) << static_cast<int>(bad);
    EXPECT_EQ(g.occupancy(2, 2), std::optional<std::int8_t>(40));
  }
}

TEST(OccupancyGrid, CellsOutsideTheGridAreRefused) {
  OccupancyGrid g = OccupancyGrid::make(5, 4, 0.1f, Pose2D::origin());
  const auto before = g.data;
  EXPECT_FALSE(g.set_occupancy(5, 0, 100));
  EXPECT_FALSE(g.set_occupancy(0, 4, 100));
  EXPECT_EQ(g.data, before);
  EXPECT_EQ(g.occupancy(5, 0), std::nullopt);
  EXPECT_EQ(g.occupancy(0, 4), std::nullopt);
  EXPECT_EQ(g.occupancy(100, 100), std::nullopt);
  // A malformed message with fewer cells than width * height.
  g.data.resize(10);
  EXPECT_EQ(g.occupancy(4, 3), std::nullopt);
  EXPECT_FALSE(g.set_occupancy(4, 3, 0));
  EXPECT_EQ(g.occupancy(4, 1), std::optional<std::int8_t>(-1));
}

TEST(OccupancyGrid, FreeBelow50OccupiedFrom50AndUnknownIsNeither) {
  OccupancyGrid g = OccupancyGrid::make(10, 10, 0.1f, Pose2D::make(-0.5, -0.5, 0.0));
  const auto centre = [&](std::uint32_t gx, std::uint32_t gy) { return *g.grid_to_world(gx, gy); };
  g.set_occupancy(1, 1, 0);
  g.set_occupancy(2, 2, 49);
  g.set_occupancy(3, 3, 50);
  g.set_occupancy(4, 4, 100);
  const auto [x1, y1] = centre(1, 1);
  const auto [x2, y2] = centre(2, 2);
  const auto [x3, y3] = centre(3, 3);
  const auto [x4, y4] = centre(4, 4);
  const auto [x5, y5] = centre(5, 5);  // still unknown
  EXPECT_TRUE(g.is_free(x1, y1));
  EXPECT_FALSE(g.is_occupied(x1, y1));
  EXPECT_TRUE(g.is_free(x2, y2));
  EXPECT_FALSE(g.is_occupied(x2, y2));
  EXPECT_FALSE(g.is_free(x3, y3));
  EXPECT_TRUE(g.is_occupied(x3, y3));
  EXPECT_FALSE(g.is_free(x4, y4));
  EXPECT_TRUE(g.is_occupied(x4, y4));
  EXPECT_FALSE(g.is_free(x5, y5));
  EXPECT_FALSE(g.is_occupied(x5, y5));
  // Outside the grid: neither.
  EXPECT_FALSE(g.is_free(-0.6, 0.0));
  EXPECT_FALSE(g.is_occupied(-0.6, 0.0));
  EXPECT_FALSE(g.is_free(kNaN, 0.0));
}

TEST(OccupancyGrid, LogSummaryGivesSizeResolutionAndCells) {
  const OccupancyGrid g = OccupancyGrid::make(200, 200, 0.05f, Pose2D::origin());
  EXPECT_EQ(g.log_summary(), "OccupancyGrid(200x200 @ 0.05 m, 40000 cells)");
  EXPECT_EQ(horus::log_summary(g), g.log_summary());
}

// ===========================================================================
// CostMap

TEST(CostMap, DefaultsAreTheHorusOnes) {
  const CostMap m{};
  EXPECT_EQ(m.inflation_radius, 0.55f);
  EXPECT_EQ(m.cost_scaling_factor, 10.0f);
  EXPECT_EQ(m.lethal_cost, 253);
  EXPECT_EQ(CostMap::COST_LETHAL, 253);
  EXPECT_EQ(CostMap::COST_UNKNOWN, 255);
  EXPECT_EQ(CostMap::COST_FREE, 0);
}

TEST(CostMap, BaseCostsFollowOccupancy) {
  OccupancyGrid g = free_grid(5, 1, 1.0f);
  g.set_occupancy(0, 0, 30);
  g.set_occupancy(1, 0, 64);
  g.set_occupancy(2, 0, 65);
  g.set_occupancy(3, 0, -1);
  const CostMap m = CostMap::from_occupancy_grid(g, 0.0f);  // no inflation
  EXPECT_EQ(m.costs, (std::vector<std::uint8_t>{60, 128, 253, 255, 0}));
}

TEST(CostMap, OccupiedCellIsLethalAndUnknownStays255) {
  OccupancyGrid g = free_grid(11, 11, 0.05f);
  g.set_occupancy(5, 5, 100);
  g.set_occupancy(0, 10, -1);
  const CostMap m = CostMap::from_occupancy_grid(g, 0.2f);
  ASSERT_EQ(m.costs.size(), 121u);
  EXPECT_EQ(cost_at(m, 5, 5), 253);
  EXPECT_EQ(cost_at(m, 0, 10), 255);
  EXPECT_EQ(m.occupancy_grid, g);
}

TEST(CostMap, InflationCostFollowsTheHorusPowerLaw) {
  // 252 * (1 - d / R)^10 with d = 0.05 m, R = 0.55 m: 252 * 0.3855 = 97.2 -> 97.
  OccupancyGrid g = free_grid(30, 30, 0.05f);
  g.set_occupancy(15, 15, 100);
  const CostMap m = CostMap::from_occupancy_grid(g, 0.55f);
  EXPECT_EQ(cost_at(m, 14, 15), 97);
  EXPECT_EQ(cost_at(m, 15, 16), 97);
  EXPECT_EQ(cost_at(m, 13, 15), 33);
  EXPECT_EQ(cost_at(m, 15, 25), 0);  // 0.5 m: (1/11)^10 * 252 < 1
}

TEST(CostMap, InflationReachesCellsJustInsideTheRadiusButNotJustOutside) {
  // Linear decay (scaling factor 1): 252 * (1 - d / 1.1), cells 0.25 m apart.
  OccupancyGrid g = free_grid(11, 11, 0.25f);
  g.set_occupancy(5, 5, 100);
  CostMap m = CostMap::from_occupancy_grid(g, 1.1f);
  m.cost_scaling_factor = 1.0f;
  m.compute_costs();
  EXPECT_EQ(cost_at(m, 5, 5), 253);
  EXPECT_EQ(cost_at(m, 4, 5), 194);  // d = 0.25
  EXPECT_EQ(cost_at(m, 3, 5), 137);  // d = 0.5
  EXPECT_EQ(cost_at(m, 2, 5), 80);   // d = 0.75
  EXPECT_EQ(cost_at(m, 1, 5), 22);   // d = 1.0, just inside 1.1
  EXPECT_EQ(cost_at(m, 0, 5), 0);    // d = 1.25, just outside
  EXPECT_EQ(cost_at(m, 5, 9), 22);
  EXPECT_EQ(cost_at(m, 5, 10), 0);
  EXPECT_EQ(cost_at(m, 9, 9), 0);    // d = 1.41 on the diagonal
  // Widening the radius past 1.25 m reaches the next cell.
  m.inflation_radius = 1.3f;
  m.compute_costs();
  EXPECT_GT(cost_at(m, 0, 5), 0);
}

TEST(CostMap, CostDecreasesWithDistanceFromTheObstacle) {
  OccupancyGrid g = free_grid(21, 21, 0.1f);
  g.set_occupancy(10, 10, 100);
  CostMap m = CostMap::from_occupancy_grid(g, 0.8f);
  m.cost_scaling_factor = 2.0f;
  m.compute_costs();
  for (std::uint32_t x = 11; x < 18; ++x) EXPECT_GT(cost_at(m, x, 10), cost_at(m, x + 1, 10)) << x;
  for (std::uint32_t x = 18; x < 21; ++x) EXPECT_EQ(cost_at(m, x, 10), 0) << x;
  // The diagonal neighbour (0.141 m) lies between the 0.1 m and 0.2 m cells.
  EXPECT_LT(cost_at(m, 11, 11), cost_at(m, 11, 10));
  EXPECT_GT(cost_at(m, 11, 11), cost_at(m, 12, 10));
  // Nothing inflated reaches the lethal cost.
  for (std::size_t i = 0; i < m.costs.size(); ++i) {
    if (i != 10 * 21 + 10) {
      EXPECT_LT(m.costs[i], 253) << i;
    }
  }
}

TEST(CostMap, NearestObstacleWins) {
  OccupancyGrid g = free_grid(21, 1, 0.1f);
  g.set_occupancy(0, 0, 100);
  g.set_occupancy(20, 0, 100);
  CostMap m = CostMap::from_occupancy_grid(g, 0.5f);
  m.cost_scaling_factor = 1.0f;
  m.compute_costs();
  EXPECT_EQ(cost_at(m, 1, 0), cost_at(m, 19, 0));
  EXPECT_GT(cost_at(m, 18, 0), cost_at(m, 17, 0));
  EXPECT_EQ(cost_at(m, 10, 0), 0);
}

TEST(CostMap, InflationKeepsAHigherBaseCost) {
  OccupancyGrid g = free_grid(11, 1, 0.25f);
  g.set_occupancy(0, 0, 100);
  g.set_occupancy(4, 0, 60);  // base 120, inflation at 1.0 m of 1.1 m is 22
  CostMap m = CostMap::from_occupancy_grid(g, 1.1f);
  m.cost_scaling_factor = 1.0f;
  m.compute_costs();
  EXPECT_EQ(cost_at(m, 4, 0), 120);
  EXPECT_EQ(cost_at(m, 1, 0), 194);
}

TEST(CostMap, UnknownCellsInflateLikeObstaclesAsInHorus) {
  OccupancyGrid g = OccupancyGrid::make(5, 1, 0.25f, Pose2D::origin());  // all unknown
  g.set_occupancy(3, 0, 0);
  g.set_occupancy(4, 0, 0);
  CostMap m = CostMap::from_occupancy_grid(g, 1.1f);
  m.cost_scaling_factor = 1.0f;
  m.compute_costs();
  EXPECT_EQ(cost_at(m, 2, 0), 255);
  EXPECT_EQ(cost_at(m, 3, 0), 194);
  EXPECT_EQ(cost_at(m, 4, 0), 137);
}

TEST(CostMap, ZeroRadiusOrBadResolutionMeansNoInflation) {
  OccupancyGrid g = free_grid(5, 5, 0.1f);
  g.set_occupancy(2, 2, 100);
  const CostMap none = CostMap::from_occupancy_grid(g, 0.0f);
  EXPECT_EQ(cost_at(none, 1, 2), 0);
  EXPECT_EQ(cost_at(none, 2, 2), 253);
  const CostMap negative = CostMap::from_occupancy_grid(g, -1.0f);
  EXPECT_EQ(cost_at(negative, 1, 2), 0);
  g.resolution = 0.0f;
  const CostMap flat = CostMap::from_occupancy_grid(g, 0.5f);
  EXPECT_EQ(cost_at(flat, 1, 2), 0);
  EXPECT_EQ(cost_at(flat, 2, 2), 253);
}

TEST(CostMap, CostTakesWorldCoordinates) {
  OccupancyGrid g = free_grid(10, 10, 0.25f, Pose2D::make(-1.0, -1.0, 0.0));
  g.set_occupancy(4, 4, 100);  // world [0, 0.25) x [0, 0.25)
  const CostMap m = CostMap::from_occupancy_grid(g, 0.0f);
  EXPECT_EQ(m.cost(0.1, 0.1), std::optional<std::uint8_t>(253));
  EXPECT_EQ(m.cost(-0.9, -0.9), std::optional<std::uint8_t>(0));
}

TEST(CostMap, OutsideTheGridIsLethal) {
  const CostMap m = CostMap::from_occupancy_grid(free_grid(10, 10, 0.25f), 0.5f);
  EXPECT_EQ(m.cost(-0.01, 1.0), std::optional<std::uint8_t>(253));
  EXPECT_EQ(m.cost(2.5, 1.0), std::optional<std::uint8_t>(253));
  EXPECT_EQ(m.cost(kNaN, 1.0), std::optional<std::uint8_t>(253));
  EXPECT_EQ(m.cost(1.0, 1.0), std::optional<std::uint8_t>(0));
}

TEST(CostMap, MissingCostsGiveNoValue) {
  CostMap m{};
  m.occupancy_grid = free_grid(4, 4, 0.25f);
  EXPECT_EQ(m.cost(0.1, 0.1), std::nullopt);  // costs never computed
  m.compute_costs();
  EXPECT_EQ(m.cost(0.1, 0.1), std::optional<std::uint8_t>(0));
}

TEST(CostMap, ShortGridDataCountsAsUnknown) {
  OccupancyGrid g = free_grid(4, 1, 1.0f);
  g.data.resize(2);
  const CostMap m = CostMap::from_occupancy_grid(g, 0.0f);
  EXPECT_EQ(m.costs, (std::vector<std::uint8_t>{0, 0, 255, 255}));
}

TEST(CostMap, LogSummaryCountsCellKinds) {
  OccupancyGrid g = free_grid(5, 1, 0.25f);
  g.set_occupancy(0, 0, 100);
  g.set_occupancy(4, 0, -1);
  CostMap m = CostMap::from_occupancy_grid(g, 0.3f);
  m.cost_scaling_factor = 1.0f;
  m.compute_costs();
  // (1, 0) is inflated, (2, 0) is 0.5 m away: beyond 0.3 m; (3, 0) is next to the unknown cell.
  EXPECT_EQ(m.log_summary(), "CostMap(5x1 @ 0.25 m, inflation 0.3 m, 1 lethal, 2 inflated, 1 unknown)");
  EXPECT_EQ(horus::log_summary(m), m.log_summary());
}

// The documented algorithm written the plain (HORUS) way: for every cell, search the
// whole window for the nearest source cell.
std::vector<std::uint8_t> reference_costs(const OccupancyGrid& g, float radius, float scaling, std::uint8_t lethal) {
  const long w = g.width, h = g.height;
  std::vector<std::uint8_t> base(g.data.size());
  for (std::size_t i = 0; i < base.size(); ++i) {
    const int v = g.data[i];
    base[i] = v == -1 ? std::uint8_t{255} : v >= 65 ? lethal : static_cast<std::uint8_t>(std::max(2 * v, 0));
  }
  std::vector<std::uint8_t> out = base;
  const long k = static_cast<long>(std::ceil(radius / g.resolution));
  for (long y = 0; y < h; ++y)
    for (long x = 0; x < w; ++x) {
      const auto c = static_cast<std::size_t>(y * w + x);
      if (base[c] >= lethal) continue;
      float best = std::numeric_limits<float>::max();
      bool found = false;
      for (long dy = -k; dy <= k; ++dy)
        for (long dx = -k; dx <= k; ++dx) {
          const long nx = x + dx, ny = y + dy;
          if (nx < 0 || ny < 0 || nx >= w || ny >= h) continue;
          if (base[static_cast<std::size_t>(ny * w + nx)] < lethal) continue;
          const float d = std::sqrt(static_cast<float>(dx * dx + dy * dy)) * g.resolution;
          if (d < best) {
            best = d;
            found = true;
          }
        }
      if (found && best <= radius) {
        const float cap = static_cast<float>(lethal) - 1.0f;
        const float v = std::min(cap * std::pow(1.0f - best / radius, scaling), cap);
        out[c] = std::max(out[c], static_cast<std::uint8_t>(v));
      }
    }
  return out;
}

TEST(CostMap, MatchesAPlainWindowSearchOnAMixedMap) {
  OccupancyGrid g = OccupancyGrid::make(37, 23, 0.1f, Pose2D::make(-1.0, 2.0, 0.0));
  std::uint32_t state = 12345;
  for (auto& v : g.data) {
    state = state * 1103515245u + 12345u;
    const std::uint32_t r = (state >> 16) % 100;
    v = r < 6 ? std::int8_t{100} : r < 9 ? std::int8_t{-1} : r < 12 ? std::int8_t{70} : static_cast<std::int8_t>(r % 60);
  }
  // A solid block, so that interior obstacle cells exist.
  for (std::uint32_t y = 5; y < 12; ++y)
    for (std::uint32_t x = 20; x < 30; ++x) g.set_occupancy(x, y, 100);
  for (float radius : {0.05f, 0.15f, 0.35f, 0.55f})
    for (float scaling : {1.0f, 2.5f, 10.0f}) {
      CostMap m = CostMap::from_occupancy_grid(g, radius);
      m.cost_scaling_factor = scaling;
      m.compute_costs();
      EXPECT_EQ(m.costs, reference_costs(g, radius, scaling, 253)) << "radius " << radius << ", scaling " << scaling;
    }
}

TEST(CostMap, LargeUnknownGridIsComputedQuickly) {
  const CostMap m = CostMap::from_occupancy_grid(OccupancyGrid::make(1000, 1000, 0.05f, Pose2D::origin()), 0.55f);
  EXPECT_EQ(m.costs.size(), 1'000'000u);
  EXPECT_EQ(m.costs.front(), 255);
}

// ===========================================================================
// VelocityObstacle / VelocityObstacles

TEST(VelocityObstacles, HoldUpTo32InTheRustLayout) {
  static_assert(sizeof(VelocityObstacle) == 48);
  static_assert(VelocityObstacles::kMaxObstacles == 32);
  static_assert(std::tuple_size_v<decltype(VelocityObstacles::obstacles)> == 32);
  static_assert(sizeof(VelocityObstacles) == 1552);
  EXPECT_EQ(offsetof(VelocityObstacles, count), 1536u);
}

TEST(VelocityObstacles, AddIsRefusedWhenFull) {
  VelocityObstacles vo{};
  for (std::uint32_t i = 0; i < 32; ++i) {
    const VelocityObstacle o{{1.0 * i, 2.0}, {0.5, 0.0}, 0.3f, 2.0f, i};
    ASSERT_TRUE(vo.add(o)) << i;
  }
  EXPECT_TRUE(vo.is_full());
  EXPECT_EQ(vo.count, 32);
  const VelocityObstacles before = vo;
  EXPECT_FALSE(vo.add(VelocityObstacle{{9.0, 9.0}, {}, 1.0f, 1.0f, 99}));
  EXPECT_EQ(vo, before);
  ASSERT_EQ(vo.valid_obstacles().size(), 32u);
  EXPECT_EQ(vo.valid_obstacles()[31].obstacle_id, 31u);
}

TEST(VelocityObstacles, ClearAndCorruptCount) {
  VelocityObstacles vo{};
  vo.add(VelocityObstacle{{1.0, 2.0}, {0.1, 0.2}, 0.5f, 3.0f, 4});
  vo.timestamp_ns = 6;
  EXPECT_EQ(vo.valid_obstacles().size(), 1u);
  vo.clear();
  EXPECT_EQ(vo.size(), 0u);
  EXPECT_EQ(vo.obstacles[0], VelocityObstacle{});
  EXPECT_EQ(vo.timestamp_ns, 6u);
  vo.count = 200;
  EXPECT_EQ(vo.size(), 32u);
  EXPECT_FALSE(vo.add(VelocityObstacle{}));
}

TEST(VelocityObstacles, LogSummaryListsIds) {
  VelocityObstacles vo{};
  EXPECT_EQ(vo.log_summary(), "VelocityObstacles(0 obstacles)");
  vo.add(VelocityObstacle{.obstacle_id = 4});
  vo.add(VelocityObstacle{.obstacle_id = 7});
  EXPECT_EQ(vo.log_summary(), "VelocityObstacles(2 obstacles, ids 4, 7)");
  for (std::uint32_t i = 0; i < 10; ++i) vo.add(VelocityObstacle{.obstacle_id = 100 + i});
  EXPECT_EQ(vo.log_summary(), "VelocityObstacles(12 obstacles, ids 4, 7, 100, 101, 102, 103, 104, 105, +4 more)");
}

// ===========================================================================
// Every type: samples with a non-default value in every field

template <class T>
T sample();

template <>
Goal sample<Goal>() {
  Goal g = Goal::make(Pose2D{5.0, 3.0, 1.5, 11}, 0.1, 0.05).with_timeout(30.0).with_priority(2);
  g.goal_id = 77;
  g.timestamp_ns = 123;
  return g;
}
template <>
GoalResult sample<GoalResult>() {
  GoalResult r = GoalResult::make(77, GoalStatus::Aborted);
  r.distance_to_goal = 1.25;
  r.eta_seconds = 4.5;
  r.progress = 0.75f;
  r.set_error_message("path blocked");
  r.timestamp_ns = 9;
  return r;
}
template <>
Waypoint sample<Waypoint>() {
  Waypoint w = Waypoint::make(Pose2D{1.0, 2.0, 0.5, 3}).with_velocity(Twist{{0.5, 0.1, 0.0}, {0.0, 0.0, 0.2}, 4});
  w.time_from_start = 2.5;
  w.curvature = 0.25f;
  w.stop_required = 1;
  return w;
}
template <class P>
P sample_path() {
  P p = P::make();
  p.add_waypoint(sample<Waypoint>());
  p.add_waypoint(Waypoint::make(Pose2D::make(4.0, 6.0, 0.0)).with_stop());
  p.set_frame_id("map");
  p.set_algorithm("a_star");
  p.timestamp_ns = 555;
  return p;
}
template <>
Path sample<Path>() {
  Path p = sample_path<Path>();
  p.duration_seconds = 12.5;
  return p;
}
template <>
NavPath sample<NavPath>() {
  NavPath p = sample_path<NavPath>();
  p.estimated_time = 12.5;
  return p;
}
template <>
PathPlan sample<PathPlan>() {
  PathPlan plan = PathPlan::make();
  plan.add_waypoint(0.5f, 1.5f, 0.25f);
  plan.add_waypoint(1.0f, 2.0f, -0.5f);
  plan.goal_pose = {5.0f, 3.0f, 1.25f};
  plan.timestamp_ns = 66;
  return plan;
}
template <>
OccupancyGrid sample<OccupancyGrid>() {
  OccupancyGrid g = OccupancyGrid::make(20, 10, 0.25f, Pose2D{-2.0, -1.0, 0.5, 8});
  for (std::uint32_t x = 0; x < 20; ++x) g.set_occupancy(x, 0, 100);
  for (std::uint32_t y = 1; y < 9; ++y)
    for (std::uint32_t x = 0; x < 15; ++x) g.set_occupancy(x, y, static_cast<std::int8_t>((x * 7 + y) % 50));
  g.set_occupancy(10, 5, 100);
  g.set_occupancy(5, 5, 0);  // free and more than 0.6 m from any obstacle or unknown cell
  g.set_frame_id("map");
  g.set_metadata("floor 2, slam v3");
  g.timestamp_ns = 1234;
  return g;
}
template <>
CostMap sample<CostMap>() {
  CostMap m = CostMap::from_occupancy_grid(sample<OccupancyGrid>(), 0.6f);
  m.cost_scaling_factor = 3.0f;
  m.lethal_cost = 250;
  m.compute_costs();
  return m;
}
template <>
VelocityObstacle sample<VelocityObstacle>() {
  return VelocityObstacle{{1.5, -2.0}, {0.5, 0.25}, 0.4f, 3.0f, 17};
}
template <>
VelocityObstacles sample<VelocityObstacles>() {
  VelocityObstacles vo{};
  vo.add(sample<VelocityObstacle>());
  vo.add(VelocityObstacle{{-1.0, 0.5}, {0.0, -0.1}, 0.2f, 1.5f, 18});
  vo.timestamp_ns = 99;
  return vo;
}

TEST(Samples, CostMapSampleHasEveryKindOfCell) {
  const CostMap m = sample<CostMap>();
  const auto has = [&](auto pred) { return std::any_of(m.costs.begin(), m.costs.end(), pred); };
  EXPECT_TRUE(has([](std::uint8_t c) { return c == 250; }));
  EXPECT_TRUE(has([](std::uint8_t c) { return c == 255; }));
  EXPECT_TRUE(has([](std::uint8_t c) { return c > 0 && c < 250; }));
  EXPECT_TRUE(has([](std::uint8_t c) { return c == 0; }));
}

template <class T>
class EveryNavigationMessage : public ::testing::Test {};
using AllNavigationMessages = ::testing::Types<Goal, GoalResult, Waypoint, Path, NavPath, PathPlan, OccupancyGrid,
                                               CostMap, VelocityObstacle, VelocityObstacles>;
TYPED_TEST_SUITE(EveryNavigationMessage, AllNavigationMessages);

TYPED_TEST(EveryNavigationMessage, JsonRoundTripGivesAnEqualMessage) {
  const TypeParam original = sample<TypeParam>();
  ASSERT_NE(original, TypeParam{}) << "the sample should exercise non-default values";
  const nlohmann::json j = horus::to_json(original);
  EXPECT_EQ(horus::from_json<TypeParam>(j), original);
  // And through text, as a file or a socket would carry it.
  EXPECT_EQ(horus::from_json<TypeParam>(nlohmann::json::parse(j.dump())), original);
}

TYPED_TEST(EveryNavigationMessage, SampleSetsEveryField) {
  const TypeParam s = sample<TypeParam>();
  const TypeParam d{};
  horus::reflect::for_each_field_desc<TypeParam>([&](const auto& fd) {
    EXPECT_FALSE(fd.get(s) == fd.get(d)) << "field " << fd.name << " keeps its default in the sample";
  });
}

TYPED_TEST(EveryNavigationMessage, FormatsWithItsShortTypeNameAndFields) {
  const TypeParam s = sample<TypeParam>();
  const std::string text = fmt::format("{}", s);
  const std::string_view qualified = horus::type_name<TypeParam>();
  const std::string short_name(qualified.substr(qualified.rfind("::") + 2));
  EXPECT_EQ(text.rfind(short_name + " { ", 0), 0u) << text.substr(0, 200);
  const std::string first_field(horus::reflect::get<0>(horus::reflect::fields<TypeParam>()).name);
  EXPECT_NE(text.find(" " + first_field + ": "), std::string::npos) << text.substr(0, 200);
  EXPECT_EQ(text, horus::to_string(s));
}

TYPED_TEST(EveryNavigationMessage, LivesInHorusMsgNamespace) {
  EXPECT_EQ(horus::type_name<TypeParam>().rfind("horus::msg::", 0), 0u) << horus::type_name<TypeParam>();
}

TEST(Formatting, GoalPrintsEveryField) {
  EXPECT_EQ(fmt::format("{}", sample<Goal>()),
            "Goal { target_pose: Pose2D { x: 5, y: 3, theta: 1.5, timestamp_ns: 11 }, tolerance_position: 0.1, "
            "tolerance_angle: 0.05, timeout_seconds: 30, priority: 2, goal_id: 77, timestamp_ns: 123 }");
}

TEST(Formatting, GridPrintsItsCellsAndText) {
  OccupancyGrid g = OccupancyGrid::make(2, 1, 0.5f, Pose2D::origin());
  g.set_occupancy(1, 0, 100);
  g.set_frame_id("map");
  const std::string text = fmt::format("{}", g);
  EXPECT_NE(text.find("data: [-1, 100]"), std::string::npos) << text;
  EXPECT_NE(text.find("frame_id: \"map\""), std::string::npos) << text;
  const std::string cm = fmt::format("{}", CostMap::from_occupancy_grid(g, 0.0f));
  EXPECT_NE(cm.find("costs: [255, 253]"), std::string::npos) << cm;
}

TEST(Json, GridDataIsAnArrayOfSignedNumbers) {
  OccupancyGrid g = OccupancyGrid::make(3, 1, 0.5f, Pose2D::origin());
  g.set_occupancy(1, 0, 0);
  g.set_occupancy(2, 0, 100);
  const nlohmann::json j = horus::to_json(g);
  EXPECT_EQ(j["data"], nlohmann::json::parse("[-1, 0, 100]"));
  EXPECT_EQ(j["width"], 3);
  // Out-of-range cell values are refused when reading.
  nlohmann::json bad = j;
  bad["data"][0] = 200;
  EXPECT_THROW((void)horus::from_json<OccupancyGrid>(bad), horus::JsonError);
}

// Fixed-size ones: trivially copyable, zero default, memcpy is a full copy.
template <class T>
class FixedNavigationMessage : public ::testing::Test {};
using FixedNavigationMessages =
    ::testing::Types<Goal, GoalResult, Waypoint, Path, NavPath, PathPlan, VelocityObstacle, VelocityObstacles>;
TYPED_TEST_SUITE(FixedNavigationMessage, FixedNavigationMessages);

TYPED_TEST(FixedNavigationMessage, IsTriviallyCopyableWithAnAllZeroDefault) {
  static_assert(horus::reflect::is_fixed_size<TypeParam>);
  static_assert(std::is_aggregate_v<TypeParam>);
  const TypeParam original = sample<TypeParam>();
  TypeParam copy{};
  std::memcpy(&copy, &original, sizeof(TypeParam));
  EXPECT_EQ(copy, original);
  const auto zero = std::bit_cast<TypeParam>(std::array<unsigned char, sizeof(TypeParam)>{});
  EXPECT_EQ(TypeParam{}, zero);
}

TEST(VariableSizeNavigationMessages, AreNotFixedSize) {
  static_assert(!horus::reflect::is_fixed_size<OccupancyGrid>);
  static_assert(!horus::reflect::is_fixed_size<CostMap>);
  EXPECT_NE(horus::reflect::type_signature<OccupancyGrid>().find("seq<i8> data;"), std::string::npos);
  EXPECT_NE(horus::reflect::type_signature<CostMap>().find("seq<u8> costs;"), std::string::npos);
}

}  // namespace
