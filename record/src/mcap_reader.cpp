// The MCAP reader (horus/record/mcap.hpp): the file is mapped; every record is checked against
// the bytes around it before it is parsed.
#include <fcntl.h>
#include <fmt/format.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <utility>

#include "mcap_internal.hpp"

namespace horus::mcap {

using detail::In;

namespace {
constexpr std::uint64_t kFooterRecord = 1 + 8 + 20;  // opcode, length, content
}  // namespace

struct Reader::Impl {
  std::string path;
  ReadOptions options;
  const std::byte* base = nullptr;
  std::uint64_t size = 0;
  std::string profile, library;
  std::uint64_t data_start = 0;     // after the Header
  std::uint64_t summary_start = 0;  // 0: none
  std::uint64_t summary_offset_start = 0;
  bool has_footer = false;
  bool truncated = false;
  std::map<std::uint16_t, Schema> schemas;
  std::map<std::uint16_t, Channel> channels;
  std::map<std::string, std::map<std::string, std::string>> metadata;
  std::optional<Statistics> stats;
  std::vector<std::byte> chunk;

  ~Impl() {
    if (base != nullptr) ::munmap(const_cast<std::byte*>(base), size);
  }

  std::span<const std::byte> bytes(std::uint64_t from, std::uint64_t n) const {
    return {base + from, static_cast<std::size_t>(n)};
  }
  Error corrupt(std::string what) const { return Error(Errc::Corrupt, path + ": " + std::move(what)); }

  // The record at `at` of the region ending at `end`: its opcode and content.
  struct Record {
    std::uint8_t op = 0;
    std::uint64_t at = 0;       // the opcode's offset
    std::uint64_t content = 0;  // the content's offset
    std::uint64_t length = 0;
  };
  enum class Next { Ok, End, Incomplete };
  Next next_record(std::uint64_t at, std::uint64_t end, Record& r, std::string& why) const {
    if (at == end) return Next::End;
    if (at > end) {  // a region that starts past its end (offsets from a corrupt file)
      why = fmt::format("a record at offset {} starts past the end of its region at {}", at, end);
      return Next::Incomplete;
    }
    if (end - at < 9) {
      why = fmt::format("a record at offset {} needs 9 bytes of opcode and length, {} left", at, end - at);
      return Next::Incomplete;
    }
    r.op = static_cast<std::uint8_t>(base[at]);
    std::uint64_t n = 0;
    for (int i = 0; i < 8; ++i) n |= static_cast<std::uint64_t>(base[at + 1 + static_cast<std::uint64_t>(i)]) << (8 * i);
    r.at = at;
    r.content = at + 9;
    r.length = n;
    if (n > end - r.content) {
      why = fmt::format("the {} record at offset {} says {} bytes, only {} left", detail::op_name(r.op), at, n,
                        end - r.content);
      return Next::Incomplete;
    }
    return Next::Ok;
  }

  Result<Schema> parse_schema(std::span<const std::byte> content, std::uint64_t base_offset, const std::string& where) {
    In in(content, base_offset, where + "Schema");
    Schema s;
    s.id = in.u16("id");
    s.name = in.str("name");
    s.encoding = in.str("encoding");
    const std::uint32_t n = in.u32("data length");
    const auto d = in.bytes(n, "data");
    s.data.assign(d.begin(), d.end());
    if (!in.ok()) return std::unexpected(corrupt(in.error()->message()));
    if (s.id == 0) return std::unexpected(corrupt(where + fmt::format("Schema at offset {} has id 0 (reserved)", base_offset)));
    return s;
  }
  Result<Channel> parse_channel(std::span<const std::byte> content, std::uint64_t base_offset, const std::string& where) {
    In in(content, base_offset, where + "Channel");
    Channel c;
    c.id = in.u16("id");
    c.schema_id = in.u16("schema_id");
    c.topic = in.str("topic");
    c.message_encoding = in.str("message_encoding");
    c.metadata = in.string_map("metadata");
    if (!in.ok()) return std::unexpected(corrupt(in.error()->message()));
    return c;
  }
  Result<void> keep_schema(Schema s, std::uint64_t at) {
    auto [it, fresh] = schemas.try_emplace(s.id, s);
    if (!fresh && (it->second.name != s.name || it->second.encoding != s.encoding || it->second.data != s.data))
      return std::unexpected(corrupt(fmt::format("Schema {} at offset {} differs from an earlier one with that id", s.id, at)));
    return {};
  }
  Result<void> keep_channel(Channel c, std::uint64_t at) {
    auto [it, fresh] = channels.try_emplace(c.id, c);
    if (!fresh && (it->second.topic != c.topic || it->second.schema_id != c.schema_id ||
                   it->second.message_encoding != c.message_encoding))
      return std::unexpected(corrupt(fmt::format("Channel {} at offset {} differs from an earlier one with that id", c.id, at)));
    return {};
  }

