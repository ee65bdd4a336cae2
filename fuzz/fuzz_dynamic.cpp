// libFuzzer target: what a tool does with a type it was not compiled with (a fleet
// announcement's signature): parse the signature, then decode a message of it into JSON in
// XCDR1 (both byte orders) and LCM. The input is "<signature>\0<message bytes>".
#include <cstring>
#include <string_view>

#include "fuzz_common.hpp"
#include "horus/wire/dynamic.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto* nul = static_cast<const std::uint8_t*>(std::memchr(data, 0, size));
  const std::size_t text = nul == nullptr ? size : static_cast<std::size_t>(nul - data);
  auto type = horus::wire::parse_signature(std::string_view(reinterpret_cast<const char*>(data), text));
  if (!type || nul == nullptr) return 0;
  const auto body = horus::fuzz::bytes(nul + 1, size - text - 1);
  for (const auto format : {horus::wire::DynFormat::Xcdr1, horus::wire::DynFormat::Lcm}) {
    if (!horus::wire::check_expressible(*type, format)) continue;
    (void)horus::wire::decode_json(*type, format, body, true);
    if (format == horus::wire::DynFormat::Xcdr1) (void)horus::wire::decode_json(*type, format, body, false);
  }
  return 0;
}
