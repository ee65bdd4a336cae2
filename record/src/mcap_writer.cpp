// The MCAP writer (horus/record/mcap.hpp).
#include <fcntl.h>
#include <fmt/format.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <utility>

#include "mcap_internal.hpp"

namespace horus::mcap {

using detail::Out;

struct Writer::Impl {
  int fd = -1;
  std::string path;
  WriterOptions options;
  std::uint64_t offset = 0;    // bytes in the file
  std::uint32_t data_crc = 0;  // of every byte of the data section so far (from the magic on)
  bool closed = false;
  std::vector<Schema> schemas;
  std::vector<Channel> channels;
  Statistics stats;

  // The open chunk: its records, and per channel (log_time, offset in the records).
  std::vector<std::byte> records;
  std::map<std::uint16_t, std::vector<std::pair<std::uint64_t, std::uint64_t>>> index;
  std::uint64_t chunk_start = 0, chunk_end = 0;
  bool chunk_has_messages = false;

  struct ChunkIndex {
    std::uint64_t start_time, end_time, offset, length;
    std::map<std::uint16_t, std::uint64_t> message_index_offsets;
    std::uint64_t message_index_length;
    std::uint64_t compressed_size, uncompressed_size;
  };
  std::vector<ChunkIndex> chunk_indexes;
  struct MetadataIndex {
    std::uint64_t offset, length;
    std::string name;
  };
  std::vector<MetadataIndex> metadata_indexes;
  std::vector<std::byte> scratch, compressed;

  Result<void> put(std::span<const std::byte> b, bool data_section) {
    const std::byte* p = b.data();
    std::size_t n = b.size();
    while (n > 0) {
      const ssize_t w = ::write(fd, p, n);
      if (w < 0) {
        if (errno == EINTR) continue;
        return fail(Errc::Io, fmt::format("{}: write failed at offset {}: {}", path, offset, std::strerror(errno)));
      }
      p += w;
      n -= static_cast<std::size_t>(w);
    }
    if (data_section) data_crc = crc32(b, data_crc);
    offset += b.size();
    return {};
  }

  static void schema_record(Out& o, const Schema& s) {
    const auto at = o.begin_record(detail::kSchema);
    o.u16(s.id);
    o.str(s.name);
    o.str(s.encoding);
    o.u32(static_cast<std::uint32_t>(s.data.size()));
    o.bytes(s.data);
    o.end_record(at);
  }
  static void channel_record(Out& o, const Channel& c) {
    const auto at = o.begin_record(detail::kChannel);
    o.u16(c.id);
    o.u16(c.schema_id);
    o.str(c.topic);
    o.str(c.message_encoding);
    o.string_map(c.metadata);
    o.end_record(at);
  }

  // The open chunk, then one Message Index per channel, in one write.
  Result<void> write_chunk() {
    if (!chunk_has_messages) return {};
    if (auto ok = detail::compress(options.compression, records, compressed); !ok) return ok;
    scratch.clear();
    Out o(scratch);
    const std::uint64_t chunk_offset = offset;
    auto at = o.begin_record(detail::kChunk);
    o.u64(chunk_start);
    o.u64(chunk_end);
    o.u64(records.size());
    o.u32(crc32(records));
    o.str(to_string(options.compression));
    o.u64(compressed.size());
    o.bytes(compressed);
    o.end_record(at);
    const std::uint64_t chunk_length = o.size();
    ChunkIndex ci{chunk_start, chunk_end, chunk_offset, chunk_length, {}, 0, compressed.size(), records.size()};
    for (const auto& [channel, entries] : index) {
      ci.message_index_offsets[channel] = chunk_offset + o.size();
      at = o.begin_record(detail::kMessageIndex);
      o.u16(channel);
      o.u32(static_cast<std::uint32_t>(entries.size() * 16));
      for (const auto& [t, off] : entries) {
        o.u64(t);
        o.u64(off);
      }
      o.end_record(at);
    }
    ci.message_index_length = o.size() - chunk_length;
    if (auto ok = put(scratch, true); !ok) return ok;
    chunk_indexes.push_back(std::move(ci));
    ++stats.chunk_count;
    records.clear();
    index.clear();
    chunk_has_messages = false;
    return {};
  }

  // The summary's Statistics record.
  void statistics_record(Out& o) const {
    const auto at = o.begin_record(detail::kStatistics);
    o.u64(stats.message_count);
    o.u16(stats.schema_count);
    o.u32(stats.channel_count);
    o.u32(0);  // attachments
    o.u32(static_cast<std::uint32_t>(metadata_indexes.size()));
    o.u32(stats.chunk_count);
    o.u64(stats.message_start_time);
    o.u64(stats.message_end_time);
    o.u32(static_cast<std::uint32_t>(stats.channel_message_counts.size() * 10));
    for (const auto& [id, n] : stats.channel_message_counts) {
      o.u16(id);
      o.u64(n);
    }
    o.end_record(at);
  }