  Result<void> open_file() {
    const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
    if (fd < 0) return fail(Errc::Io, fmt::format("{}: cannot open: {}", path, std::strerror(errno)));
    struct stat st{};
    if (::fstat(fd, &st) != 0) {
      const int e = errno;
      ::close(fd);
      return fail(Errc::Io, fmt::format("{}: cannot stat: {}", path, std::strerror(e)));
    }
    size = static_cast<std::uint64_t>(st.st_size);
    if (size < 8 + 9) {
      ::close(fd);
      return std::unexpected(corrupt(fmt::format("{} bytes is too short for an MCAP file (magic and Header first)", size)));
    }
    void* m = ::mmap(nullptr, size, PROT_READ, MAP_PRIVATE, fd, 0);
    ::close(fd);
    if (m == MAP_FAILED) return fail(Errc::Io, fmt::format("{}: cannot map: {}", path, std::strerror(errno)));
    base = static_cast<const std::byte*>(m);
    return {};
  }

  // The magic and the Header record (`data_start` follows it).
  Result<void> read_header() {
    if (std::memcmp(base, detail::kMagic, 8) != 0)
      return std::unexpected(corrupt("offset 0: not an MCAP file (expected the magic 89 4D 43 41 50 30 0D 0A)"));
    Record r;
    std::string why;
    if (next_record(8, size, r, why) != Next::Ok) return std::unexpected(corrupt(why));
    if (r.op != detail::kHeader)
      return std::unexpected(corrupt(fmt::format("offset 8: expected the Header record (opcode 0x01), found {}",
                                                 detail::op_name(r.op))));
    In h(bytes(r.content, r.length), r.content, "Header");
    profile = h.str("profile");
    library = h.str("library");
    if (!h.ok()) return std::unexpected(corrupt(h.error()->message()));
    data_start = r.content + r.length;
    return {};
  }

  // The summary's Statistics record.
  Result<Statistics> parse_statistics(std::span<const std::byte> content, std::uint64_t at) {
    In in(content, at, "Statistics");
    Statistics s;
    s.message_count = in.u64("message_count");
    s.schema_count = in.u16("schema_count");
    s.channel_count = in.u32("channel_count");
    (void)in.u32("attachment_count");
    (void)in.u32("metadata_count");
    s.chunk_count = in.u32("chunk_count");
    s.message_start_time = in.u64("message_start_time");
    s.message_end_time = in.u64("message_end_time");
    const std::uint32_t n = in.u32("channel_message_counts length");
    In m(in.bytes(n, "channel_message_counts"), at, "Statistics channel_message_counts");
    while (in.ok() && m.ok() && m.left() > 0) {
      const std::uint16_t id = m.u16("channel id");
      s.channel_message_counts[id] = m.u64("count");
    }
    if (!in.ok()) return std::unexpected(corrupt(in.error()->message()));
    if (!m.ok()) return std::unexpected(corrupt(m.error()->message()));
    return s;
  }

