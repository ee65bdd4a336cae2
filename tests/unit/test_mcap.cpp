// The MCAP writer and reader (record/): files round-trip with each compression, carry a summary
// whose statistics match, a file cut short reads back to its last complete chunk, and damaged
// files are clear errors naming the offset, never a crash. The same for LCM event logs
// (record/lcm_log), whose reader also takes files other programs wrote.
#include <gtest/gtest.h>

#include <unistd.h>

#include <array>
#include <cstring>
#include <fstream>
#include <random>
#include <string>
#include <vector>

#include "horus/record/lcm_log.hpp"
#include "horus/record/mcap.hpp"

namespace {

using horus::Errc;
namespace mcap = horus::mcap;

std::string temp_path(const std::string& tag) {
  return "/tmp/horus_test_mcap_" + std::to_string(::getpid()) + "_" + tag + ".mcap";
}

std::vector<std::byte> read_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::vector<char> c((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  std::vector<std::byte> out(c.size());
  if (!c.empty()) std::memcpy(out.data(), c.data(), c.size());
  return out;
}

void write_file(const std::string& path, std::span<const std::byte> bytes) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
}

std::vector<std::byte> payload(std::size_t n, std::uint32_t seed) {
  std::vector<std::byte> v(n);
  std::uint32_t x = seed * 2654435761u + 1;
  for (auto& b : v) {
    x ^= x << 13;
    x ^= x >> 17;
    x ^= x << 5;
    b = std::byte{static_cast<std::uint8_t>(x)};
  }
  return v;
}

struct Written {
  std::uint16_t channel;
  std::uint32_t sequence;
  std::uint64_t log_time, publish_time;
  std::vector<std::byte> data;
};

// Writes 2 schemas, 3 channels and `n` messages (sizes 0..3000 bytes, one of 1 MB) in chunks
// of about `chunk` bytes; returns what it wrote.
std::vector<Written> write_sample(const std::string& path, mcap::Compression c, int n, std::size_t chunk,
                                  bool close = true, std::unique_ptr<mcap::Writer>* keep = nullptr) {
  mcap::WriterOptions o;
  o.compression = c;
  o.chunk_size = chunk;
  o.profile = "horus-test";
  auto w = mcap::Writer::create(path, o);
  EXPECT_TRUE(w) << (w ? "" : w.error().message());
  if (!w) return {};
  const std::string idl = "module m { struct A { double x; }; };";
  const auto s1 = (*w)->add_schema("m::A", "omgidl", std::as_bytes(std::span(idl.data(), idl.size())));
  const auto s2 = (*w)->add_schema("m::B", "jsonschema", {});
  EXPECT_TRUE(s1 && s2);
  const auto c1 = (*w)->add_channel(*s1, "robot.pose", "cdr", {{"horus.type_hash", "0123456789abcdef"}, {"scope", "fleet"}});
  const auto c2 = (*w)->add_channel(*s2, "robot.log", "json");
  const auto c3 = (*w)->add_channel(0, "raw", "");
  EXPECT_TRUE(c1 && c2 && c3);
  std::vector<Written> out;
  const std::uint16_t ch[3] = {*c1, *c2, *c3};
  for (int i = 0; i < n; ++i) {
    const std::size_t size = i == n / 2 ? (1u << 20) : static_cast<std::size_t>((i * 37) % 3001);
    Written m{ch[i % 3], static_cast<std::uint32_t>(i), 1'700'000'000'000'000'000ULL + static_cast<std::uint64_t>(i) * 1000,
              1'700'000'000'000'000'000ULL + static_cast<std::uint64_t>(i) * 1000 - 7, payload(size, static_cast<std::uint32_t>(i))};
    EXPECT_TRUE((*w)->write(mcap::Message{m.channel, m.sequence, m.log_time, m.publish_time, m.data}));
    out.push_back(std::move(m));
  }
  if (close) {
    EXPECT_TRUE((*w)->close());
  } else if (keep != nullptr) {
    *keep = std::move(*w);
  }
  return out;
}

std::vector<Written> read_all(mcap::Reader& r, horus::Result<void>* status = nullptr) {
  std::vector<Written> got;
  auto ok = r.read_messages([&](const mcap::Channel& c, const mcap::Schema*, const mcap::Message& m) {
    EXPECT_EQ(c.id, m.channel_id);
    got.push_back({m.channel_id, m.sequence, m.log_time, m.publish_time, {m.data.begin(), m.data.end()}});
    return true;
  });
  if (status != nullptr) *status = ok;
  else EXPECT_TRUE(ok) << ok.error().message();
  return got;
}

class McapCompression : public ::testing::TestWithParam<mcap::Compression> {};

TEST_P(McapCompression, MessagesSchemasAndChannelsRoundTripWithASummary) {
  const auto path = temp_path("roundtrip" + std::string(mcap::to_string(GetParam())));
  const auto sent = write_sample(path, GetParam(), 600, 64 * 1024);
  auto r = mcap::Reader::open(path);
  ASSERT_TRUE(r) << r.error().message();
  EXPECT_EQ((*r)->profile(), "horus-test");
  EXPECT_EQ((*r)->library(), "horus");
  EXPECT_TRUE((*r)->has_summary());
  EXPECT_FALSE((*r)->truncated());
  // The summary alone (before any message is read) knows the schemas and channels.
  ASSERT_EQ((*r)->schemas().size(), 2u);
  ASSERT_EQ((*r)->channels().size(), 3u);
  EXPECT_EQ((*r)->schemas().at(1).name, "m::A");
  EXPECT_EQ((*r)->schemas().at(1).encoding, "omgidl");
  EXPECT_EQ((*r)->channels().at(1).topic, "robot.pose");
  EXPECT_EQ((*r)->channels().at(1).metadata.at("horus.type_hash"), "0123456789abcdef");
  EXPECT_EQ((*r)->channels().at(3).schema_id, 0);
  const auto stats = (*r)->statistics();
  ASSERT_TRUE(stats);
  EXPECT_EQ(stats->message_count, sent.size());
  EXPECT_EQ(stats->channel_count, 3u);
  EXPECT_EQ(stats->schema_count, 2u);
  EXPECT_GT(stats->chunk_count, 10u) << "64 KiB chunks for ~2 MB of messages";
  EXPECT_EQ(stats->message_start_time, sent.front().log_time);
  EXPECT_EQ(stats->message_end_time, sent.back().log_time);
  EXPECT_EQ(stats->channel_message_counts.at(1), 200u);
  const auto got = read_all(**r);
  ASSERT_EQ(got.size(), sent.size());
  for (std::size_t i = 0; i < got.size(); ++i) {
    EXPECT_EQ(got[i].channel, sent[i].channel) << i;
    EXPECT_EQ(got[i].sequence, sent[i].sequence) << i;
    EXPECT_EQ(got[i].log_time, sent[i].log_time) << i;
    EXPECT_EQ(got[i].publish_time, sent[i].publish_time) << i;
    EXPECT_TRUE(got[i].data == sent[i].data) << "message " << i << " of " << sent[i].data.size() << " bytes";
  }
  ::unlink(path.c_str());
}

INSTANTIATE_TEST_SUITE_P(All, McapCompression,
                         ::testing::Values(mcap::Compression::None, mcap::Compression::Zstd, mcap::Compression::Lz4),
                         [](const auto& p) { return p.param == mcap::Compression::None ? std::string("none") : std::string(mcap::to_string(p.param)); });

TEST(Mcap, CompressionNamesAreCheckedWithTheValidOnesNamed) {
  EXPECT_EQ(mcap::parse_compression("zstd").value(), mcap::Compression::Zstd);
  EXPECT_EQ(mcap::parse_compression("none").value(), mcap::Compression::None);
  const auto bad = mcap::parse_compression("gzip");
  ASSERT_FALSE(bad);
  EXPECT_NE(bad.error().message().find("expected zstd, lz4 or none"), std::string::npos);
}

TEST(Mcap, Crc32IsTheZlibOne) {
  const std::string s = "123456789";
  EXPECT_EQ(mcap::crc32(std::as_bytes(std::span(s.data(), s.size()))), 0xCBF43926u);
  // Continuing a CRC gives the same as one pass.
  const auto a = mcap::crc32(std::as_bytes(std::span(s.data(), 4)));
  EXPECT_EQ(mcap::crc32(std::as_bytes(std::span(s.data() + 4, 5)), a), 0xCBF43926u);
}

TEST(Mcap, AFileCutShortReadsBackToItsLastCompleteChunk) {
  const auto path = temp_path("cut");
  std::unique_ptr<mcap::Writer> w;
  const auto sent = write_sample(path, mcap::Compression::Zstd, 300, 16 * 1024, false, &w);
  ASSERT_TRUE(w);
  ASSERT_TRUE(w->flush());
  // What a recorder killed now leaves: every chunk so far, no summary, no footer.
  const auto whole = read_file(path);
  const auto copy = temp_path("cut_copy");
  write_file(copy, whole);
  auto strict = mcap::Reader::open(copy);
  ASSERT_FALSE(strict);
  EXPECT_EQ(strict.error().code(), Errc::Corrupt);
  EXPECT_NE(strict.error().message().find("does not end with the MCAP magic"), std::string::npos) << strict.error().message();
  auto r = mcap::Reader::open(copy, {.recover = true});
  ASSERT_TRUE(r) << r.error().message();
  EXPECT_FALSE((*r)->has_summary());
  auto got = read_all(**r);
  EXPECT_TRUE((*r)->truncated());
  ASSERT_EQ(got.size(), sent.size()) << "everything was flushed";
  // Cut in the middle of the last chunk: the messages of the complete chunks come back.
  std::size_t last_chunk = 0;
  for (std::size_t at = 8; at + 9 <= whole.size();) {
    std::uint64_t n = 0;
    for (int i = 0; i < 8; ++i) n |= static_cast<std::uint64_t>(whole[at + 1 + static_cast<std::size_t>(i)]) << (8 * i);
    if (static_cast<std::uint8_t>(whole[at]) == 0x06) last_chunk = at;
    at += 9 + n;
  }
  ASSERT_GT(last_chunk, 0u);
  std::vector<std::byte> cut(whole.begin(), whole.begin() + static_cast<std::ptrdiff_t>(last_chunk + 50));
  write_file(copy, cut);
  auto r2 = mcap::Reader::open(copy, {.recover = true});
  ASSERT_TRUE(r2) << r2.error().message();
  got = read_all(**r2);
  EXPECT_TRUE((*r2)->truncated());
  EXPECT_GT(got.size(), sent.size() / 2);
  EXPECT_LT(got.size(), sent.size());
  for (std::size_t i = 0; i < got.size(); ++i) EXPECT_TRUE(got[i].data == sent[i].data) << i;
  const auto stats = (*r2)->statistics();
  ASSERT_TRUE(stats);
  EXPECT_EQ(stats->message_count, got.size());
  ASSERT_TRUE(w->close());
  ::unlink(path.c_str());
  ::unlink(copy.c_str());
}

// Damage one thing at a time in a good file; each is Errc::Corrupt naming the problem.
class McapDamage : public ::testing::Test {
 protected:
  void SetUp() override {
    path_ = temp_path("damage");
    sent_ = write_sample(path_, mcap::Compression::Lz4, 120, 8 * 1024);
    good_ = read_file(path_);
    ASSERT_GT(good_.size(), 1000u);
  }
  void TearDown() override { ::unlink(path_.c_str()); }
  // The error of opening and reading `bytes` (nullopt when both succeed).
  std::optional<horus::Error> error_of(const std::vector<std::byte>& bytes) {
    write_file(path_, bytes);
    auto r = mcap::Reader::open(path_);
    if (!r) return r.error();
    horus::Result<void> status;
    (void)read_all(**r, &status);
    if (!status) return status.error();
    return std::nullopt;
  }
  // The offset of the first record with `op` after the magic (top level).
  std::size_t first_record(std::uint8_t op) const { return first_record(op, good_); }
  static std::size_t first_record(std::uint8_t op, const std::vector<std::byte>& file) {
    std::size_t at = 8;
    while (at + 9 <= file.size()) {
      std::uint64_t n = 0;
      for (int i = 0; i < 8; ++i) n |= static_cast<std::uint64_t>(file[at + 1 + static_cast<std::size_t>(i)]) << (8 * i);
      if (static_cast<std::uint8_t>(file[at]) == op) return at;
      at += 9 + n;
    }
    return 0;
  }
  std::string path_;
  std::vector<Written> sent_;
  std::vector<std::byte> good_;
};

TEST_F(McapDamage, WrongMagicIsNotAnMcapFile) {
  auto b = good_;
  b[1] = std::byte{'X'};
  const auto e = error_of(b);
  ASSERT_TRUE(e);
  EXPECT_EQ(e->code(), Errc::Corrupt);
  EXPECT_NE(e->message().find("offset 0: not an MCAP file"), std::string::npos) << e->message();
}

TEST_F(McapDamage, AChunkWhoseBytesChangedFailsItsCheck) {
  const std::size_t chunk = first_record(0x06);
  ASSERT_NE(chunk, 0u);
  auto b = good_;
  b[chunk + 9 + 60] ^= std::byte{0x5a};  // inside the compressed records
  const auto e = error_of(b);
  ASSERT_TRUE(e);
  EXPECT_EQ(e->code(), Errc::Corrupt);
  EXPECT_NE(e->message().find("Chunk at offset " + std::to_string(chunk)), std::string::npos) << e->message();
}

TEST_F(McapDamage, ARecordLengthPastTheEndIsNamed) {
  const std::size_t chunk = first_record(0x06);
  auto b = good_;
  b[chunk + 8] = std::byte{0x7f};  // the length's top byte: far past the file
  const auto e = error_of(b);
  ASSERT_TRUE(e);
  EXPECT_NE(e->message().find("Chunk record at offset " + std::to_string(chunk) + " says"), std::string::npos)
      << e->message();
}

// Found by fuzz_mcap (fuzz/regressions/mcap/header-overlaps-footer): a 65-byte file whose Header
// record runs into the Footer. The reader then started the data section past its end and read
// far outside the file (a CRC over 2^64 bytes). Now the Header's end is checked.
TEST_F(McapDamage, AHeaderThatRunsIntoTheFooterIsNamed) {
  const unsigned char file[] = {
      0x89, 0x4d, 0x43, 0x41, 0x50, 0x30, 0x0d, 0x0a, 0x01, 0x0d, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00,
      0x00, 0x00, 0x00, 0x00, 0x05, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x02, 0x14, 0x00, 0x00, 0x00, 0x00,
      0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x03, 0x09, 0x00, 0x00, 0x00, 0x00,
      0x00, 0x00, 0xff, 0x16, 0xc7, 0xd9, 0x89, 0x4d, 0x43, 0x41, 0x50, 0x30, 0x0d, 0x0a};
  std::vector<std::byte> b(sizeof(file));
  std::memcpy(b.data(), file, sizeof(file));
  const auto e = error_of(b);
  ASSERT_TRUE(e);
  EXPECT_EQ(e->code(), Errc::Corrupt);
  EXPECT_NE(e->message().find("the Header record ends at offset 30, inside the Footer record at offset 28"),
            std::string::npos)
      << e->message();
}

TEST_F(McapDamage, AnUnknownCompressionIsNamed) {
  const std::size_t chunk = first_record(0x06);
  auto b = good_;
  // The compression string follows 8+8+8+4 bytes of the chunk: "lz4" becomes "lzX".
  const std::size_t name = chunk + 9 + 28 + 4;
  ASSERT_EQ(static_cast<char>(b[name]), 'l');
  b[name + 2] = std::byte{'X'};
  const auto e = error_of(b);
  ASSERT_TRUE(e);
  EXPECT_NE(e->message().find("unknown compression 'lzX'"), std::string::npos) << e->message();
}

// A chunk that claims far more than its bytes can hold (a "decompression bomb": 1 TiB, 8 GiB,
// 512 MiB from a few kilobytes of lz4, and of zstd) is refused before anything is allocated, with
// what it claims and what it could hold; a claim its bytes could hold but above the reader's
// limit is Errc::LimitReached naming ReadOptions::max_chunk_bytes.
TEST_F(McapDamage, AChunkThatClaimsMoreThanItsBytesCanHoldIsRefusedBeforeAllocating) {
  auto claim = [](std::vector<std::byte> b, std::size_t chunk, std::uint64_t size) {
    for (int i = 0; i < 8; ++i) b[chunk + 9 + 16 + static_cast<std::size_t>(i)] = static_cast<std::byte>(size >> (8 * i));
    return b;
  };
  const std::string zstd_path = temp_path("damage_zstd");
  (void)write_sample(zstd_path, mcap::Compression::Zstd, 120, 8 * 1024);
  const auto zstd = read_file(zstd_path);
  ::unlink(zstd_path.c_str());
  for (const auto* file : std::array<const std::vector<std::byte>*, 2>{&good_, &zstd}) {
    const std::size_t chunk = first_record(0x06, *file);
    ASSERT_NE(chunk, 0u);
    for (const std::uint64_t size : {std::uint64_t{1} << 40, std::uint64_t{8} << 30, std::uint64_t{512} << 20}) {
      const auto e = error_of(claim(*file, chunk, size));
      ASSERT_TRUE(e) << size;
      EXPECT_EQ(e->code(), Errc::Corrupt) << e->message();
      EXPECT_NE(e->message().find("claim " + std::to_string(size) + " bytes uncompressed; they can hold at most"),
                std::string::npos)
          << e->message();
    }
  }
  write_file(path_, good_);
  mcap::ReadOptions small;
  small.max_chunk_bytes = 1000;
  auto r = mcap::Reader::open(path_, small);
  ASSERT_TRUE(r) << r.error().message();
  horus::Result<void> status;
  (void)read_all(**r, &status);
  ASSERT_FALSE(status);
  EXPECT_EQ(status.error().code(), Errc::LimitReached) << status.error().message();
  EXPECT_NE(status.error().message().find("above the reader's limit of 1000 bytes (ReadOptions::max_chunk_bytes)"),
            std::string::npos)
      << status.error().message();
}

TEST_F(McapDamage, AChangedChannelRecordFailsTheDataSectionCrc) {
  const std::size_t channel = first_record(0x04);
  ASSERT_NE(channel, 0u);
  auto b = good_;
  std::uint64_t n = 0;
  for (int i = 0; i < 8; ++i) n |= static_cast<std::uint64_t>(b[channel + 1 + static_cast<std::size_t>(i)]) << (8 * i);
  ASSERT_EQ(static_cast<char>(b[channel + 9 + n - 1]), 't') << "the last metadata value, scope's \"fleet\"";
  b[channel + 9 + n - 1] = std::byte{'X'};  // metadata, which only the CRC covers
  const auto e = error_of(b);
  ASSERT_TRUE(e);
  EXPECT_NE(e->message().find("the data section's CRC"), std::string::npos) << e->message();
}

TEST_F(McapDamage, AChangedSummaryFailsItsCrc) {
  auto b = good_;
  std::uint64_t summary = 0;
  for (int i = 0; i < 8; ++i) summary |= static_cast<std::uint64_t>(b[b.size() - 8 - 20 + static_cast<std::size_t>(i)]) << (8 * i);
  ASSERT_GT(summary, 0u);
  b[summary + 20] ^= std::byte{1};
  const auto e = error_of(b);
  ASSERT_TRUE(e);
  EXPECT_NE(e->message().find("the summary's CRC"), std::string::npos) << e->message();
}

TEST_F(McapDamage, TooShortAndEmptyFilesAreClearErrors) {
  for (std::size_t n : {0, 5, 8, 16}) {
    const auto e = error_of(std::vector<std::byte>(good_.begin(), good_.begin() + static_cast<std::ptrdiff_t>(n)));
    ASSERT_TRUE(e) << n;
    EXPECT_EQ(e->code(), Errc::Corrupt) << n;
  }
}

TEST_F(McapDamage, RandomDamageNeverCrashesTheReader) {
  std::mt19937 rng(7);
  int errors = 0;
  for (int round = 0; round < 300; ++round) {
    auto b = good_;
    const int flips = 1 + static_cast<int>(rng() % 4);
    for (int k = 0; k < flips; ++k) b[rng() % b.size()] ^= std::byte{static_cast<std::uint8_t>(1 + rng() % 255)};
    if (round % 3 == 0) b.resize(rng() % b.size());
    for (const bool recover : {false, true}) {
      write_file(path_, b);
      auto r = mcap::Reader::open(path_, {.recover = recover});
      if (!r) {
        EXPECT_EQ(r.error().code(), Errc::Corrupt) << r.error().message();
        ++errors;
        continue;
      }
      horus::Result<void> status;
      (void)read_all(**r, &status);
      if (!status) {
        EXPECT_EQ(status.error().code(), Errc::Corrupt) << status.error().message();
        ++errors;
      }
      (void)(*r)->statistics();
    }
  }
  EXPECT_GT(errors, 100) << "damage should mostly be caught";
}

TEST(Mcap, WriterRefusesUnknownChannelsAndSchemas) {
  const auto path = temp_path("refuse");
  auto w = mcap::Writer::create(path);
  ASSERT_TRUE(w);
  EXPECT_EQ((*w)->add_channel(3, "x", "cdr").error().code(), Errc::InvalidArgument);
  const std::byte one{1};
  EXPECT_EQ((*w)->write(mcap::Message{9, 0, 0, 0, std::span(&one, 1)}).error().code(), Errc::InvalidArgument);
  ASSERT_TRUE((*w)->close());
  auto bad = mcap::Writer::create("/nonexistent-dir/x.mcap");
  ASSERT_FALSE(bad);
  EXPECT_EQ(bad.error().code(), Errc::Io);
  EXPECT_NE(bad.error().message().find("/nonexistent-dir/x.mcap"), std::string::npos);
  ::unlink(path.c_str());
}

// ---- LCM event logs -------------------------------------------------------------------------

struct LogEvent {
  std::string channel;
  std::int64_t timestamp_us;
  std::vector<std::byte> data;
};

std::vector<LogEvent> write_log(const std::string& path, int n) {
  std::vector<LogEvent> out;
  auto w = horus::lcmlog::Writer::create(path);
  EXPECT_TRUE(w) << w.error().message();
  for (int i = 0; i < n; ++i) {
    LogEvent e{"robot" + std::to_string(i % 3) + ".imu", 1'700'000'000'000'000 + i * 1000,
               payload(static_cast<std::size_t>((i * 37) % 900), static_cast<std::uint32_t>(i))};
    EXPECT_TRUE((*w)->write(e.channel, e.timestamp_us, e.data));
    out.push_back(std::move(e));
  }
  EXPECT_TRUE((*w)->close());
  return out;
}

std::vector<LogEvent> read_log(horus::lcmlog::Reader& r, horus::Result<void>* status) {
  std::vector<LogEvent> got;
  *status = r.read([&](const horus::lcmlog::Event& e) {
    got.push_back({std::string(e.channel), e.timestamp_us, {e.data.begin(), e.data.end()}});
    return true;
  });
  return got;
}

TEST(LcmLog, EventsRoundTripInOrderWithTheirNumbersAndTimes) {
  const auto path = temp_path("log_rt");
  const auto sent = write_log(path, 200);
  auto r = horus::lcmlog::Reader::open(path);
  ASSERT_TRUE(r) << r.error().message();
  horus::Result<void> status;
  std::int64_t expect_number = 0;
  bool numbers_ok = true;
  auto got = std::vector<LogEvent>{};
  status = (*r)->read([&](const horus::lcmlog::Event& e) {
    numbers_ok = numbers_ok && e.number == expect_number++;
    got.push_back({std::string(e.channel), e.timestamp_us, {e.data.begin(), e.data.end()}});
    return true;
  });
  ASSERT_TRUE(status) << status.error().message();
  EXPECT_TRUE(numbers_ok);
  EXPECT_FALSE((*r)->truncated());
  ASSERT_EQ(got.size(), sent.size());
  for (std::size_t i = 0; i < got.size(); ++i) {
    EXPECT_EQ(got[i].channel, sent[i].channel) << i;
    EXPECT_EQ(got[i].timestamp_us, sent[i].timestamp_us) << i;
    EXPECT_EQ(got[i].data, sent[i].data) << i;
  }
  EXPECT_TRUE(horus::lcmlog::looks_like_log(path));
  ::unlink(path.c_str());
}

TEST(LcmLog, AChannelLongerThanLcmAllowsIsRefused) {
  const auto path = temp_path("log_long");
  auto w = horus::lcmlog::Writer::create(path);
  ASSERT_TRUE(w);
  const std::byte one{1};
  auto bad = (*w)->write(std::string(horus::lcmlog::kMaxChannel + 1, 'c'), 0, std::span(&one, 1));
  ASSERT_FALSE(bad);
  EXPECT_EQ(bad.error().code(), Errc::InvalidArgument);
  EXPECT_TRUE((*w)->write(std::string(horus::lcmlog::kMaxChannel, 'c'), 0, std::span(&one, 1)));
  ASSERT_TRUE((*w)->close());
  ::unlink(path.c_str());
}

TEST(LcmLog, ALogCutInsideAnEventReadsToTheEventBefore) {
  const auto path = temp_path("log_cut");
  const auto sent = write_log(path, 50);
  auto bytes = read_file(path);
  // Every cut point inside the last event leaves the 49 before it.
  const std::size_t last = 4 + 8 + 8 + 4 + 4 + sent.back().channel.size() + sent.back().data.size();
  for (std::size_t cut = 1; cut < last; cut += 7) {
    write_file(path, std::span(bytes).first(bytes.size() - cut));
    auto r = horus::lcmlog::Reader::open(path);
    ASSERT_TRUE(r) << r.error().message();
    horus::Result<void> status;
    const auto got = read_log(**r, &status);
    ASSERT_TRUE(status) << "cut " << cut << ": " << status.error().message();
    EXPECT_EQ(got.size(), 49u) << "cut " << cut;
    EXPECT_TRUE((*r)->truncated()) << "cut " << cut;
  }
  ::unlink(path.c_str());
}

TEST(LcmLog, RandomDamageNeverCrashesTheReader) {
  const auto path = temp_path("log_damage");
  (void)write_log(path, 40);
  const auto good = read_file(path);
  std::mt19937 rng(11);
  int errors = 0, truncated = 0;
  for (int round = 0; round < 300; ++round) {
    auto b = good;
    const int flips = 1 + static_cast<int>(rng() % 4);
    for (int k = 0; k < flips; ++k) b[rng() % b.size()] ^= std::byte{static_cast<std::uint8_t>(1 + rng() % 255)};
    if (round % 3 == 0) b.resize(rng() % b.size());
    write_file(path, b);
    auto r = horus::lcmlog::Reader::open(path);
    if (!r) {
      EXPECT_EQ(r.error().code(), Errc::Corrupt) << r.error().message();
      ++errors;
      continue;
    }
    horus::Result<void> status;
    const auto got = read_log(**r, &status);
    for (const auto& e : got) EXPECT_LE(e.channel.size(), b.size());
    if (!status) {
      EXPECT_EQ(status.error().code(), Errc::Corrupt) << status.error().message();
      EXPECT_NE(status.error().message().find("offset"), std::string::npos) << status.error().message();
      ++errors;
    }
    truncated += (*r)->truncated() ? 1 : 0;
  }
  // Payload bytes carry no check in this format, so only damage to the framing is caught.
  EXPECT_GT(errors + truncated, 100) << "framing damage should be caught";
  ::unlink(path.c_str());
}

}  // namespace
