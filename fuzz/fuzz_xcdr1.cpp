// libFuzzer target: a DDS sample as a DDS reader hands it over: the 4-byte encapsulation header
// (net::encapsulation::parse), then the XCDR1 body in the byte order it names (horus::cdr::decode)
// on the message types of fuzz_common.hpp; the first byte picks the type.
#include <variant>

#include "fuzz_codecs.hpp"
#include "fuzz_common.hpp"
#include "horus/transport/encapsulation.hpp"
#include "horus/wire/xcdr1.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const auto sample = horus::net::encapsulation::parse(horus::fuzz::bytes(data + 1, size - 1));
  const auto* s = std::get_if<horus::net::Sample>(&sample);
  if (s == nullptr) return 0;
  horus::fuzz::with_type(data[0], [&]<class T>() {
    auto m = horus::cdr::decode<T>(s->body, s->little_endian);
    if (!m) return;
    horus::fuzz::round_trip(
        *m, [](const T& v) { return horus::cdr::encode(v); },
        [](const std::vector<std::byte>& b) { return horus::cdr::decode<T>(b); });
  });
  return 0;
}
