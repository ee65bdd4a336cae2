// The LCM codec and the .lcm emitter: exact bytes for every construct (what lcm-gen programs
// read and write), lcm-gen's fingerprints, corrupt or truncated messages refused with the field
// named, and the emitted types. The interop test (tests/interop) checks the same against code
// that lcm-gen generates.
#include <gtest/gtest.h>

#include <cstring>
#include <string>
#include <vector>

#include "horus/idlgen/emit.hpp"
#include "horus/wire/lcm.hpp"
#include "horus/msg/all.hpp"
#include "wire_test_support.hpp"

namespace lcmtest {

// lcm-gen 1.3.1 hashes of small types (their _get_hash(), printed by generated C code).
struct InnerT {  // struct inner_t { int32_t a; double b[2]; }
  std::int32_t a{};
  std::array<double, 2> b{};
};
HORUS_REFLECT(InnerT, a, b)
struct DecT {  // struct dec_t { int32_t a[16]; }
  std::array<std::int32_t, 16> a{};
};
HORUS_REFLECT(DecT, a)

// Names lcm-gen would pass through into code that does not compile.
struct Names {
  std::int32_t encode{};
  bool in{};
  std::vector<std::int8_t> final;
  bool operator==(const Names&) const = default;
};
HORUS_REFLECT(Names, encode, in, final)

struct Clash {  // a vector `points` brings a member num_points
  std::vector<std::int32_t> points;
  std::int32_t num_points{};
};
HORUS_REFLECT(Clash, points, num_points)

struct Ragged {  // rows of different lengths: no LCM type
  std::vector<std::vector<float>> rows;
};
HORUS_REFLECT(Ragged, rows)

}  // namespace lcmtest