  // The summary section up to `summary_end`: its Schema, Channel and Statistics records.
  Result<void> read_summary(std::uint64_t summary_end) {
    Record r;
    std::string why;
    for (std::uint64_t at = summary_start; at < summary_end;) {
      if (next_record(at, summary_end, r, why) != Next::Ok) return std::unexpected(corrupt("in the summary: " + why));
      const auto content = bytes(r.content, r.length);
      if (r.op == detail::kSchema) {
        auto s = parse_schema(content, r.content, "summary ");
        if (!s) return std::unexpected(s.error());
        if (auto ok = keep_schema(std::move(*s), r.at); !ok) return ok;
      } else if (r.op == detail::kChannel) {
        auto c = parse_channel(content, r.content, "summary ");
        if (!c) return std::unexpected(c.error());
        if (auto ok = keep_channel(std::move(*c), r.at); !ok) return ok;
      } else if (r.op == detail::kStatistics) {
        auto s = parse_statistics(content, r.content);
        if (!s) return std::unexpected(s.error());
        stats = std::move(*s);
      }
      at = r.content + r.length;
    }
    return {};
  }

  Result<void> open() {
    if (auto ok = open_file(); !ok) return ok;
    if (auto ok = read_header(); !ok) return ok;

    // The end: Footer and magic.
    const bool magic_at_end = size >= 8 + 9 + kFooterRecord + 8 && std::memcmp(base + size - 8, detail::kMagic, 8) == 0;
    if (!magic_at_end) {
      if (!options.recover)
        return std::unexpected(corrupt(fmt::format(
            "offset {}: the file does not end with the MCAP magic (it was cut short, e.g. a recorder that was "
            "killed; `horus record recover` reads what is whole)",
            size >= 8 ? size - 8 : 0)));
      truncated = true;
      return {};
    }
    const std::uint64_t footer = size - 8 - kFooterRecord;
    if (data_start > footer)
      return std::unexpected(corrupt(fmt::format("offset 8: the Header record ends at offset {}, inside the Footer "
                                                 "record at offset {}",
                                                 data_start, footer)));
    In f(bytes(footer, kFooterRecord), footer, "Footer");
    const std::uint8_t op = f.u8("opcode");
    const std::uint64_t len = f.u64("length");
    if (op != detail::kFooter || len != 20)
      return std::unexpected(corrupt(fmt::format("offset {}: expected the Footer record (opcode 0x02, 20 bytes), found {} "
                                                 "of {} bytes",
                                                 footer, detail::op_name(op), len)));
    summary_start = f.u64("summary_start");
    summary_offset_start = f.u64("summary_offset_start");
    const std::uint32_t summary_crc = f.u32("summary_crc");
    has_footer = true;
    if (summary_start == 0) return {};
    if (summary_start < data_start || summary_start > footer ||
        (summary_offset_start != 0 && (summary_offset_start < summary_start || summary_offset_start > footer)))
      return std::unexpected(corrupt(fmt::format("offset {}: the Footer's summary offsets {} and {} are outside the file's "
                                                 "summary area {}..{}",
                                                 footer, summary_start, summary_offset_start, data_start, footer)));
    if (summary_crc != 0) {
      const std::uint32_t crc = crc32(bytes(summary_start, footer + 1 + 8 + 16 - summary_start));
      if (crc != summary_crc)
        return std::unexpected(corrupt(fmt::format("offset {}: the summary's CRC is {:08x}, the Footer says {:08x}",
                                                   summary_start, crc, summary_crc)));
    }
    return read_summary(summary_offset_start != 0 ? summary_offset_start : footer);
  }

