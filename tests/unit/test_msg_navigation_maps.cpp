// Unit tests of the navigation maps: OccupancyGrid and CostMap (navigation.hpp).
#include "msg_navigation_test.hpp"

namespace {

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

}  // namespace
