// Decoding without the C++ type, from the type signature a topic announces
// (horus/wire/dynamic.hpp): the same JSON as to_json for every standard message and every
// wire construct, in XCDR1 and LCM; corrupt bytes refused exactly when the typed decoders
// refuse them; malformed signatures refused with the offset named.
#include <gtest/gtest.h>

#include <random>
#include <string>
#include <vector>

#include "horus/json.hpp"
#include "horus/wire/dynamic.hpp"
#include "horus/wire/lcm.hpp"
#include "horus/wire/xcdr1.hpp"
#include "message_trips.hpp"
#include "wire_test_support.hpp"

namespace {

using horus::wire::decode_json;
using horus::wire::DynFormat;
using horus::wire::DynType;
using horus::wire::parse_signature;

TEST(DynamicDecode, EveryStandardMessageAndWireConstructDecodesFromItsSignatureAsToJson) {
  std::size_t checked = 0;
  for (const auto& t : horus_test::standard_and_wire_test_types()) {
    const std::string failure = t.dynamic_check();
    EXPECT_TRUE(failure.empty()) << t.name << ": " << failure;
    ++checked;
  }
  EXPECT_EQ(checked, 81U + 3U);
}

TEST(DynamicDecode, ParsesEveryConstructOfASignature) {
  const std::string sig = horus::reflect::type_signature<wiretest::All>();
  auto t = parse_signature(sig, horus::type_hash<wiretest::All>);
  ASSERT_TRUE(t) << t.error();
  EXPECT_EQ(t->kind, DynType::Kind::Struct);
  EXPECT_EQ(t->name, "wiretest::All");
  ASSERT_EQ(t->field_names.size(), 17U);
  EXPECT_EQ(t->field_names[8], "mode");
  const DynType& mode = t->children[8];
  EXPECT_EQ(mode.kind, DynType::Kind::Enum);
  EXPECT_EQ(mode.name, "wiretest::Mode");
  EXPECT_TRUE(mode.idl_enum());
  ASSERT_EQ(mode.enumerators.size(), 3U);
  EXPECT_EQ(mode.enumerators[2].first, "Auto");
  const DynType& raw = t->children[9];
  EXPECT_FALSE(raw.idl_enum());  // a plain enum: its integer
  EXPECT_EQ(raw.size, 2);
  EXPECT_TRUE(raw.is_signed);
  EXPECT_TRUE(t->children[10].char_array());
  EXPECT_EQ(t->children[10].length, 4U);
  EXPECT_EQ(t->children[13].kind, DynType::Kind::Sequence);
  EXPECT_EQ(t->children[13].children[0].kind, DynType::Kind::Float);
  EXPECT_EQ(t->children[14].children[0].kind, DynType::Kind::Struct);
  EXPECT_EQ(t->children[16].kind, DynType::Kind::Struct);
  EXPECT_EQ(t->children[16].name, "wiretest::Inner");
  // Names GCC gives types in anonymous namespaces and templates parse too.
  auto anon = parse_signature("{anonymous}::Local<int, 3>{u8 a;[enum {anonymous}::E:i8{A=-1;B=2;};2] e;}");
  ASSERT_TRUE(anon) << anon.error();
  EXPECT_EQ(anon->name, "{anonymous}::Local<int, 3>");
  EXPECT_EQ(anon->children[1].children[0].name, "{anonymous}::E");
  EXPECT_EQ(anon->children[1].children[0].enumerators[0].second, -1);
}

TEST(DynamicDecode, RefusesMalformedSignaturesNamingTheOffset) {
  const std::string good = horus::reflect::type_signature<wiretest::Inner>();
  auto hash = parse_signature(good, horus::type_hash<wiretest::Inner> + 1);
  ASSERT_FALSE(hash);
  EXPECT_NE(hash.error().find("does not match its type hash"), std::string::npos) << hash.error();
  const std::vector<std::pair<std::string, std::string>> bad = {
      {"", "expected a type name"},
      {"X{u8 a}", "expected ';'"},
      {"X{u8 a;", "expected '}'"},
      {"X{q8 a;}", "expected '{'"},
      {"X{u8 a;u8 a;}", "appears twice"},
      {"X{[u8;] a;}", "expected a number"},
      {"X{[u8;99999999999999999999] a;}", "too large"},
      {"X{[u8;5000000000] a;}", "more than 2^32"},
      {"X{seq<u8 a;}", "expected '>'"},
      {"X{enum E:f32 a;}", "integer type"},
      {"X{enum E:u8{A=1} a;}", "expected ';'"},
      {"X{u8 a;}junk", "text after the type"},
      {"u8", "not a struct"},
      {std::string(40, '[') + "u8;1]", "nesting deeper"},
  };
  for (const auto& [text, why] : bad) {
    auto r = parse_signature(text);
    ASSERT_FALSE(r) << text;
    EXPECT_NE(r.error().find(why), std::string::npos) << text << " -> " << r.error();
    if (why != "not a struct") {
      EXPECT_NE(r.error().find("offset"), std::string::npos) << r.error();
    }
  }
}

TEST(DynamicDecode, ReadsBigEndianXcdr1) {
  // Inner{a = 7, b = 1.0} written big endian: a, 7 bytes of padding, then b.
  auto t = parse_signature(horus::reflect::type_signature<wiretest::Inner>());
  ASSERT_TRUE(t);
  const auto be = wiretest::hex("07 00 00 00 00 00 00 00 3f f0 00 00 00 00 00 00");
  auto j = decode_json(*t, DynFormat::Xcdr1, be, /*little_endian=*/false);
  ASSERT_TRUE(j) << j.error();
  EXPECT_EQ(*j, horus::to_json(wiretest::Inner{7, 1.0}));
}

// Random corruption of every construct: the dynamic decoder accepts exactly what the typed
// one accepts, and then renders the same JSON.
template <class T, class Typed>
void fuzz_against_typed(DynFormat format, std::vector<std::byte> bytes, const Typed& typed) {
  auto t = parse_signature(horus::reflect::type_signature<T>(), horus::type_hash<T>);
  ASSERT_TRUE(t) << t.error();
  std::mt19937 rng(7);
  int both_ok = 0;
  for (int round = 0; round < 3000; ++round) {
    auto b = bytes;
    const int flips = 1 + static_cast<int>(rng() % 3);
    for (int i = 0; i < flips; ++i) b[rng() % b.size()] = static_cast<std::byte>(rng());
    if (rng() % 8 == 0) b.resize(rng() % b.size());
    const auto want = typed(std::span<const std::byte>(b));
    const auto got = decode_json(*t, format, b, true);
    ASSERT_EQ(want.has_value(), got.has_value())
        << "round " << round << ": typed " << (want ? "ok" : want.error()) << " / dynamic "
        << (got ? "ok" : got.error());
    if (want) {
      ASSERT_EQ(*got, horus::to_json(*want)) << "round " << round;
      ++both_ok;
    } else {
      EXPECT_NE(got.error().find(std::string(horus::type_name<T>())), std::string::npos) << got.error();
    }
  }
  EXPECT_GT(both_ok, 0);  // some corruptions still decode (a changed number): compared too
}

TEST(DynamicDecode, CorruptXcdr1IsRefusedExactlyWhenTheTypedDecoderRefusesIt) {
  fuzz_against_typed<wiretest::All>(DynFormat::Xcdr1, horus::cdr::encode(wiretest::all_sample()),
                                    [](std::span<const std::byte> b) { return horus::cdr::decode<wiretest::All>(b); });
}

TEST(DynamicDecode, CorruptLcmIsRefusedExactlyWhenTheTypedDecoderRefusesIt) {
  auto bytes = horus::lcm::encode(wiretest::all_sample());
  // Keep the fingerprint intact: the dynamic decoder trusts the announced type instead.
  auto t = parse_signature(horus::reflect::type_signature<wiretest::All>());
  ASSERT_TRUE(t);
  std::mt19937 rng(11);
  for (int round = 0; round < 3000; ++round) {
    auto b = bytes;
    b[8 + rng() % (b.size() - 8)] = static_cast<std::byte>(rng());
    if (rng() % 8 == 0) b.resize(8 + rng() % (b.size() - 8));
    const auto want = horus::lcm::decode<wiretest::All>(b);
    const auto got = decode_json(*t, DynFormat::Lcm, b);
    ASSERT_EQ(want.has_value(), got.has_value())
        << "round " << round << ": typed " << (want ? "ok" : want.error()) << " / dynamic "
        << (got ? "ok" : got.error());
    if (want) {
      ASSERT_EQ(*got, horus::to_json(*want));
    }
  }
}

TEST(DynamicDecode, AVectorOfVectorsIsNotExpressibleInLcm) {
  auto t = parse_signature("X{seq<seq<u8>> rows;}");
  ASSERT_TRUE(t);
  auto why = horus::wire::check_expressible(*t, DynFormat::Lcm);
  ASSERT_FALSE(why);
  EXPECT_NE(why.error().find("X.rows"), std::string::npos) << why.error();
  EXPECT_TRUE(horus::wire::check_expressible(*t, DynFormat::Xcdr1));
  const auto bytes = wiretest::hex("00 00 00 00 00 00 00 00 00 00 00 00");
  EXPECT_FALSE(decode_json(*t, DynFormat::Lcm, bytes));
}

}  // namespace
