// What the perception message tests share (test_msg_*.cpp of these messages): includes and helpers.
#pragma once

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <optional>
#include <ostream>
#include <span>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include <fmt/format.h>

#include "horus/format.hpp"
#include "horus/json.hpp"
#include "horus/messages.hpp"
#include "message_test_support.hpp"

namespace {

using namespace horus_test::values;

using namespace horus::msg;
using Bytes = std::vector<std::uint8_t>;

inline Bytes to_bytes(std::span<const std::uint8_t> s) { return Bytes(s.begin(), s.end()); }
inline Bytes to_bytes(const std::optional<std::span<const std::uint8_t>>& s) {
  return s ? to_bytes(*s) : Bytes{0xDE, 0xAD};  // marker that no expectation uses
}

template <class T>
inline Bytes bytes_of(const T& v) {
  Bytes b(sizeof(T));
  std::memcpy(b.data(), &v, sizeof(T));
  return b;
}

// Expects fn() to throw std::invalid_argument whose text contains every fragment.
template <class F>
::testing::AssertionResult ThrowsNaming(F&& fn, std::initializer_list<std::string_view> fragments) {
  try {
    fn();
  } catch (const std::invalid_argument& e) {
    const std::string what = e.what();
    for (std::string_view f : fragments)
      if (what.find(f) == std::string::npos)
        return ::testing::AssertionFailure() << "message \"" << what << "\" lacks \"" << f << "\"";
    return ::testing::AssertionSuccess();
  }
  return ::testing::AssertionFailure() << "no std::invalid_argument thrown";
}

template <class T>
void ExpectJsonRoundTrip(const T& m) {
  const auto j = horus::to_json(m);
  EXPECT_EQ(horus::from_json<T>(j), m) << j.dump();
}

}  // namespace
