// Unit tests of VelocityObstacle / VelocityObstacles, samples of every navigation type with a
// non-default value in every field, and the properties of every navigation message.
#include "msg_navigation_test.hpp"
#include "msg_properties_test.hpp"

namespace {

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

// The navigation types: the properties every message has (msg_properties_test.hpp; the grids are
// variable-size), and what only this family checks: every field sampled, the first one printed.
using NavigationMessages = ::testing::Types<Goal, GoalResult, Waypoint, Path, NavPath, PathPlan, OccupancyGrid, CostMap,
                                           VelocityObstacle, VelocityObstacles>;
template <>
constexpr bool kVariableSize<OccupancyGrid> = true;
template <>
constexpr bool kVariableSize<CostMap> = true;
INSTANTIATE_TYPED_TEST_SUITE_P(Navigation, MessageProperties, NavigationMessages);

template <class T>
class EveryNavigationMessage : public ::testing::Test {};
TYPED_TEST_SUITE(EveryNavigationMessage, NavigationMessages);

TYPED_TEST(EveryNavigationMessage, SampleSetsEveryField) { ExpectSampleSetsEveryField<TypeParam>(); }

TYPED_TEST(EveryNavigationMessage, FormatsItsFirstField) {
  const std::string text = fmt::format("{}", sample<TypeParam>());
  const std::string first_field(horus::reflect::get<0>(horus::reflect::fields<TypeParam>()).name);
  EXPECT_NE(text.find(" " + first_field + ": "), std::string::npos) << text.substr(0, 200);
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

TEST(VariableSizeNavigationMessages, AreNotFixedSize) {
  static_assert(!horus::reflect::is_fixed_size<OccupancyGrid>);
  static_assert(!horus::reflect::is_fixed_size<CostMap>);
  EXPECT_NE(horus::reflect::type_signature<OccupancyGrid>().find("seq<i8> data;"), std::string::npos);
  EXPECT_NE(horus::reflect::type_signature<CostMap>().find("seq<u8> costs;"), std::string::npos);
}

}  // namespace
