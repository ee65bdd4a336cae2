// libFuzzer target: an MCAP file as `horus record info` and `horus play` read it: open (magic,
// header, footer, summary and its CRC; then again recovering a file cut short), the statistics,
// and every message (chunks decompressed with zstd or lz4, records, CRCs).
#include "fuzz_common.hpp"
#include "horus/record/mcap.hpp"

namespace {
void read_all(const std::string& path, bool recover) {
  horus::mcap::ReadOptions o;
  o.recover = recover;
  o.max_chunk_bytes = std::uint64_t{64} << 20;  // the fuzzer's memory limit is 2 GB
  auto r = horus::mcap::Reader::open(path, o);
  if (!r) return;
  (void)(*r)->statistics();
  std::size_t n = 0;
  (void)(*r)->read_messages([&](const auto&, const auto*, const auto& m) {
    n += m.data.size();
    return true;
  });
}
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  horus::fuzz::MemFile f(data, size);
  if (!f.ok()) return 0;
  read_all(f.path(), false);
  read_all(f.path(), true);
  return 0;
}
