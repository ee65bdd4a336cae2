// Sample messages for tests over every standard type: a value with a distinct, valid value
// in every field (sample<T>()), a large-data message whose metadata describes its bytes
// (topic_sample<T>()), a comparison that prints both sides, and the gtest type list.
#pragma once

#include <gtest/gtest.h>

#include <fmt/format.h>

#include <concepts>
#include <cstdint>
#include <string>
#include <string_view>
#include <type_traits>

#include "horus/fixed_string.hpp"
#include "horus/format.hpp"
#include "horus/json.hpp"
#include "horus/msg/all.hpp"
#include "horus/topic.hpp"

namespace horus_test {

// ---------------------------------------------------------------------------
// A message with a distinct, valid value in every field (reflection-driven), so that a
// path that drops, reorders or truncates a field shows up as a difference.

struct Filler {
  std::uint64_t k = 1;

  template <class V>
  void fill(V& v) {
    using namespace horus::reflect;
    if constexpr (std::is_same_v<V, bool>) {
      v = (k++ % 2) == 1;
    } else if constexpr (detail::is_char_array<V>::value) {
      horus::set_fixed_str(v, fmt::format("t{}", k++).substr(0, std::tuple_size_v<V> - 1));
    } else if constexpr (std::is_same_v<V, char>) {
      v = static_cast<char>('a' + k++ % 26);
    } else if constexpr (std::is_integral_v<V>) {
      v = static_cast<V>(k++ % 100 + 1);
    } else if constexpr (std::is_floating_point_v<V>) {
      v = static_cast<V>(static_cast<double>(k++ % 1000) * 0.5 + 0.25);
    } else if constexpr (ReflectedEnum<V>) {
      const auto values = enum_values<V>();
      v = values[k++ % values.size()].value;
    } else if constexpr (std::is_enum_v<V>) {
      v = static_cast<V>(1);
    } else if constexpr (std::is_same_v<V, std::string>) {
      v = fmt::format("s{}", k++);
    } else if constexpr (detail::is_std_array<V>::value) {
      for (auto& e : v) fill(e);
    } else if constexpr (detail::is_std_vector<V>::value) {
      v.resize(3);
      for (auto& e : v) fill(e);
    } else {
      for_each_field(v, [&](std::string_view, auto& f) { fill(f); });
    }
  }
};

template <class T>
T sample() {
  T m{};
  Filler f;
  f.fill(m);
  return m;
}

template <class T>
::testing::AssertionResult SameMessage(const T& a, const T& b) {
  if constexpr (std::equality_comparable<T>) {
    if (!(a == b)) return ::testing::AssertionFailure() << "operator== says they differ: " << horus::to_string(a)
                                                        << "\n vs " << horus::to_string(b);
  }
  if (horus::to_json(a) != horus::to_json(b))
    return ::testing::AssertionFailure() << "JSON differs: " << horus::to_json(a).dump() << "\n vs "
                                         << horus::to_json(b).dump();
  return ::testing::AssertionSuccess();
}

template <class... T>
::testing::Types<T...> to_gtest(horus::msg::TypeList<T...>);
using AllTypes = decltype(to_gtest(horus::msg::AllMessages{}));


struct TypeNames {
  template <class T>
  static std::string GetName(int) {
    const std::string_view q = horus::type_name<T>();
    return std::string(q.substr(q.rfind("::") + 2));
  }
};

// A large-data message whose metadata describes its bytes (the reflection sample's sizes do
// not agree with each other), with a distinct byte pattern and the sample's text and stamps.
template <class T>
T topic_sample() {
  using namespace horus::msg;
  T m;
  if constexpr (std::is_same_v<T, Image>) {
    m = Image(3, 5, ImageEncoding::Rgb8);
    m.set_frame_id("cam");
    m.set_timestamp_ns(42);
  } else if constexpr (std::is_same_v<T, PointCloud>) {
    m = PointCloud::make(7, 4, TensorDtype::F32);
    m.set_timestamp_ns(42);
  } else if constexpr (std::is_same_v<T, DepthImage>) {
    m = DepthImage::millimeters(4, 6);
    m.set_timestamp_ns(42);
  } else if constexpr (std::is_same_v<T, Tensor>) {
    m = Tensor({2, 3, 4}, TensorDtype::U16);
  } else {
    return sample<T>();
  }
  if constexpr (horus::PoolMessage<T>) {
    auto bytes = m.data_mut();
    for (std::size_t i = 0; i < bytes.size(); ++i) bytes[i] = static_cast<std::uint8_t>(i * 7 + 3);
  }
  return m;
}

}  // namespace horus_test
