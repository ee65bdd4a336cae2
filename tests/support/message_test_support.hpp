// What the standard messages' unit tests (unit/test_messages.cpp, unit/test_msg_*.cpp, built
// into one binary) share: GoogleTest's printer of a message, special values, a substring check.
#pragma once

#include <cstdint>
#include <limits>
#include <numbers>
#include <ostream>
#include <string_view>

#include "horus/format.hpp"
#include "horus/reflect.hpp"

namespace horus::msg {
// Lets GoogleTest print messages in failure output (found by ADL).
template <class T>
  requires horus::Reflected<T>
void PrintTo(const T& m, std::ostream* os) {
  *os << horus::to_string(m);
}
}  // namespace horus::msg

namespace horus_test::values {
inline constexpr double kPi = std::numbers::pi;
inline constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
inline constexpr double kInf = std::numeric_limits<double>::infinity();
inline constexpr float kNaNf = std::numeric_limits<float>::quiet_NaN();
inline constexpr float kInff = std::numeric_limits<float>::infinity();
inline constexpr std::uint32_t kU32Max = std::numeric_limits<std::uint32_t>::max();

inline bool contains(std::string_view text, std::string_view part) { return text.find(part) != std::string_view::npos; }
}  // namespace horus_test::values
