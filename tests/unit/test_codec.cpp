// The local wire format (horus/wire/local.hpp): round trips of every kind of field, and
// truncated, corrupt and over-long buffers giving errors that name the field.
#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <cstring>
#include <string>
#include <stdexcept>
#include <vector>

#include "horus/wire/local.hpp"

namespace codec_test {

enum class Kind : std::uint8_t { A = 1, B = 7 };
HORUS_REFLECT_ENUM(Kind, A, B)

struct Point {
  float x{}, y{};
  friend bool operator==(const Point&, const Point&) = default;
};
HORUS_REFLECT(Point, x, y)

struct Named {
  std::string name;
  std::vector<Point> points;
  friend bool operator==(const Named&, const Named&) = default;
};
HORUS_REFLECT(Named, name, points)

/// Trivially copyable, but holds a bool: encoded field by field (5 bytes, no padding).
struct Flagged {
  std::uint32_t id{};
  bool on{};
  friend bool operator==(const Flagged&, const Flagged&) = default;
};
HORUS_REFLECT(Flagged, id, on)

struct Everything {
  std::uint8_t u8{};
  std::int64_t i64{};
  double f64{};
  bool flag{};
  Kind kind{};
  std::array<char, 8> tag{};
  Point origin{};
  std::vector<std::int8_t> cells;
  std::string text;
  std::vector<Named> groups;
  std::array<Named, 2> pair;
  std::vector<std::vector<std::uint16_t>> nested;
  std::vector<std::string> words;
  friend bool operator==(const Everything&, const Everything&) = default;
};
HORUS_REFLECT(Everything, u8, i64, f64, flag, kind, tag, origin, cells, text, groups, pair, nested, words)

Everything sample() {
  Everything e;
  e.u8 = 200;
  e.i64 = -1234567890123;
  e.f64 = 3.25;
  e.flag = true;
  e.kind = Kind::B;
  e.tag = {'o', 'd', 'o', 'm', 0, 0, 0, 0};
  e.origin = {1.5f, -2.5f};
  e.cells = {-1, 0, 100, 42};
  e.text = "hello, fleet";
  e.groups = {Named{"a", {{1, 2}, {3, 4}}}, Named{"", {}}, Named{"ccc", {{5, 6}}}};
  e.pair = {Named{"left", {{7, 8}}}, Named{"right", {}}};
  e.nested = {{1, 2, 3}, {}, {65535}};
  e.words = {"x", "", "yz"};
  return e;
}

}  // namespace codec_test

namespace {
using codec_test::Everything;
using codec_test::Point;
using codec_test::sample;
namespace codec = horus::codec;

TEST(Codec, EveryKindOfFieldRoundTrips) {
  const Everything e = sample();
  const auto bytes = codec::encode(e);
  EXPECT_EQ(bytes.size(), codec::encoded_size(e));
  auto back = codec::decode<Everything>(bytes);
  ASSERT_TRUE(back) << back.error();
  EXPECT_EQ(*back, e);
}

TEST(Codec, AnEmptyMessageRoundTrips) {
  const Everything e{};
  auto back = codec::decode<Everything>(codec::encode(e));
  ASSERT_TRUE(back) << back.error();
  EXPECT_EQ(*back, e);
}

TEST(Codec, ATriviallyCopyableMessageIsItsBytes) {
  const Point p{1.0f, 2.0f};
  const auto bytes = codec::encode(p);
  ASSERT_EQ(bytes.size(), sizeof(Point));
  EXPECT_EQ(std::memcmp(bytes.data(), &p, sizeof(Point)), 0);
}

TEST(Codec, SequencesAreACountThenTheElements) {
  codec_test::Named n{"ab", {{1, 2}}};
  const auto bytes = codec::encode(n);
  ASSERT_EQ(bytes.size(), 4u + 2u + 4u + sizeof(Point));
  std::uint32_t count = 0;
  std::memcpy(&count, bytes.data(), 4);
  EXPECT_EQ(count, 2u);
  std::memcpy(&count, bytes.data() + 6, 4);
  EXPECT_EQ(count, 1u);
}

TEST(Codec, EveryTruncationIsAnErrorNamingAField) {
  const auto bytes = codec::encode(sample());
  for (std::size_t n = 0; n < bytes.size(); ++n) {
    auto r = codec::decode<Everything>(std::span<const std::byte>(bytes.data(), n));
    ASSERT_FALSE(r) << "a buffer cut at " << n << " of " << bytes.size() << " bytes decoded";
    EXPECT_NE(r.error().find("codec_test::Everything."), std::string::npos) << r.error();
  }
}

TEST(Codec, TrailingBytesAreAnError) {
  auto bytes = codec::encode(sample());
  bytes.push_back(std::byte{0});
  auto r = codec::decode<Everything>(bytes);
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().find("1 bytes left over"), std::string::npos) << r.error();
}