  // One record of the data section (or of a chunk: `in_chunk`), handed to the caller's f.
  // Returns false when f asked to stop.
  Result<bool> handle(std::uint8_t op, std::span<const std::byte> content, std::uint64_t at, const std::string& where,
                      const std::function<bool(const Channel&, const Schema*, const Message&)>& f) {
    if (op == detail::kSchema) {
      auto s = parse_schema(content, at, where);
      if (!s) return std::unexpected(s.error());
      if (auto ok = keep_schema(std::move(*s), at); !ok) return std::unexpected(ok.error());
    } else if (op == detail::kChannel) {
      auto c = parse_channel(content, at, where);
      if (!c) return std::unexpected(c.error());
      if (auto ok = keep_channel(std::move(*c), at); !ok) return std::unexpected(ok.error());
    } else if (op == detail::kMessage) {
      In in(content, at, where + "Message");
      Message m;
      m.channel_id = in.u16("channel_id");
      m.sequence = in.u32("sequence");
      m.log_time = in.u64("log_time");
      m.publish_time = in.u64("publish_time");
      m.data = in.rest();
      if (!in.ok()) return std::unexpected(corrupt(in.error()->message()));
      const auto c = channels.find(m.channel_id);
      if (c == channels.end())
        return std::unexpected(corrupt(fmt::format("{}Message at offset {} names channel {}, which no Channel record "
                                                   "before it declares",
                                                   where, at, m.channel_id)));
      const Schema* s = nullptr;
      if (c->second.schema_id != 0) {
        const auto it = schemas.find(c->second.schema_id);
        if (it == schemas.end())
          return std::unexpected(corrupt(fmt::format("{}channel {} ('{}') names schema {}, which no Schema record before "
                                                     "its first message declares",
                                                     where, c->first, c->second.topic, c->second.schema_id)));
        s = &it->second;
      }
      return f(c->second, s, m);
    } else if (op == detail::kMetadata) {
      In in(content, at, where + "Metadata");
      std::string name = in.str("name");
      auto values = in.string_map("metadata");
      if (!in.ok()) return std::unexpected(corrupt(in.error()->message()));
      metadata[std::move(name)] = std::move(values);
    }
    return true;  // indexes, attachments: nothing for a message reader
  }

