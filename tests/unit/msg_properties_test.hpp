// The properties every standard message has, as one typed suite (MessageProperties): a full copy,
// an all-zero (or empty) default, a JSON round trip, printing under its short name, the horus::msg
// namespace.
// Each family's file defines sample<T>() for its types and instantiates the suite with its type
// list (test_messages.cpp, test_msg_force.cpp, test_msg_motion_layouts.cpp,
// test_msg_navigation_obstacles.cpp, test_msg_vision_tracking.cpp); what only some families check
// stays in their files.
#pragma once

#include <gtest/gtest.h>

#include <array>
#include <bit>
#include <cstring>
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

#include <fmt/format.h>

#include "horus/format.hpp"
#include "horus/json.hpp"
#include "horus/reflect.hpp"
#include "message_test_support.hpp"

namespace {

// A value of T with non-default values (each family's file defines it for its types).
template <class T>
T sample();

// Whether T holds a sequence and so has no fixed layout (each family's file says so for such
// types, before it instantiates the suite); every other type must be fixed-size.
template <class T>
constexpr bool kVariableSize = false;

// Whether T, fixed-size, keeps its fields private and so is not an aggregate (each family's file
// says so for such types, before it instantiates the suite); every other fixed-size one must be.
template <class T>
constexpr bool kNotAggregate = false;

// Whether T is a sequence field (std::vector).
template <class T>
constexpr bool kIsVector = false;
template <class E, class A>
constexpr bool kIsVector<std::vector<E, A>> = true;

// Expects every field of sample<T>() to differ from the field of the default value.
template <class T>
void ExpectSampleSetsEveryField() {
  const T s = sample<T>();
  const T d{};
  horus::reflect::for_each_field_desc<T>([&](const auto& fd) {
    EXPECT_FALSE(fd.get(s) == fd.get(d)) << "field " << fd.name << " keeps its default in the sample";
  });
}

template <class T>
class MessageProperties : public ::testing::Test {};
TYPED_TEST_SUITE_P(MessageProperties);

// A fixed-size message is trivially copyable, standard layout and an aggregate (unless
// kNotAggregate), and a memcpy is a full copy; a variable-size one does not claim a fixed size,
// and a copy is a full copy.
TYPED_TEST_P(MessageProperties, CopiesWhole) {
  const TypeParam original = sample<TypeParam>();
  if constexpr (kVariableSize<TypeParam>) {
    static_assert(!horus::reflect::is_fixed_size<TypeParam>);
    const TypeParam copy = original;
    EXPECT_EQ(copy, original);
  } else {
    static_assert(std::is_trivially_copyable_v<TypeParam>);
    static_assert(std::is_standard_layout_v<TypeParam>);
    static_assert(horus::reflect::is_fixed_size<TypeParam>);
    static_assert(std::is_aggregate_v<TypeParam> != kNotAggregate<TypeParam>);
    TypeParam copy{};
    std::memcpy(&copy, &original, sizeof(TypeParam));
    EXPECT_EQ(copy, original);
  }
}

// A fixed-size message's default is all zero bytes; a variable-size one's sequences are empty.
TYPED_TEST_P(MessageProperties, DefaultValueIsAllZerosOrEmpty) {
  if constexpr (kVariableSize<TypeParam>) {
    const TypeParam d{};
    int sequences = 0;
    horus::reflect::for_each_field_desc<TypeParam>([&](const auto& fd) {
      if constexpr (kIsVector<std::remove_cvref_t<decltype(fd.get(d))>>) {
        ++sequences;
        EXPECT_TRUE(fd.get(d).empty()) << "field " << fd.name << " is not empty by default";
      }
    });
    EXPECT_GT(sequences, 0) << "a variable-size message without a sequence field";
  } else {
    const auto zero = std::bit_cast<TypeParam>(std::array<unsigned char, sizeof(TypeParam)>{});
    EXPECT_EQ(TypeParam{}, zero);
  }
}

TYPED_TEST_P(MessageProperties, JsonRoundTripGivesAnEqualMessage) {
  const TypeParam original = sample<TypeParam>();
  ASSERT_NE(original, TypeParam{}) << "the sample should exercise non-default values";
  const nlohmann::json j = horus::to_json(original);
  EXPECT_EQ(horus::from_json<TypeParam>(j), original) << j.dump();
  // And through text, as a file or a socket would carry it.
  EXPECT_EQ(horus::from_json<TypeParam>(nlohmann::json::parse(j.dump())), original) << j.dump();
}

TYPED_TEST_P(MessageProperties, FormatsWithItsShortTypeName) {
  const TypeParam s = sample<TypeParam>();
  const std::string text = fmt::format("{}", s);
  const std::string_view qualified = horus::type_name<TypeParam>();
  const std::string short_name(qualified.substr(qualified.rfind("::") + 2));
  EXPECT_EQ(text.rfind(short_name + " { ", 0), 0u) << text.substr(0, 200);
  EXPECT_EQ(text, horus::to_string(s));
}

TYPED_TEST_P(MessageProperties, LivesInHorusMsgNamespace) {
  EXPECT_EQ(horus::type_name<TypeParam>().rfind("horus::msg::", 0), 0u) << horus::type_name<TypeParam>();
}

REGISTER_TYPED_TEST_SUITE_P(MessageProperties, CopiesWhole, DefaultValueIsAllZerosOrEmpty,
                            JsonRoundTripGivesAnEqualMessage, FormatsWithItsShortTypeName, LivesInHorusMsgNamespace);

}  // namespace