TEST(Codec, AHugeCorruptCountIsRefusedBeforeAllocating) {
  codec_test::Named n{"ab", {{1, 2}}};
  auto bytes = codec::encode(n);
  const std::uint32_t huge = 0xfffffff0u;
  std::memcpy(bytes.data() + 6, &huge, 4);  // the points count
  auto r = codec::decode<codec_test::Named>(bytes);
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().find("codec_test::Named.points: count 4294967280"), std::string::npos) << r.error();
}

TEST(Codec, RandomCorruptionNeverCrashesOrReadsPastTheEnd) {
  // Flip bytes one at a time: decoding either fails with a message or yields some message;
  // under ASan any read past the buffer would abort the test.
  const auto good = codec::encode(sample());
  std::uint64_t x = 0x9e3779b97f4a7c15ULL;
  int failures = 0;
  for (int i = 0; i < 2000; ++i) {
    auto bytes = good;
    x ^= x << 13;
    x ^= x >> 7;
    x ^= x << 17;
    bytes[x % bytes.size()] = static_cast<std::byte>(x >> 56);
    auto r = codec::decode<Everything>(bytes);
    if (!r) {
      ++failures;
      EXPECT_FALSE(r.error().empty());
    }
  }
  EXPECT_GT(failures, 0);  // some flips hit lengths and must be caught
}

TEST(Codec, ABoolByteOtherThanZeroOrOneIsAnErrorNamingTheField) {
  auto bytes = codec::encode(sample());
  bytes[1 + 8 + 8] = std::byte{2};  // u8, i64, f64, then flag
  auto r = codec::decode<Everything>(bytes);
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().find("codec_test::Everything.flag: bool byte 2, expected 0 or 1"), std::string::npos)
      << r.error();
}

TEST(Codec, ACorruptCountOfStringsFailsWithoutAllocatingBeyondTheBuffer) {
  // 1000 empty strings encode as 4 bytes each; a count claiming them all then fails at the end.
  Everything e;
  e.words.assign(1000, std::string());
  auto bytes = codec::encode(e);
  const std::size_t count_at = bytes.size() - (4 + 1000 * 4);
  const std::uint32_t claimed = 1001;
  std::memcpy(bytes.data() + count_at, &claimed, 4);
  auto r = codec::decode<Everything>(bytes);
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().find("codec_test::Everything.words: count 1001"), std::string::npos) << r.error();
}

TEST(Codec, ErrorsNameTheElementInsideNestedSequences) {
  Everything e = sample();
  auto bytes = codec::encode(e);
  // Cut inside groups[2].points (the last group's single point).
  const std::size_t tail = codec::detail::size_of(e.pair) + codec::detail::size_of(e.nested) + codec::detail::size_of(e.words);
  auto r = codec::decode<Everything>(std::span<const std::byte>(bytes.data(), bytes.size() - tail - 3));
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().find("codec_test::Everything.groups[2].points: count 1 needs at least 8 bytes, 5 remain"),
            std::string::npos)
      << r.error();
}

TEST(Codec, EncodingIntoATooSmallBufferThrowsAndWritesNothingPastIt) {
  const Everything e = sample();
  std::vector<std::byte> out(codec::encoded_size(e) + 16, std::byte{0x5a});
  EXPECT_THROW(codec::encode(e, std::span<std::byte>(out.data(), out.size() - 17)), std::length_error);
  for (std::size_t i = out.size() - 17; i < out.size(); ++i) EXPECT_EQ(out[i], std::byte{0x5a}) << i;
}

TEST(Codec, APodMessageWithABoolIsEncodedFieldByFieldAndRoundTrips) {
  const codec_test::Flagged f{7, true};
  const auto bytes = codec::encode(f);
  EXPECT_EQ(bytes.size(), 5u);
  EXPECT_EQ(bytes[4], std::byte{1});
  auto back = codec::decode<codec_test::Flagged>(bytes);
  ASSERT_TRUE(back) << back.error();
  EXPECT_EQ(*back, f);
}

TEST(Codec, EnumValuesWithoutANameRoundTrip) {
  Everything e;
  e.kind = static_cast<codec_test::Kind>(42);
  auto back = codec::decode<Everything>(codec::encode(e));
  ASSERT_TRUE(back) << back.error();
  EXPECT_EQ(static_cast<int>(back->kind), 42);
}

}  // namespace