  Result<void> read(const std::function<bool(const Channel&, const Schema*, const Message&)>& f) {
    Record r;
    std::string why;
    std::uint64_t at = data_start;
    const std::uint64_t end = has_footer && summary_start != 0 ? summary_start : (has_footer ? size - 8 - kFooterRecord : size);
    std::uint32_t crc = crc32(bytes(0, data_start));
    for (;;) {
      const Next n = next_record(at, end, r, why);
      if (n == Next::End) {
        if (has_footer) return {};  // a file with no Data End (allowed)
        truncated = true;
        return {};
      }
      if (n != Next::Ok) {
        if (options.recover) {
          truncated = true;
          return {};
        }
        return std::unexpected(corrupt(why));
      }
      if (r.op == detail::kDataEnd) {
        In in(bytes(r.content, r.length), r.content, "Data End");
        const std::uint32_t want = in.u32("data_section_crc");
        if (!in.ok()) return std::unexpected(corrupt(in.error()->message()));
        if (want != 0 && want != crc)
          return std::unexpected(corrupt(fmt::format("offset {}: the data section's CRC is {:08x}, Data End says {:08x}",
                                                     r.at, crc, want)));
        return {};
      }
      crc = crc32(bytes(r.at, 9 + r.length), crc);
      const auto content = bytes(r.content, r.length);
      if (r.op == detail::kChunk) {
        In in(content, r.content, "Chunk");
        (void)in.u64("message_start_time");
        (void)in.u64("message_end_time");
        const std::uint64_t uncompressed_size = in.u64("uncompressed_size");
        const std::uint32_t uncompressed_crc = in.u32("uncompressed_crc");
        const std::string compression = in.str("compression");
        const std::uint64_t n_records = in.u64("records length");
        const auto records = in.bytes(n_records, "records");
        if (!in.ok()) return std::unexpected(corrupt(in.error()->message()));
        const std::string where = fmt::format("the Chunk at offset {}", r.at);
        if (auto ok = detail::decompress(compression, records, uncompressed_size, chunk, where, options.max_chunk_bytes); !ok)
          return std::unexpected(Error(ok.error().code(), path + ": " + ok.error().message()));
        if (uncompressed_crc != 0 && crc32(chunk) != uncompressed_crc)
          return std::unexpected(corrupt(fmt::format("{}: its records' CRC is {:08x}, the chunk says {:08x}", where,
                                                     crc32(chunk), uncompressed_crc)));
        // Records inside: offsets are within the decompressed records.
        const std::vector<std::byte> records_copy = std::move(chunk);
        chunk.clear();
        std::uint64_t p = 0;
        while (p < records_copy.size()) {
          const std::uint64_t left = records_copy.size() - p;
          if (left < 9)
            return std::unexpected(corrupt(fmt::format("{}: a record at offset {} of its records needs 9 bytes, {} left",
                                                       where, p, left)));
          const auto op = static_cast<std::uint8_t>(records_copy[p]);
          std::uint64_t len = 0;
          for (int i = 0; i < 8; ++i) len |= static_cast<std::uint64_t>(records_copy[p + 1 + static_cast<std::uint64_t>(i)]) << (8 * i);
          if (len > left - 9)
            return std::unexpected(corrupt(fmt::format("{}: the {} record at offset {} of its records says {} bytes, only "
                                                       "{} left",
                                                       where, detail::op_name(op), p, len, left - 9)));
          const std::span<const std::byte> inner(records_copy.data() + p + 9, static_cast<std::size_t>(len));
          auto go = handle(op, inner, p + 9, where + " (offsets within its records): ", f);
          if (!go) return std::unexpected(go.error());
          if (!*go) return {};
          p += 9 + len;
        }
      } else {
        auto go = handle(r.op, content, r.content, "", f);
        if (!go) return std::unexpected(go.error());
        if (!*go) return {};
      }
      at = r.content + r.length;
    }
  }
};

Reader::Reader(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
Reader::~Reader() = default;

Result<std::unique_ptr<Reader>> Reader::open(const std::string& path, ReadOptions options) {
  auto impl = std::make_unique<Impl>();
  impl->path = path;
  impl->options = options;
  if (auto ok = impl->open(); !ok) return std::unexpected(ok.error());
  return std::unique_ptr<Reader>(new Reader(std::move(impl)));
}

const std::string& Reader::profile() const noexcept { return impl_->profile; }
const std::string& Reader::library() const noexcept { return impl_->library; }
std::uint64_t Reader::file_size() const noexcept { return impl_->size; }
bool Reader::has_summary() const noexcept { return impl_->summary_start != 0; }
bool Reader::truncated() const noexcept { return impl_->truncated; }
const std::map<std::uint16_t, Schema>& Reader::schemas() const noexcept { return impl_->schemas; }
const std::map<std::uint16_t, Channel>& Reader::channels() const noexcept { return impl_->channels; }
const std::map<std::string, std::map<std::string, std::string>>& Reader::metadata() const noexcept {
  return impl_->metadata;
}

Result<void> Reader::read_messages(const std::function<bool(const Channel&, const Schema*, const Message&)>& f) {
  return impl_->read(f);
}

Result<Statistics> Reader::statistics() {
  if (impl_->stats) return *impl_->stats;
  Statistics s;
  auto ok = impl_->read([&](const Channel& c, const Schema*, const Message& m) {
    s.message_start_time = s.message_count == 0 ? m.log_time : std::min(s.message_start_time, m.log_time);
    s.message_end_time = std::max(s.message_end_time, m.log_time);
    ++s.message_count;
    ++s.channel_message_counts[c.id];
    return true;
  });
  if (!ok) return std::unexpected(ok.error());
  s.schema_count = static_cast<std::uint16_t>(impl_->schemas.size());
  s.channel_count = static_cast<std::uint32_t>(impl_->channels.size());
  impl_->stats = s;
  return s;
}

}  // namespace horus::mcap
