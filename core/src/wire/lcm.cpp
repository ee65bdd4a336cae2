// The LCM codec's error texts (horus/wire/lcm.hpp), compiled once.
#include "horus/wire/lcm.hpp"

#include <string>

namespace horus::lcm::detail {

std::string hex64(std::uint64_t v) {
  static constexpr char kDigits[] = "0123456789abcdef";
  std::string out = "0x";
  for (int shift = 60; shift >= 0; shift -= 4) out += kDigits[(v >> shift) & 0xf];
  return out;
}

std::string fingerprint_error(std::string_view type, std::uint64_t got, std::uint64_t want) {
  return std::string(type) + ": fingerprint " + hex64(got) + ", expected " + hex64(want) +
         " (a message of another LCM type on this channel, another version of the type, or not an LCM message)";
}

}  // namespace horus::lcm::detail
