// The functions of horus/msg/large_data.hpp that produce text with fmt, compiled once here so that
// including the header does not pull in fmt.
#include "horus/msg/large_data.hpp"

#include <fmt/format.h>

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

namespace horus::msg {

namespace detail {

std::string size_error_text(SizeError e, std::uint64_t bytes) {
  switch (e) {
    case SizeError::None: return "ok";
    case SizeError::ZeroDimension: return "every dimension must be greater than zero";
    case SizeError::UnknownType: return "unknown element type or encoding";
    case SizeError::Overflow: return "the byte size overflows 64 bits";
    case SizeError::TooLarge:
      return fmt::format("needs {} bytes, more than the {}-byte (2 GiB) limit", bytes, kMaxLargeDataBytes);
    case SizeError::BadShape: return "a tensor has 1 to 8 dimensions";
  }
  return "invalid size";
}

std::string format_bytes(std::uint64_t n) {
  if (n < 1024) return fmt::format("{} B", n);
  static constexpr std::array<std::string_view, 3> kUnits{"KiB", "MiB", "GiB"};
  double v = static_cast<double>(n) / 1024.0;
  std::size_t unit = 0;
  while (v >= 1024.0 && unit + 1 < kUnits.size()) {
    v /= 1024.0;
    ++unit;
  }
  std::string text = fmt::format("{:.1f}", v);
  if (text.size() > 2 && text.ends_with(".0")) text.resize(text.size() - 2);
  return text + " " + std::string(kUnits[unit]);
}

std::string pool_text(std::uint32_t pool_id, std::uint32_t slot_id) {
  return pool_id == 0 ? std::string("heap") : fmt::format("pool {} slot {}", pool_id, slot_id);
}

}  // namespace detail

}  // namespace horus::msg