  // The summary's Metadata Index record of one Metadata record.
  static void metadata_index_record(Out& o, const MetadataIndex& mi) {
    const auto at = o.begin_record(detail::kMetadataIndex);
    o.u64(mi.offset);
    o.u64(mi.length);
    o.str(mi.name);
    o.end_record(at);
  }

  // The summary's Chunk Index record of one chunk.
  void chunk_index_record(Out& o, const ChunkIndex& ci) const {
    const auto at = o.begin_record(detail::kChunkIndex);
    o.u64(ci.start_time);
    o.u64(ci.end_time);
    o.u64(ci.offset);
    o.u64(ci.length);
    o.u32(static_cast<std::uint32_t>(ci.message_index_offsets.size() * 10));
    for (const auto& [id, off] : ci.message_index_offsets) {
      o.u16(id);
      o.u64(off);
    }
    o.u64(ci.message_index_length);
    o.str(to_string(options.compression));
    o.u64(ci.compressed_size);
    o.u64(ci.uncompressed_size);
    o.end_record(at);
  }

  Result<void> finish() {
    if (auto ok = write_chunk(); !ok) return ok;
    scratch.clear();
    Out o(scratch);
    auto at = o.begin_record(detail::kDataEnd);
    o.u32(data_crc);  // the data section up to here (this record excluded)
    o.end_record(at);
    if (auto ok = put(scratch, false); !ok) return ok;

    // The summary: schemas, channels, statistics, chunk indexes; then one Summary Offset per group.
    const std::uint64_t summary_start = offset;
    scratch.clear();
    struct Group {
      std::uint8_t op;
      std::uint64_t start, length;
    };
    std::vector<Group> groups;
    auto group = [&](std::uint8_t op, auto&& body) {
      const std::size_t from = o.size();
      body();
      if (o.size() != from) groups.push_back({op, summary_start + from, o.size() - from});
    };
    group(detail::kSchema, [&] {
      for (const auto& s : schemas) schema_record(o, s);
    });
    group(detail::kChannel, [&] {
      for (const auto& c : channels) channel_record(o, c);
    });
    group(detail::kStatistics, [&] { statistics_record(o); });
    group(detail::kChunkIndex, [&] {
      for (const auto& ci : chunk_indexes) chunk_index_record(o, ci);
    });
    group(detail::kMetadataIndex, [&] {
      for (const auto& mi : metadata_indexes) metadata_index_record(o, mi);
    });
    const std::uint64_t summary_offset_start = summary_start + o.size();
    for (const auto& g : groups) {
      at = o.begin_record(detail::kSummaryOffset);
      o.u8(g.op);
      o.u64(g.start);
      o.u64(g.length);
      o.end_record(at);
    }
    // The Footer; its CRC covers the summary through the summary_offset_start field.
    o.u8(detail::kFooter);
    o.u64(20);
    o.u64(summary_start);
    o.u64(summary_offset_start);
    o.u32(crc32(scratch));
    o.bytes(detail::kMagic);
    return put(scratch, false);
  }
};

Writer::Writer(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}

Writer::~Writer() { (void)close(); }

Result<std::unique_ptr<Writer>> Writer::create(const std::string& path, WriterOptions options) {
  if (options.chunk_size == 0) return fail(Errc::InvalidArgument, "MCAP writer: chunk_size must be at least 1 byte");
  auto impl = std::make_unique<Impl>();
  impl->path = path;
  impl->options = std::move(options);
  impl->fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (impl->fd < 0) return fail(Errc::Io, fmt::format("{}: cannot create: {}", path, std::strerror(errno)));
  std::vector<std::byte> head(std::begin(detail::kMagic), std::end(detail::kMagic));
  Out o(head);
  const auto at = o.begin_record(detail::kHeader);
  o.str(impl->options.profile);
  o.str(impl->options.library);
  o.end_record(at);
  if (auto ok = impl->put(head, true); !ok) {
    ::close(impl->fd);
    return std::unexpected(ok.error());
  }
  return std::unique_ptr<Writer>(new Writer(std::move(impl)));
}

Result<std::uint16_t> Writer::add_schema(std::string_view name, std::string_view encoding,
                                         std::span<const std::byte> data) {
  auto& d = *impl_;
  if (d.closed) return fail(Errc::InvalidArgument, d.path + ": the MCAP writer is closed");
  if (d.schemas.size() >= 0xFFFF) return fail(Errc::LimitReached, d.path + ": an MCAP file holds at most 65535 schemas");
  Schema s{static_cast<std::uint16_t>(d.schemas.size() + 1), std::string(name), std::string(encoding),
           std::vector<std::byte>(data.begin(), data.end())};
  d.scratch.clear();
  Out o(d.scratch);
  Impl::schema_record(o, s);
  if (auto ok = d.put(d.scratch, true); !ok) return std::unexpected(ok.error());
  d.schemas.push_back(std::move(s));
  d.stats.schema_count = static_cast<std::uint16_t>(d.schemas.size());
  return d.schemas.back().id;
}

Result<std::uint16_t> Writer::add_channel(std::uint16_t schema_id, std::string_view topic,
                                          std::string_view message_encoding,
                                          const std::map<std::string, std::string>& metadata) {
  auto& d = *impl_;
  if (d.closed) return fail(Errc::InvalidArgument, d.path + ": the MCAP writer is closed");
  if (schema_id > d.schemas.size())
    return fail(Errc::InvalidArgument, fmt::format("{}: channel '{}' names schema {}, which was not added", d.path,
                                                   topic, schema_id));
  if (d.channels.size() >= 0xFFFF) return fail(Errc::LimitReached, d.path + ": an MCAP file holds at most 65535 channels");
  Channel c{static_cast<std::uint16_t>(d.channels.size() + 1), schema_id, std::string(topic),
            std::string(message_encoding), metadata};
  d.scratch.clear();
  Out o(d.scratch);
  Impl::channel_record(o, c);
  if (auto ok = d.put(d.scratch, true); !ok) return std::unexpected(ok.error());
  d.channels.push_back(std::move(c));
  d.stats.channel_count = static_cast<std::uint32_t>(d.channels.size());
  return d.channels.back().id;
}

Result<void> Writer::write(const Message& m) {
  auto& d = *impl_;
  if (d.closed) return fail(Errc::InvalidArgument, d.path + ": the MCAP writer is closed");
  if (m.channel_id == 0 || m.channel_id > d.channels.size())
    return fail(Errc::InvalidArgument, fmt::format("{}: a message names channel {}, which was not added", d.path,
                                                   m.channel_id));
  Out o(d.records);
  d.index[m.channel_id].emplace_back(m.log_time, d.records.size());
  const auto at = o.begin_record(detail::kMessage);
  o.u16(m.channel_id);
  o.u32(m.sequence);
  o.u64(m.log_time);
  o.u64(m.publish_time);
  o.bytes(m.data);
  o.end_record(at);
  if (!d.chunk_has_messages) {
    d.chunk_start = d.chunk_end = m.log_time;
    d.chunk_has_messages = true;
  }
  d.chunk_start = std::min(d.chunk_start, m.log_time);
  d.chunk_end = std::max(d.chunk_end, m.log_time);
  auto& s = d.stats;
  s.message_start_time = s.message_count == 0 ? m.log_time : std::min(s.message_start_time, m.log_time);
  s.message_end_time = std::max(s.message_end_time, m.log_time);
  ++s.message_count;
  ++s.channel_message_counts[m.channel_id];
  if (d.records.size() >= d.options.chunk_size) return d.write_chunk();
  return {};
}

Result<void> Writer::add_metadata(std::string_view name, const std::map<std::string, std::string>& metadata) {
  auto& d = *impl_;
  if (d.closed) return fail(Errc::InvalidArgument, d.path + ": the MCAP writer is closed");
  if (auto ok = d.write_chunk(); !ok) return ok;  // a Metadata record stands outside chunks
  d.scratch.clear();
  Out o(d.scratch);
  const auto at = o.begin_record(detail::kMetadata);
  o.str(name);
  o.string_map(metadata);
  o.end_record(at);
  d.metadata_indexes.push_back({d.offset, d.scratch.size(), std::string(name)});
  return d.put(d.scratch, true);
}

Result<void> Writer::flush() {
  if (impl_->closed) return {};
  return impl_->write_chunk();
}

Result<void> Writer::close() {
  auto& d = *impl_;
  if (d.closed) return {};
  d.closed = true;
  auto ok = d.finish();
  if (::close(d.fd) != 0 && ok)
    ok = fail(Errc::Io, fmt::format("{}: close failed: {}", d.path, std::strerror(errno)));
  d.fd = -1;
  return ok;
}

std::uint64_t Writer::file_size() const noexcept { return impl_->offset; }
const Statistics& Writer::statistics() const noexcept { return impl_->stats; }

}  // namespace horus::mcap
