// The XCDR1 codec: exact bytes for every construct (what idlc and fastddsgen programs read),
// both byte orders, and corrupt or truncated samples refused with the field named.
#include <gtest/gtest.h>

#include <cstring>
#include <string>
#include <vector>

#include "horus/wire/xcdr1.hpp"
#include "wire_test_support.hpp"

namespace {

using wiretest::all_sample;
using wiretest::hex;

// Offsets count from the body's first byte; 8-byte values align to 8 (XCDR1).
const std::string kAllBytes =
    "01 78 fe 00 34 12 00 00 fd ff ff ff 00 00 00 00"  // flag c i8 pad u16 pad i32 pad
    "08 07 06 05 04 03 02 01 00 00 c0 3f 00 00 00 00"  // u64 f pad
    "00 00 00 00 00 00 04 40 02 00 00 00 fe ff 61 62"  // d mode(u32) raw(i16) name..
    "00 00 01 00 02 00 03 00 03 00 00 00 68 69 00 00"  // ..name shorts text("hi\0") pad
    "01 00 00 00 00 00 00 00 00 00 00 00 00 00 e0 3f"  // values: count pad 0.5
    "01 00 00 00 07 00 00 00 00 00 00 00 00 00 f0 3f"  // inners: count a pad b
    "02 00 00 00 02 00 00 00 61 00 00 00 01 00 00 00"  // words: count "a\0" pad ""
    "00 09 00 00 00 00 00 00 00 00 00 00 00 00 f0 bf";  // \0 inner.a pad inner.b

TEST(Cdr, EncodesEveryConstructAsXcdr1) {
  const auto m = all_sample();
  const auto bytes = horus::cdr::encode(m);
  EXPECT_EQ(bytes, hex(kAllBytes));
  EXPECT_EQ(horus::cdr::encoded_size(m), bytes.size());
}

TEST(Cdr, DecodesWhatItEncodes) {
  const auto m = all_sample();
  auto back = horus::cdr::decode<wiretest::All>(hex(kAllBytes));
  ASSERT_TRUE(back) << back.error();
  EXPECT_EQ(*back, m);
}

TEST(Cdr, EmptySequencesAddNoAlignment) {
  // As Fast CDR and Cyclone write it: an empty sequence<double> is its count only, and an
  // empty string is length 1 and its NUL.
  wiretest::All m;
  const auto bytes = horus::cdr::encode(m);
  auto back = horus::cdr::decode<wiretest::All>(bytes);
  ASSERT_TRUE(back) << back.error();
  EXPECT_EQ(*back, m);
  // text at 56: length 1 then NUL; values count at 64, inners count at 68 (no padding to 8).
  ASSERT_GE(bytes.size(), 72u);
  EXPECT_EQ(bytes[56], std::byte{1});
  EXPECT_EQ(bytes[60], std::byte{0});
}

TEST(Cdr, DecodesBigEndianSamples) {
  // Inner{a = 7, b = 1.0} written big endian: a, 7 bytes of padding, then b.
  const auto be = hex("07 00 00 00 00 00 00 00 3f f0 00 00 00 00 00 00");
  auto m = horus::cdr::decode<wiretest::Inner>(be, /*little_endian=*/false);
  ASSERT_TRUE(m) << m.error();
  EXPECT_EQ(m->a, 7);
  EXPECT_EQ(m->b, 1.0);
  // A big-endian sequence of uint16 and a big-endian enum.
  wiretest::Keywords k;
  k.map = 0x01020304;
  k.keywords = 5;
  k.pairs = {{1, 2}};
  const auto kb = hex("01 02 03 04 05 00 00 00"
                      "00 00 00 00 00 00 00 00 00 00 00 00 00 00 00 00 00 00 00 00 00 00 00 00"  // grid (6 floats, at 8)
                      "00 00 00 01 00 01 00 02");  // pairs: count, {1, 2}
  auto kd = horus::cdr::decode<wiretest::Keywords>(kb, false);
  ASSERT_TRUE(kd) << kd.error();
  EXPECT_EQ(*kd, k);
}

TEST(Cdr, EveryTruncationIsAnErrorNamingAField) {
  const auto bytes = hex(kAllBytes);
  for (std::size_t n = 0; n + 3 < bytes.size(); ++n) {  // up to 3 bytes short could be padding
    auto m = horus::cdr::decode<wiretest::All>(std::span(bytes.data(), n));
    ASSERT_FALSE(m) << "decoded from " << n << " of " << bytes.size() << " bytes";
    EXPECT_NE(m.error().find("wiretest::All."), std::string::npos) << m.error();
  }
}

TEST(Cdr, RefusesCorruptValuesWithTheFieldNamed) {
  auto bad_bool = hex(kAllBytes);
  bad_bool[0] = std::byte{2};
  auto m = horus::cdr::decode<wiretest::All>(bad_bool);
  ASSERT_FALSE(m);
  EXPECT_NE(m.error().find("wiretest::All.flag: bool byte 2"), std::string::npos) << m.error();

  auto bad_enum = hex(kAllBytes);
  bad_enum[40] = std::byte{3};  // Mode has 3 enumerators
  m = horus::cdr::decode<wiretest::All>(bad_enum);
  ASSERT_FALSE(m);
  EXPECT_NE(m.error().find("wiretest::All.mode: enum value 3, expected 0..2"), std::string::npos) << m.error();

  auto huge_count = hex(kAllBytes);
  huge_count[64] = std::byte{0xff};
  huge_count[65] = std::byte{0xff};
  huge_count[66] = std::byte{0xff};
  huge_count[67] = std::byte{0x7f};
  m = horus::cdr::decode<wiretest::All>(huge_count);
  ASSERT_FALSE(m);
  EXPECT_NE(m.error().find("wiretest::All.values: count 2147483647"), std::string::npos) << m.error();

  auto no_nul = hex(kAllBytes);
  no_nul[62] = std::byte{'!'};  // "hi" loses its terminator
  m = horus::cdr::decode<wiretest::All>(no_nul);
  ASSERT_FALSE(m);
  EXPECT_NE(m.error().find("wiretest::All.text: a string of 3 bytes without its NUL"), std::string::npos) << m.error();
}

TEST(Cdr, AcceptsPaddingButNotALongerSample) {
  auto bytes = hex(kAllBytes);
  bytes.insert(bytes.end(), 3, std::byte{0});
  EXPECT_TRUE(horus::cdr::decode<wiretest::All>(bytes));
  bytes.push_back(std::byte{0});
  auto m = horus::cdr::decode<wiretest::All>(bytes);
  ASSERT_FALSE(m);
  EXPECT_NE(m.error().find("4 bytes left over"), std::string::npos) << m.error();
}

TEST(Cdr, ATooSmallBufferThrowsInsteadOfWritingPastIt) {
  const auto m = all_sample();
  std::vector<std::byte> out(horus::cdr::encoded_size(m) - 1);
  EXPECT_THROW(horus::cdr::encode(m, std::span<std::byte>(out)), std::length_error);
}

}  // namespace
