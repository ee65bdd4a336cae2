// libFuzzer target: LCM. The first byte picks what the rest is: an LCM message (fingerprint and
// members, horus::lcm::decode) of a message type of fuzz_common.hpp (the second byte picks it),
// or an LCM URL (the provider, group, port and options that lcm_url.cpp checks).
#include <string_view>

#include "fuzz_codecs.hpp"
#include "fuzz_common.hpp"
#include "horus/wire/lcm.hpp"
#include "lcm_internal.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 2) return 0;
  if ((data[0] & 1u) != 0) {
    (void)horus::lcm::detail::parse_url(std::string_view(reinterpret_cast<const char*>(data + 1), size - 1));
    return 0;
  }
  horus::fuzz::with_type(data[1], [&]<class T>() {
    if constexpr (horus::lcm::expressible<T>) {
      auto m = horus::lcm::decode<T>(horus::fuzz::bytes(data + 2, size - 2));
      if (!m) return;
      horus::fuzz::round_trip(
          *m, [](const T& v) { return horus::lcm::encode(v); },
          [](const std::vector<std::byte>& b) { return horus::lcm::decode<T>(b); });
    }
  });
  return 0;
}
