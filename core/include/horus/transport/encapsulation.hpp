// The 4-byte encapsulation header in front of an XCDR1 sample (OMG DDS-XTypes 7.6.3.1.2), for
// the DDS transports: two bytes naming the representation and byte order (0x0000 CDR_BE,
// 0x0001 CDR_LE), two bytes of options whose two low bits count the zero bytes of final padding
// that round the body up to a multiple of 4.
#pragma once

#include <cstddef>
#include <span>
#include <string>
#include <variant>

#include "horus/network.hpp"

#include "horus/export.hpp"

HORUS_API_BEGIN

namespace horus::net::encapsulation {

inline constexpr std::size_t kHeaderSize = 4;

/// The zero bytes after a body of `body_size` bytes: up to the next multiple of 4.
constexpr std::size_t final_padding(std::size_t body_size) noexcept { return (4 - body_size % 4) % 4; }

/// Header + body + final padding.
constexpr std::size_t serialized_size(std::size_t body_size) noexcept {
  return kHeaderSize + body_size + final_padding(body_size);
}

/// Writes the header of a little-endian XCDR1 sample (CDR_LE) with a body of `body_size` bytes,
/// and zeroes the final padding: `serialized` holds serialized_size(body_size) bytes.
void write_header_and_padding(std::span<std::byte> serialized, std::size_t body_size) noexcept;

/// The body (header and final padding removed) and byte order of a received sample, or what
/// is wrong with it, to follow "<label>: " in a message: "a sample of 2 bytes, shorter than the
/// 4-byte encapsulation header; dropped".
std::variant<Sample, std::string> parse(std::span<const std::byte> serialized);

}  // namespace horus::net::encapsulation

HORUS_API_END
