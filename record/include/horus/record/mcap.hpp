// MCAP (https://mcap.dev/spec), written and read by horus's own code: the container of
// `horus record`. A file is
//
//   <magic> <Header> <data: Schema, Channel, Chunk, Message Index...> <Data End>
//   <summary: Schema, Channel, Statistics, Chunk Index> <Summary Offset...> <Footer> <magic>
//
// Messages travel in chunks (compressed with zstd or lz4, or not), each followed by one Message
// Index per channel, so a reader seeks by time through the summary's Chunk Indexes. Schemas and
// channels are written in the data section when they are added (before any chunk that uses
// them) and again in the summary. A chunk reaches the file whole, in one write: a recorder that
// is killed leaves a file whose complete chunks read back (ReadOptions::recover).
//
// The reader checks every length against the bytes that hold it and every CRC the writer set
// (chunks, the data section, the summary); an error names the offset and what was expected.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "horus/error.hpp"

#include "horus/export.hpp"

HORUS_API_BEGIN

namespace horus::mcap {

enum class Compression : std::uint8_t { None, Zstd, Lz4 };

/// "" (none), "zstd", "lz4": the names MCAP files carry.
std::string_view to_string(Compression c) noexcept;
/// Parses "none", "zstd" or "lz4" (Errc::InvalidArgument naming the valid ones otherwise).
Result<Compression> parse_compression(std::string_view name);

struct Schema {
  std::uint16_t id = 0;
  std::string name;      // e.g. the message type's qualified name
  std::string encoding;  // "omgidl", "ros2msg", "jsonschema", ...
  std::vector<std::byte> data;
};

struct Channel {
  std::uint16_t id = 0;
  std::uint16_t schema_id = 0;  // 0: no schema
  std::string topic;
  std::string message_encoding;  // "cdr", "json", ...
  std::map<std::string, std::string> metadata;
};

/// One message; `data` is only valid during the call that hands it over.
struct Message {
  std::uint16_t channel_id = 0;
  std::uint32_t sequence = 0;
  std::uint64_t log_time = 0;      // ns since the Unix epoch, when it was recorded
  std::uint64_t publish_time = 0;  // ns since the Unix epoch, when it was sent
  std::span<const std::byte> data;
};

struct Statistics {
  std::uint64_t message_count = 0;
  std::uint16_t schema_count = 0;
  std::uint32_t channel_count = 0;
  std::uint32_t chunk_count = 0;
  std::uint64_t message_start_time = 0;
  std::uint64_t message_end_time = 0;
  std::map<std::uint16_t, std::uint64_t> channel_message_counts;
};

struct WriterOptions {
  Compression compression = Compression::Zstd;
  std::size_t chunk_size = 4u << 20;  // a chunk is closed when its records reach this many bytes
  std::string profile;                // the Header's profile ("" : none)
  std::string library = "horus";
};

/// Writes one MCAP file. Not thread-safe: one thread writes (or lock around it).
class Writer {
 public:
  /// Creates (truncates) `path` and writes the magic and the Header.
  static Result<std::unique_ptr<Writer>> create(const std::string& path, WriterOptions options = {});
  ~Writer();  // close(), errors ignored
  Writer(const Writer&) = delete;
  Writer& operator=(const Writer&) = delete;

  /// Ids start at 1.
  Result<std::uint16_t> add_schema(std::string_view name, std::string_view encoding, std::span<const std::byte> data);
  Result<std::uint16_t> add_channel(std::uint16_t schema_id, std::string_view topic, std::string_view message_encoding,
                                    const std::map<std::string, std::string>& metadata = {});
  /// Writes a Metadata record (after the open chunk), indexed in the summary: rosbag2's
  /// "rosbag2" record, for one.
  Result<void> add_metadata(std::string_view name, const std::map<std::string, std::string>& metadata);
  /// Appends to the current chunk; writes the chunk when it is full.
  Result<void> write(const Message& message);
  /// Writes the current chunk now (what a killed recorder leaves readable ends here).
  Result<void> flush();
  /// Writes the last chunk, the Data End, the summary and the Footer. Idempotent.
  Result<void> close();

  /// Bytes in the file so far (the open chunk not included).
  std::uint64_t file_size() const noexcept;
  const Statistics& statistics() const noexcept;

 private:
  struct Impl;
  explicit Writer(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

struct ReadOptions {
  /// Reads what is whole in a file that ends early (a killed recorder): records up to the last
  /// complete one, and no error for the missing end (Reader::truncated() says so).
  bool recover = false;
  /// The most a chunk may decompress to: a chunk that claims more is an error
  /// (Errc::LimitReached) before anything is allocated. Chunks that this writer makes hold
  /// WriterOptions::chunk_size bytes or one larger message.
  std::uint64_t max_chunk_bytes = std::uint64_t{1} << 30;
};

/// Reads one MCAP file (mapped into memory).
class Reader {
 public:
  /// Checks the magic, the Header and (unless recovering a file without one) the Footer and
  /// the summary with its CRC.
  static Result<std::unique_ptr<Reader>> open(const std::string& path, ReadOptions options = {});
  ~Reader();
  Reader(const Reader&) = delete;
  Reader& operator=(const Reader&) = delete;

  const std::string& profile() const noexcept;
  const std::string& library() const noexcept;
  std::uint64_t file_size() const noexcept;
  /// False when the file has no summary (a recovered file): statistics() then counts by reading.
  bool has_summary() const noexcept;
  /// After open() with recover: the file ended before its Footer.
  bool truncated() const noexcept;

  /// Every message in file order with its channel and schema (nullptr when the channel has
  /// none); `f` returns false to stop. Checks chunk CRCs and the data section's CRC on the way.
  /// With recover, reading stops quietly at the first incomplete record.
  Result<void> read_messages(const std::function<bool(const Channel&, const Schema*, const Message&)>& f);

  /// The schemas and channels seen so far (all of them after open() when the file has a
  /// summary, else after read_messages()).
  const std::map<std::uint16_t, Schema>& schemas() const noexcept;
  const std::map<std::uint16_t, Channel>& channels() const noexcept;
  /// The Metadata records by name (after read_messages(): they are in the data section).
  const std::map<std::string, std::map<std::string, std::string>>& metadata() const noexcept;
  /// From the summary; a file without one is read through once to count.
  Result<Statistics> statistics();

 private:
  struct Impl;
  explicit Reader(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

/// CRC-32 (ISO-HDLC, the zlib one) of `bytes`, continuing from `crc` (0 to start).
std::uint32_t crc32(std::span<const std::byte> bytes, std::uint32_t crc = 0) noexcept;

}  // namespace horus::mcap

HORUS_API_END