namespace {

using wiretest::all_sample;
using wiretest::hex;

std::vector<std::byte> be64(std::uint64_t v) {
  std::vector<std::byte> out;
  for (int s = 56; s >= 0; s -= 8) out.push_back(static_cast<std::byte>((v >> s) & 0xff));
  return out;
}

template <class T>
std::vector<std::byte> with_fingerprint(const std::string& body) {
  auto out = be64(horus::lcm::fingerprint<T>());
  const auto b = hex(body);
  out.insert(out.end(), b.begin(), b.end());
  return out;
}

// Big-endian, no padding, no counts for fixed arrays, num_<field> before a variable array.
const std::string kAllBody =
    "01 78 fe 00001234 fffffffd 0102030405060708"     // flag c i8 u16(int32) i32 u64(int64)
    "3fc00000 4004000000000000 00000002 fffe"          // f d mode(int32) raw(int16)
    "61620000 0001 0002 0003"                          // name[4] shorts[3]
    "00000003 686900"                                  // text: length+1, bytes, NUL
    "00000001 3fe0000000000000"                        // num_values, values
    "00000001 07 3ff0000000000000"                     // num_inners, inners (a byte, b double)
    "00000002 00000002 6100 00000001 00"               // num_words, "a", ""
    "09 bff0000000000000";                             // inner

horus::idlgen::Model catalogue_model() {
  horus::idlgen::Model model;
  horus::msg::for_each_message([&]<class T>(std::string_view domain) { model.add<T>(domain); });
  return model;
}

TEST(LcmCodec, FingerprintsAreLcmGens) {
  // The values lcm-gen 1.3.1 generates for the same member lists.
  static_assert(horus::lcm::fingerprint<lcmtest::InnerT>() == 0x739d11e41f328d10ULL);
  EXPECT_EQ(horus::lcm::fingerprint<lcmtest::DecT>(), 0xbb3b93e0584eeeebULL);
  // The hash follows the members, not the type's name: Point3 and Vector3 are alike.
  EXPECT_EQ(horus::lcm::fingerprint<horus::msg::Point3>(), horus::lcm::fingerprint<horus::msg::Vector3>());
  EXPECT_NE(horus::lcm::fingerprint<horus::msg::Point3>(), horus::lcm::fingerprint<horus::msg::Quaternion>());
}

TEST(LcmCodec, EncodesEveryConstructAsLcmGenDoes) {
  const auto bytes = horus::lcm::encode(all_sample());
  EXPECT_EQ(bytes, with_fingerprint<wiretest::All>(kAllBody));
  EXPECT_EQ(horus::lcm::encoded_size(all_sample()), bytes.size());
  auto back = horus::lcm::decode<wiretest::All>(bytes);
  ASSERT_TRUE(back) << back.error();
  EXPECT_EQ(*back, all_sample());
}

TEST(LcmCodec, EncodesNestedArraysAndWidths) {
  wiretest::Keywords k;
  k.map = 1;
  k.keywords = 2;
  k.grid = {{{1.0f, 2.0f}, {3.0f, 4.0f}, {5.0f, 6.0f}}};
  k.pairs = {{7, 65535}};
  EXPECT_EQ(horus::lcm::encode(k),
            with_fingerprint<wiretest::Keywords>("00000001 02"
                                                 "3f800000 40000000 40400000 40800000 40a00000 40c00000"
                                                 "00000001 00000007 0000ffff"));
  wiretest::Widths w;
  w.i64 = -1;
  w.u32 = 0xfffffffe;
  w.i16 = -2;
  w.u8 = 0xab;
  w.bytes = {1, 2};
  w.longs = {3};
  w.flags = {true, false, true};
  EXPECT_EQ(horus::lcm::encode(w),
            with_fingerprint<wiretest::Widths>("ffffffffffffffff 00000000fffffffe fffe ab"
                                               "00000002 0102 00000001 0000000000000003 010001"));
  auto back = horus::lcm::decode<wiretest::Widths>(horus::lcm::encode(w));
  ASSERT_TRUE(back) << back.error();
  EXPECT_EQ(*back, w);
}

TEST(LcmCodec, RefusesAnotherFingerprint) {
  auto bytes = horus::lcm::encode(horus::msg::Pose2D{});
  auto as_other = horus::lcm::decode<horus::msg::CmdVel>(bytes);
  ASSERT_FALSE(as_other);
  EXPECT_NE(as_other.error().find("fingerprint"), std::string::npos) << as_other.error();
  EXPECT_NE(as_other.error().find("horus::msg::CmdVel"), std::string::npos) << as_other.error();
  auto empty = horus::lcm::decode<horus::msg::CmdVel>({});
  ASSERT_FALSE(empty);
  EXPECT_NE(empty.error().find("shorter than the 8-byte fingerprint"), std::string::npos) << empty.error();
}

// Decoding a corrupted copy of the All sample fails, naming the field.
void expect_refused(std::string body, const std::string& field, const std::string& what) {
  const auto bytes = with_fingerprint<wiretest::All>(body);
  auto m = horus::lcm::decode<wiretest::All>(bytes);
  ASSERT_FALSE(m) << "decoded a corrupt message (" << what << ")";
  EXPECT_NE(m.error().find(field), std::string::npos) << m.error();
  EXPECT_NE(m.error().find(what), std::string::npos) << m.error();
}

std::string replaced(std::string s, const std::string& from, const std::string& to) {
  const auto pos = s.find(from);
  EXPECT_NE(pos, std::string::npos) << from;
  return s.replace(pos, from.size(), to);
}

TEST(LcmCodec, RefusesCorruptMessagesNamingTheField) {
  expect_refused(replaced(kAllBody, "00001234", "00011234"), "wiretest::All.u16", "out of range");
  expect_refused(replaced(kAllBody, "00000002 fffe", "00000003 fffe"), "wiretest::All.mode", "enum value 3");
  expect_refused(replaced(kAllBody, "00000003 686900", "00000003 686921"), "wiretest::All.text", "NUL");
  expect_refused(replaced(kAllBody, "00000003 686900", "00000000 686900"), "wiretest::All.text", "length 0");
  expect_refused(replaced(kAllBody, "00000001 3fe0", "ffffffff 3fe0"), "wiretest::All.values", "negative");
  expect_refused(replaced(kAllBody, "00000001 3fe0", "7fffffff 3fe0"), "wiretest::All.values", "remain");
  expect_refused(kAllBody + "00", "wiretest::All", "left over");
  // u64 keeps its bits; u32 widened to int64 must fit.
  wiretest::Widths w;
  auto bytes = horus::lcm::encode(w);
  bytes[8 + 8 + 3] = std::byte{1};  // u32 = 2^32
  auto m = horus::lcm::decode<wiretest::Widths>(bytes);
  ASSERT_FALSE(m);
  EXPECT_NE(m.error().find("wiretest::Widths.u32"), std::string::npos) << m.error();
}

TEST(LcmCodec, EmptyArraysAndStringsRoundTrip) {
  const wiretest::Widths w{};  // empty vectors: nothing to copy (and no null pointer handed to memcpy)
  auto back = horus::lcm::decode<wiretest::Widths>(horus::lcm::encode(w));
  ASSERT_TRUE(back) << back.error();
  EXPECT_EQ(*back, w);
  const wiretest::All a{};
  auto all = horus::lcm::decode<wiretest::All>(horus::lcm::encode(a));
  ASSERT_TRUE(all) << all.error();
  EXPECT_EQ(*all, a);
}

TEST(LcmCodec, RefusesAStringWithANulInside) {
  // "h\0" (length 3): lcm-gen's C and C++ would read "h"; horus refuses it rather than differ.
  expect_refused(replaced(kAllBody, "00000003 686900", "00000003 680000"), "wiretest::All.text", "NUL byte inside");
}

TEST(LcmCodec, RefusesEveryTruncationOfEveryConstruct) {
  const auto bytes = horus::lcm::encode(all_sample());
  for (std::size_t n = 0; n < bytes.size(); ++n)
    EXPECT_FALSE(horus::lcm::decode<wiretest::All>(std::span(bytes.data(), n))) << "decoded from " << n << " bytes";
}

TEST(LcmCodec, BooleanBytesOtherThanZeroReadAsTrue) {
  auto bytes = horus::lcm::encode(all_sample());
  bytes[8] = std::byte{0x7f};  // flag: a C program stores booleans in an int8_t
  auto m = horus::lcm::decode<wiretest::All>(bytes);
  ASSERT_TRUE(m) << m.error();
  EXPECT_TRUE(m->flag);
}

TEST(LcmCodec, RefusesToEncodeAStringWithANulInside) {
  auto m = all_sample();
  m.text = std::string("a\0b", 3);
  EXPECT_THROW((void)horus::lcm::encoded_size(m), std::invalid_argument);
}

TEST(LcmCodec, KnowsWhatLcmCannotExpress) {
  static_assert(horus::lcm::expressible<wiretest::All>);
  static_assert(!horus::lcm::expressible<lcmtest::Ragged>);
  horus::msg::for_each_message([]<class T>(std::string_view) {
    static_assert(horus::lcm::expressible<T>, "every catalogue message travels over LCM");
  });
}

TEST(LcmEmitter, EmitsPackagesConstantsLengthsAndWidenedTypes) {
  horus::idlgen::Model model;
  model.add<wiretest::All>("wiretest");
  model.add<wiretest::Keywords>("wiretest");
  model.add<wiretest::Widths>("wiretest");
  const auto files = horus::idlgen::emit_lcm(model);
  ASSERT_EQ(files.size(), 1u);
  EXPECT_EQ(files[0].name, "wiretest.lcm");
  const std::string& t = files[0].text;
  for (const char* line : {"package wiretest;", "struct Mode\n{\n    const int32_t Off = 0;\n    const int32_t On = 1;\n"
                                                "    const int32_t Auto = 2;\n}",
                           "struct All\n{\n    boolean flag;\n    byte c;", "    int8_t i8;", "    int32_t u16;",
                           "    int64_t u64;", "    int32_t mode;", "    int16_t raw;", "    byte name[4];",
                           "    int16_t shorts[3];", "    string text;", "    int32_t num_values;",
                           "    double values[num_values];", "    wiretest.Inner inners[num_inners];",
                           "    string words[num_words];", "    wiretest.Inner inner;", "    float grid[3][2];",
                           "    int32_t pairs[num_pairs][2];", "    int64_t u32;", "    boolean flags[3];"})
    EXPECT_NE(t.find(line), std::string::npos) << "missing: " << line << "\n" << t;
  EXPECT_EQ(t.find("\n    uint"), std::string::npos) << "LCM has no unsigned types\n" << t;
}

TEST(LcmEmitter, EscapesNamesThatGeneratedCodeCannotUse) {
  horus::idlgen::Model model;
  model.add<lcmtest::Names>("names");
  const std::string t = horus::idlgen::emit_lcm(model)[0].text;
  for (const char* line : {"    int32_t encode_;", "    boolean in_;", "    int32_t num_final;",
                           "    int8_t final_[num_final];"})
    EXPECT_NE(t.find(line), std::string::npos) << "missing: " << line << "\n" << t;
  // The codec hashes the same names.
  EXPECT_EQ(horus::idlgen::lcm_fingerprint(model, "lcmtest::Names"), horus::lcm::fingerprint<lcmtest::Names>());
}

// Left out of the .lcm file with a comment naming the field (the .idl still has them, so a
// DDS-only project with such a type still builds).
TEST(LcmEmitter, LeavesOutWhatLcmCannotExpressNamingTheField) {
  horus::idlgen::Model model;
  model.add<lcmtest::Clash>("odd");
  model.add<lcmtest::Ragged>("odd");
  model.add<lcmtest::DecT>("odd");
  const std::string t = horus::idlgen::emit_lcm(model)[0].text;
  EXPECT_NE(t.find("// no LCM type: lcmtest::Clash has two LCM members named 'num_points'"), std::string::npos) << t;
  EXPECT_NE(t.find("// no LCM type: lcmtest::Ragged.rows: a variable-size array inside an array"), std::string::npos)
      << t;
  EXPECT_EQ(t.find("struct Clash"), std::string::npos) << t;
  EXPECT_EQ(t.find("struct Ragged"), std::string::npos) << t;
  EXPECT_NE(t.find("struct DecT"), std::string::npos) << t;
  EXPECT_EQ(horus::idlgen::lcm_definitions(model).size(), 1u);
  EXPECT_EQ(horus::idlgen::emit_idl(model).size(), 1u);  // DDS keeps them
}

TEST(LcmEmitter, FingerprintsMatchTheCodecForEveryMessage) {
  const auto model = catalogue_model();
  std::size_t n = 0;
  horus::msg::for_each_message([&]<class T>(std::string_view) {
    EXPECT_EQ(horus::idlgen::lcm_fingerprint(model, horus::type_name<T>()), horus::lcm::fingerprint<T>())
        << horus::type_name<T>();
    ++n;
  });
  EXPECT_GT(n, 70u);
  horus::idlgen::Model wire;
  wire.add<wiretest::All>("w");
  wire.add<wiretest::Keywords>("w");
  wire.add<wiretest::Widths>("w");
  EXPECT_EQ(horus::idlgen::lcm_fingerprint(wire, "wiretest::All"), horus::lcm::fingerprint<wiretest::All>());
  EXPECT_EQ(horus::idlgen::lcm_fingerprint(wire, "wiretest::Keywords"), horus::lcm::fingerprint<wiretest::Keywords>());
  EXPECT_EQ(horus::idlgen::lcm_fingerprint(wire, "wiretest::Widths"), horus::lcm::fingerprint<wiretest::Widths>());
}

}  // namespace
