#include "horus/transport/encapsulation.hpp"

#include <cstdio>

namespace horus::net::encapsulation {

void write_header_and_padding(std::span<std::byte> serialized, std::size_t body_size) noexcept {
  const std::size_t padding = final_padding(body_size);
  serialized[0] = std::byte{0x00};  // CDR_LE: XCDR1, little endian
  serialized[1] = std::byte{0x01};
  serialized[2] = std::byte{0x00};
  serialized[3] = static_cast<std::byte>(padding);  // options: the final padding count
  for (std::size_t i = 0; i < padding; i++) serialized[kHeaderSize + body_size + i] = std::byte{0};
}

std::variant<Sample, std::string> parse(std::span<const std::byte> serialized) {
  const std::size_t n = serialized.size();
  if (n < kHeaderSize)
    return "a sample of " + std::to_string(n) + " bytes, shorter than the 4-byte encapsulation header; dropped";
  const auto b0 = std::to_integer<unsigned>(serialized[0]);
  const auto b1 = std::to_integer<unsigned>(serialized[1]);
  if (b0 != 0 || b1 > 1) {
    char hex[8];
    std::snprintf(hex, sizeof hex, "0x%02x%02x", b0 & 0xffu, b1 & 0xffu);
    return std::string("a sample with encapsulation ") + hex + ", expected XCDR1 (0x0000 or 0x0001); dropped";
  }
  const std::size_t padding = std::to_integer<std::size_t>(serialized[3]) & 3u;
  const std::size_t available = n - kHeaderSize;
  if (padding > available)
    return "a sample of " + std::to_string(n) + " bytes declares " + std::to_string(padding) +
           " bytes of final padding, more than its body; dropped";
  return Sample{serialized.subspan(kHeaderSize, available - padding), b1 == 1};
}

}  // namespace horus::net::encapsulation
