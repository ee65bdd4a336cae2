// What the navigation message tests share (test_msg_*.cpp of these messages): includes and helpers.
#pragma once

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
inline OccupancyGrid free_grid(std::uint32_t w, std::uint32_t h, float res, const Pose2D& origin = Pose2D::origin()) {
  OccupancyGrid g = OccupancyGrid::make(w, h, res, origin);
  std::fill(g.data.begin(), g.data.end(), std::int8_t{0});
  return g;
}

inline std::uint8_t cost_at(const CostMap& m, std::uint32_t gx, std::uint32_t gy) {
  return m.costs.at(static_cast<std::size_t>(gy) * m.occupancy_grid.width + gx);
}

}  // namespace
