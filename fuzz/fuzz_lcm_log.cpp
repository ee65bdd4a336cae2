// libFuzzer target: an LCM event log (lcm-logger's format) as `horus play` reads it: events with
// their sync word, numbers, times, channel and data lengths.
#include "fuzz_common.hpp"
#include "horus/record/lcm_log.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  horus::fuzz::MemFile f(data, size);
  if (!f.ok()) return 0;
  auto r = horus::lcmlog::Reader::open(f.path());
  if (!r) return 0;
  std::size_t n = 0;
  (void)(*r)->read([&](const horus::lcmlog::Event& e) {
    n += e.channel.size() + e.data.size();
    return true;
  });
  return 0;
}
