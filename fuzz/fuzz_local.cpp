// libFuzzer target: the local codec (horus::codec::decode, the bytes of serialized shared-memory
// topics and recordings) on the message types of fuzz_common.hpp; the first byte picks the type.
// A GenericMessage's MessagePack payload is unpacked too, and printed by log_summary().
#include <map>
#include <string>
#include <type_traits>
#include <vector>

#include "fuzz_codecs.hpp"
#include "fuzz_common.hpp"
#include "horus/msg/generic_value.hpp"
#include "horus/wire/local.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  horus::fuzz::with_type(data[0], [&]<class T>() {
    auto m = horus::codec::decode<T>(horus::fuzz::bytes(data + 1, size - 1));
    if (!m) return;
    if constexpr (std::is_same_v<T, horus::msg::GenericMessage>) {
      // Its MessagePack payload, as `horus bench`'s control topic and `horus topic echo` unpack it.
      (void)m->template to_value<std::map<std::string, std::string>>();
      (void)m->template to_value<std::vector<double>>();
      (void)m->log_summary();  // its own MessagePack reader (msgpack_text.hpp)
    }
    horus::fuzz::round_trip(
        *m, [](const T& v) { return horus::codec::encode(v); },
        [](const std::vector<std::byte>& b) { return horus::codec::decode<T>(b); });
  });
  return 0;
}
