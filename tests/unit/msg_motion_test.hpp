// What the motion message tests share (test_msg_*.cpp of these messages): includes and helpers.
#pragma once

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

}  // namespace
