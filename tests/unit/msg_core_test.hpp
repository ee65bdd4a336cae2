// What the core message tests share (test_messages.cpp, test_msg_sensors.cpp: geometry, sensor,
// joint and heartbeat messages): includes and helpers.
#pragma once

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstddef>
#include <limits>
#include <numbers>
#include <optional>
#include <ostream>
#include <stdexcept>
#include <string>
#include <string_view>

#include <fmt/format.h>

#include "horus/format.hpp"
#include "horus/json.hpp"
#include "horus/messages.hpp"
#include "message_test_support.hpp"

namespace {

using namespace horus_test::values;

using namespace horus::msg;

}  // namespace
