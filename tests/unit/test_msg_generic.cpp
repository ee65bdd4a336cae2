// Unit tests of GenericMessage (horus/msg/generic.hpp, generic_value.hpp): inline and overflow
// buffers, metadata, from_value/to_value through msgpack-cxx, log_summary()'s own MessagePack
// reader, layout and corrupt received values.
#include <gtest/gtest.h>

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <map>
#include <optional>
#include <span>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>

#include <fmt/format.h>

#include "horus/json.hpp"
#include "horus/msg/detail/msgpack_text.hpp"
#include "horus/msg/generic.hpp"
#include "horus/msg/generic_value.hpp"
#include "message_test_support.hpp"

// A user type carried by GenericMessage (packed as a MessagePack array).
namespace app {
struct SensorReading {
  double temperature{};
  double humidity{};
  std::string label;
  std::vector<int> history;
  MSGPACK_DEFINE(temperature, humidity, label, history)
  friend bool operator==(const SensorReading&, const SensorReading&) = default;
};
}  // namespace app

namespace {

using namespace horus_test::values;

using namespace horus::msg;

std::vector<std::uint8_t> pattern_bytes(std::size_t n) {
  std::vector<std::uint8_t> v(n);
  for (std::size_t i = 0; i < n; ++i) v[i] = static_cast<std::uint8_t>((i * 7 + 3) & 0xFF);
  return v;
}


// ===========================================================================
// GenericMessage

TEST(GenericMessage, TwoHundredFiftySixBytesStayInline) {
  const auto bytes = pattern_bytes(256);
  const auto m = GenericMessage::make(bytes);
  ASSERT_TRUE(m.has_value()) << m.error();
  EXPECT_TRUE(m->is_inline());
  EXPECT_EQ(m->size(), 256u);
  EXPECT_EQ(m->data(), bytes);
  EXPECT_EQ(horus::to_json(*m)["inline_len"], 256);
  EXPECT_EQ(horus::to_json(*m)["overflow_len"], 0);
}

TEST(GenericMessage, TwoHundredFiftySevenBytesUseTheOverflowBuffer) {
  const auto bytes = pattern_bytes(257);
  const auto m = GenericMessage::make(bytes);
  ASSERT_TRUE(m.has_value()) << m.error();
  EXPECT_FALSE(m->is_inline());
  EXPECT_EQ(m->size(), 257u);
  EXPECT_EQ(m->data(), bytes);
  const nlohmann::json j = horus::to_json(*m);
  EXPECT_EQ(j["inline_len"], 256);
  EXPECT_EQ(j["overflow_len"], 1);
  EXPECT_EQ(j["overflow_data"][0], bytes[256]);
}

TEST(GenericMessage, ExactlyFourKilobytesFitAndOneMoreIsRefused) {
  const auto max = pattern_bytes(4096);
  const auto m = GenericMessage::make(max);
  ASSERT_TRUE(m.has_value()) << m.error();
  EXPECT_EQ(m->size(), 4096u);
  EXPECT_EQ(m->data(), max);

  const auto over = GenericMessage::make(pattern_bytes(4097));
  ASSERT_FALSE(over.has_value());
  EXPECT_TRUE(contains(over.error(), "4097")) << over.error();
  EXPECT_TRUE(contains(over.error(), "4096")) << over.error();
}

TEST(GenericMessage, EmptyPayloadIsAllowedAndEqualsTheDefault) {
  const auto m = GenericMessage::make({});
  ASSERT_TRUE(m.has_value());
  EXPECT_TRUE(m->empty());
  EXPECT_EQ(*m, GenericMessage{});
  EXPECT_EQ(m->metadata(), std::nullopt);
}

TEST(GenericMessage, MetadataUpTo255BytesOfUtf8) {
  const auto bytes = pattern_bytes(10);
  const auto m = GenericMessage::with_metadata(bytes, "imu/raw");
  ASSERT_TRUE(m.has_value()) << m.error();
  EXPECT_EQ(m->metadata(), "imu/raw");
  EXPECT_EQ(m->data(), bytes);

  const std::string max(255, 'm');
  EXPECT_EQ(GenericMessage::with_metadata(bytes, max)->metadata(), max);
  const auto too_long = GenericMessage::with_metadata(bytes, std::string(256, 'm'));
  ASSERT_FALSE(too_long.has_value());
  EXPECT_TRUE(contains(too_long.error(), "256")) << too_long.error();
  EXPECT_TRUE(contains(too_long.error(), "255")) << too_long.error();

  EXPECT_FALSE(GenericMessage::with_metadata(bytes, std::string("a\0b", 3)).has_value());
  EXPECT_FALSE(GenericMessage::with_metadata(bytes, "bad \xC3(").has_value());
  EXPECT_FALSE(GenericMessage::with_metadata(bytes, "cut \xE2\x82").has_value());
  EXPECT_FALSE(GenericMessage::with_metadata(bytes, "surrogate \xED\xA0\x80").has_value());
  EXPECT_FALSE(GenericMessage::with_metadata(bytes, "overlong \xC0\xAF").has_value());
  EXPECT_FALSE(GenericMessage::with_metadata(bytes, "too high \xF4\x90\x80\x80").has_value());
  const auto not_utf8 = GenericMessage::with_metadata(bytes, "ab\xFF");
  ASSERT_FALSE(not_utf8.has_value());
  EXPECT_TRUE(contains(not_utf8.error(), "UTF-8 (at byte 2)")) << not_utf8.error();
  const std::string_view utf8 = "caf\xC3\xA9 \xF0\x9F\xA4\x96";  // 2- and 4-byte characters
  EXPECT_EQ(GenericMessage::with_metadata(bytes, utf8)->metadata(), utf8);
  // The payload limit applies too.
  const auto big = GenericMessage::with_metadata(pattern_bytes(5000), "ok");
  ASSERT_FALSE(big.has_value());
  EXPECT_TRUE(contains(big.error(), "5000")) << big.error();
}

TEST(GenericMessage, SetMetadataRefusesBadTextAndEmptyClears) {
  GenericMessage m = *GenericMessage::with_metadata(pattern_bytes(3), "first");
  EXPECT_FALSE(m.set_metadata(std::string(256, 'x')));
  EXPECT_EQ(m.metadata(), "first");
  EXPECT_TRUE(m.set_metadata("second"));
  EXPECT_EQ(m.metadata(), "second");
  EXPECT_TRUE(m.set_metadata(""));
  EXPECT_EQ(m.metadata(), std::nullopt);
  EXPECT_EQ(m, *GenericMessage::make(pattern_bytes(3)));
}

TEST(GenericMessage, FromValueRoundTripsBuiltInTypes) {
  const auto i = GenericMessage::from_value(-123456789);
  ASSERT_TRUE(i.has_value());
  EXPECT_EQ(i->to_value<int>(), -123456789);

  const auto s = GenericMessage::from_value(std::string("hello"));
  ASSERT_TRUE(s.has_value());
  EXPECT_EQ(s->to_value<std::string>(), "hello");
  EXPECT_EQ(s->data(), (std::vector<std::uint8_t>{0xA5, 'h', 'e', 'l', 'l', 'o'}));  // fixstr, as any MessagePack peer

  const std::vector<double> v{1.5, -2.25, 1e300};
  EXPECT_EQ(GenericMessage::from_value(v)->to_value<std::vector<double>>(), v);

  const std::map<std::string, double> map{{"x", 1.0}, {"y", 2.0}};
  const auto mm = GenericMessage::from_value(map);
  ASSERT_TRUE(mm.has_value());
  EXPECT_EQ((mm->to_value<std::map<std::string, double>>()), map);
}

TEST(GenericMessage, UserStructWithMsgpackDefineRoundTrips) {
  const app::SensorReading r{22.5, 60.0, "greenhouse", {1, 2, 3}};
  const auto m = GenericMessage::from_value(r);
  ASSERT_TRUE(m.has_value()) << m.error();
  const auto back = m->to_value<app::SensorReading>();
  ASSERT_TRUE(back.has_value()) << back.error();
  EXPECT_EQ(*back, r);
}

TEST(GenericMessage, FromValueRefusesEncodingsOverFourKilobytes) {
  // str16 header (3 bytes) + 4093 characters = 4096 bytes: fits exactly.
  const auto exact = GenericMessage::from_value(std::string(4093, 's'));
  ASSERT_TRUE(exact.has_value()) << exact.error();
  EXPECT_EQ(exact->size(), 4096u);
  EXPECT_EQ(exact->to_value<std::string>(), std::string(4093, 's'));

  const auto over = GenericMessage::from_value(std::string(4094, 's'));
  ASSERT_FALSE(over.has_value());
  EXPECT_TRUE(contains(over.error(), "4097 bytes")) << over.error();
  EXPECT_TRUE(contains(over.error(), "4096")) << over.error();
}

TEST(GenericMessage, ToValueIntoTheWrongTypeIsAnError) {
  const auto m = GenericMessage::from_value(42);
  ASSERT_TRUE(m.has_value());
  const auto as_string = m->to_value<std::string>();
  ASSERT_FALSE(as_string.has_value());
  EXPECT_TRUE(contains(as_string.error(), "positive integer")) << as_string.error();
  EXPECT_TRUE(contains(as_string.error(), "to_value<")) << as_string.error();

  // An integer out of the target's range is an error too, not a wrap-around.
  EXPECT_FALSE(GenericMessage::from_value(300)->to_value<std::uint8_t>().has_value());
  EXPECT_EQ(GenericMessage::from_value(200)->to_value<std::uint8_t>(), 200);
  // A map is not a vector.
  EXPECT_FALSE(GenericMessage::from_value(std::map<std::string, int>{{"a", 1}})->to_value<std::vector<int>>());
  // A struct's fields must have the right types: a text where temperature should be.
  const auto wrong_field = GenericMessage::from_value(std::vector<std::string>{"warm", "humid"});
  ASSERT_TRUE(wrong_field.has_value());
  EXPECT_FALSE(wrong_field->to_value<app::SensorReading>().has_value());
}

// A container header that claims more elements than the payload holds (found by fuzz_local: a
// map of 2^32 entries in 5 bytes made msgpack allocate 64 GiB) is an error, not an allocation.
TEST(GenericMessage, AContainerClaimingMoreThanThePayloadHoldsIsAnError) {
  for (const std::vector<std::uint8_t>& bytes :
       {std::vector<std::uint8_t>{0xdf, 0xff, 0xff, 0xff, 0xff}, std::vector<std::uint8_t>{0xdd, 0x10, 0, 0, 0, 1},
        std::vector<std::uint8_t>{0xdb, 0x7f, 0xff, 0xff, 0xff, 'a'}}) {
    const auto m = GenericMessage::make(bytes);
    ASSERT_TRUE(m.has_value());
    const auto v = m->to_value<std::map<std::string, std::string>>();
    ASSERT_FALSE(v.has_value());
    EXPECT_TRUE(contains(v.error(), "is not valid MessagePack")) << v.error();
    if (bytes.size() == 5) {
      EXPECT_TRUE(contains(v.error(), "claims more than the payload holds")) << v.error();
    }
  }
}

// log_summary() prints a payload with a reader of its own (msgpack-cxx stays out of the headers
// most files include): the text is msgpack-cxx's for every kind of value, and what msgpack-cxx
// would refuse (or allocate for) is refused without allocating.
struct SummaryMix {
  std::map<std::string, std::vector<double>> series{{"a/b", {1.5, -0.25, 1e20}}, {"q\"\\\n\x01\x7f", {}}};
  std::vector<std::int64_t> ints{0, 127, 128, -1, -32, -33, -129, 65536, -2147483649LL, 9007199254740993LL};
  std::uint64_t big = 18446744073709551615ULL;
  float f = 0.1f;
  bool yes = true, no = false;
  std::optional<int> none;
  std::string text = std::string(300, 'x');
  MSGPACK_DEFINE(series, ints, big, f, yes, no, none, text)
};

TEST(GenericMessage, TheSummarysOwnReaderPrintsWhatMsgpackPrintsAndRefusesWhatItRefuses) {
  msgpack::sbuffer buf;
  msgpack::pack(buf, SummaryMix{});
  // Binaries and extensions, each size class.
  msgpack::packer<msgpack::sbuffer> pk(buf);
  for (std::size_t n : {std::size_t{3}, std::size_t{300}}) {
    pk.pack_bin(static_cast<std::uint32_t>(n));
    pk.pack_bin_body(std::string(n, 'b').data(), static_cast<std::uint32_t>(n));
  }
  for (std::size_t n : {std::size_t{1}, std::size_t{4}, std::size_t{5}, std::size_t{300}}) {
    pk.pack_ext(n, -3);
    pk.pack_ext_body(std::string(n, 'e').data(), static_cast<std::uint32_t>(n));
  }
  std::vector<std::uint8_t> all(reinterpret_cast<const std::uint8_t*>(buf.data()),
                                reinterpret_cast<const std::uint8_t*>(buf.data()) + buf.size());
  // Each value alone, and then all of them (trailing values: not one value).
  std::size_t offset = 0;
  while (offset < all.size()) {
    const std::size_t start = offset;
    const auto h = msgpack::unpack(reinterpret_cast<const char*>(all.data()), all.size(), offset);
    std::ostringstream theirs;
    theirs << h.get();
    std::string ours;
    EXPECT_TRUE(horus::msg::detail::MsgpackText::write(std::span(all).subspan(start, offset - start), ours));
    EXPECT_EQ(ours, theirs.str());
  }
  std::string text;
  EXPECT_FALSE(horus::msg::detail::MsgpackText::write(all, text)) << "more than one value";
  // Cut short anywhere: refused.
  const std::size_t first = [&] {
    std::size_t o = 0;
    (void)msgpack::unpack(reinterpret_cast<const char*>(all.data()), all.size(), o);
    return o;
  }();
  for (std::size_t n = 0; n < first; ++n) {
    text.clear();
    EXPECT_FALSE(horus::msg::detail::MsgpackText::write(std::span(all).first(n), text)) << n << " bytes";
  }
  // Claims without the bytes (a map of 2^32 - 1 entries in 5 bytes), the unused byte, depth 65.
  std::vector<std::vector<std::uint8_t>> bad{{0xdf, 0xff, 0xff, 0xff, 0xff}, {0xdb, 0x7f, 0xff, 0xff, 0xff, 'a'}, {0xc1}};
  bad.emplace_back(65, std::uint8_t{0x91});
  bad.back().push_back(0x01);
  for (const auto& b : bad) {
    text.clear();
    EXPECT_FALSE(horus::msg::detail::MsgpackText::write(b, text)) << b.size() << " bytes";
  }
  std::vector<std::uint8_t> deep(63, std::uint8_t{0x91});
  deep.push_back(0x01);
  text.clear();
  EXPECT_TRUE(horus::msg::detail::MsgpackText::write(deep, text));
  EXPECT_EQ(text, std::string(63, '[') + "1" + std::string(63, ']'));
  EXPECT_EQ(GenericMessage::make(std::vector<std::uint8_t>{0xdf, 0xff, 0xff, 0xff, 0xff})->log_summary(),
            "GenericMessage(5 B, not MessagePack)");
}

TEST(GenericMessage, ToValueOfEmptyInvalidOrTrailingBytesIsAnError) {
  const auto empty = GenericMessage{}.to_value<int>();
  ASSERT_FALSE(empty.has_value());
  EXPECT_TRUE(contains(empty.error(), "empty")) << empty.error();

  const std::vector<std::uint8_t> never_used{0xC1};  // a byte MessagePack never uses
  const auto invalid = GenericMessage::make(never_used)->to_value<int>();
  ASSERT_FALSE(invalid.has_value());
  EXPECT_TRUE(contains(invalid.error(), "not valid MessagePack")) << invalid.error();

  const std::vector<std::uint8_t> truncated{0xA5, 'h', 'e'};  // fixstr of 5, only 2 bytes
  EXPECT_FALSE(GenericMessage::make(truncated)->to_value<std::string>().has_value());

  const std::vector<std::uint8_t> two_values{0x01, 0x02};
  const auto trailing = GenericMessage::make(two_values)->to_value<int>();
  ASSERT_FALSE(trailing.has_value());
  EXPECT_TRUE(contains(trailing.error(), "1 bytes follow")) << trailing.error();
}

TEST(GenericMessage, LogSummaryGivesSizeMetadataAndValue) {
  const std::map<std::string, int> map{{"x", 1}, {"y", 2}};
  auto m = *GenericMessage::from_value(map);
  EXPECT_EQ(m.log_summary(), fmt::format("GenericMessage({} B msgpack, value {{\"x\":1,\"y\":2}})", m.size()));
  ASSERT_TRUE(m.set_metadata("pose"));
  EXPECT_EQ(m.log_summary(),
            fmt::format("GenericMessage({} B msgpack, meta \"pose\", value {{\"x\":1,\"y\":2}})", m.size()));

  EXPECT_EQ(GenericMessage{}.log_summary(), "GenericMessage(0 B, empty)");
  const std::vector<std::uint8_t> never_used{0xC1, 0xC1};
  EXPECT_EQ(GenericMessage::make(never_used)->log_summary(), "GenericMessage(2 B, not MessagePack)");

  const auto payload = GenericMessage::from_value(std::vector<int>(1000, 7));
  ASSERT_TRUE(payload.has_value());
  const GenericMessage big = *GenericMessage::with_metadata(payload->data(), std::string(255, 'm'));
  const std::string line = big.log_summary();
  EXPECT_LT(line.size(), 200u) << line;
  EXPECT_TRUE(line.starts_with(fmt::format("GenericMessage({} B msgpack, meta \"", big.size()))) << line;
  EXPECT_TRUE(contains(line, "...\", value [7,7,7")) << line;
}

TEST(GenericMessage, LayoutMatchesHorusAndCopiesByMemcpy) {
  EXPECT_EQ(sizeof(GenericMessage), 4364u);
  static_assert(std::is_trivially_copyable_v<GenericMessage>);
  static_assert(std::is_standard_layout_v<GenericMessage>);
  const GenericMessage original = *GenericMessage::with_metadata(pattern_bytes(1000), "copy");
  GenericMessage copy{};
  std::memcpy(&copy, &original, sizeof copy);
  EXPECT_EQ(copy.data(), pattern_bytes(1000));
  EXPECT_EQ(copy.metadata(), "copy");
  EXPECT_EQ(copy, original);
}

TEST(GenericMessage, CorruptLengthsAreClampedToTheBuffers) {
  GenericMessage m = *GenericMessage::with_metadata(pattern_bytes(10), std::string(255, 'm'));
  nlohmann::json j = horus::to_json(m);
  j["inline_len"] = 60000;
  j["overflow_len"] = 4000000000u;
  j["metadata_len"] = 9999;
  const GenericMessage bad = horus::from_json<GenericMessage>(j);
  EXPECT_EQ(bad.size(), 4096u);
  EXPECT_EQ(bad.data().size(), 4096u);
  EXPECT_EQ(bad.metadata(), std::string(255, 'm'));
  EXPECT_LT(bad.log_summary().size(), 200u);
}

// A received message is not validated: metadata() checks the stored bytes.
TEST(GenericMessage, ReceivedMetadataThatIsNotUtf8IsNullopt) {
  const GenericMessage good = *GenericMessage::with_metadata(pattern_bytes(3), "imu");
  nlohmann::json j = horus::to_json(good);
  j["metadata"] = std::string("ab\xFF");  // a byte UTF-8 never uses
  j["metadata_len"] = 3;
  const GenericMessage bad = horus::from_json<GenericMessage>(j);
  EXPECT_EQ(bad.metadata(), std::nullopt);
  EXPECT_EQ(bad.data(), pattern_bytes(3));  // the payload is still readable

  j["metadata"] = std::string("caf\xC3");  // a 2-byte character cut off
  j["metadata_len"] = 4;
  EXPECT_EQ(horus::from_json<GenericMessage>(j).metadata(), std::nullopt);
  j["metadata"] = std::string("surrogate \xED\xA0\x80");
  j["metadata_len"] = 13;
  EXPECT_EQ(horus::from_json<GenericMessage>(j).metadata(), std::nullopt);

  // A length that cuts a valid text inside a character.
  j["metadata"] = std::string("caf\xC3\xA9");
  j["metadata_len"] = 4;
  EXPECT_EQ(horus::from_json<GenericMessage>(j).metadata(), std::nullopt);
  j["metadata_len"] = 5;
  EXPECT_EQ(horus::from_json<GenericMessage>(j).metadata(), "caf\xC3\xA9");
}

TEST(GenericMessage, ReceivedMetadataHoldingANulIsNullopt) {
  const GenericMessage good = *GenericMessage::with_metadata(pattern_bytes(3), "imu");
  nlohmann::json j = horus::to_json(good);
  j["metadata_len"] = 5;  // "imu" then two of the NUL padding bytes
  const GenericMessage bad = horus::from_json<GenericMessage>(j);
  EXPECT_EQ(bad.metadata(), std::nullopt);
  j["metadata_len"] = 3;
  EXPECT_EQ(horus::from_json<GenericMessage>(j).metadata(), "imu");
  // All-NUL metadata of any length is not text either.
  j["metadata"] = "";
  j["metadata_len"] = 9999;
  EXPECT_EQ(horus::from_json<GenericMessage>(j).metadata(), std::nullopt);
}

TEST(GenericMessage, LogSummaryLeavesOutMetadataThatIsNotText) {
  const GenericMessage good = *GenericMessage::from_value(7);
  nlohmann::json j = horus::to_json(good);
  j["metadata"] = std::string("ab\xFF\xFE");
  j["metadata_len"] = 4;
  const std::string line = horus::from_json<GenericMessage>(j).log_summary();
  EXPECT_EQ(line, "GenericMessage(1 B msgpack, meta not UTF-8 text (4 B), value 7)");
  EXPECT_EQ(detail::generic_utf8_error(line), std::string_view::npos);
}

}  // namespace
