// The per-type table of the network bridge (WireOps), made from the reflection with the wire
// formats of the bottom layer: XCDR1 for DDS, lcm-gen's encoding for LCM.
// Internal to horus: users include <horus/topic.hpp>.
#pragma once

#include <cstring>
#include <expected>
#include <stdexcept>
#include <string>

#include "horus/byte_buffer.hpp"
#include "horus/detail/network_link.hpp"
#include "horus/wire/lcm.hpp"
#include "horus/wire/xcdr1.hpp"

#include "horus/export.hpp"

HORUS_API_BEGIN

namespace horus::detail {

template <class T>
bool wire_expressible(net::WireFormat format) noexcept {
  return format != net::WireFormat::Lcm || lcm::expressible<T>;
}

template <class T>
Result<std::size_t> wire_encoded_size(net::WireFormat format, const void* msg) {
  const T& m = *static_cast<const T*>(msg);
  try {
    if constexpr (lcm::expressible<T>) {
      if (format == net::WireFormat::Lcm) return lcm::encoded_size(m);
    }
    return cdr::encoded_size(m);
  } catch (const std::logic_error& e) {
    return fail(Errc::MessageTooLarge, e.what());
  }
}

template <class T>
void wire_encode(net::WireFormat format, const void* msg, std::span<std::byte> body) noexcept {
  // Cannot throw: body has encoded_size bytes. Called from the transport's C code, so nothing
  // may escape regardless.
  try {
    if constexpr (lcm::expressible<T>) {
      if (format == net::WireFormat::Lcm) {
        lcm::encode(*static_cast<const T*>(msg), body);
        return;
      }
    }
    cdr::encode(*static_cast<const T*>(msg), body);
  } catch (...) {
    std::memset(body.data(), 0, body.size());
  }
}

/// A received sample as a T; large data may be decoded straight into memory `sink` provides.
template <class T>
std::expected<T, std::string> wire_decode(net::WireFormat format, const net::Sample& sample, const ByteSink* sink) {
  if constexpr (lcm::expressible<T>) {
    if (format == net::WireFormat::Lcm) return lcm::decode<T>(sample.body, sink);
  }
  return cdr::decode<T>(sample.body, sample.little_endian, sink);
}

}  // namespace horus::detail

HORUS_API_END
