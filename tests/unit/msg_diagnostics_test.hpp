// What the diagnostics message tests share (test_msg_*.cpp of these messages): includes and helpers.
#pragma once

#include <gtest/gtest.h>

#include <array>
#include <bit>
#include <chrono>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <limits>
#include <map>
#include <tuple>
#include <optional>
#include <span>
#include <sstream>
#include <ostream>
#include <stdexcept>
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

#include <fmt/format.h>

#include "horus/format.hpp"
#include "horus/json.hpp"
#include "horus/msg/audio.hpp"
#include "horus/msg/diagnostics.hpp"
#include "horus/msg/force.hpp"
#include "horus/msg/generic.hpp"
#include "horus/msg/generic_value.hpp"
#include "message_test_support.hpp"

namespace {

using namespace horus_test::values;

using namespace horus::msg;

}  // namespace
