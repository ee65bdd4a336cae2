// The functions of horus/msg/perception.hpp that produce text with fmt, compiled once here so that
// including the header does not pull in fmt.
#include "horus/msg/perception.hpp"

#include <fmt/format.h>

#include <cstdint>
#include <stdexcept>
#include <string>

namespace horus::msg {

std::string DepthImageDescriptor::log_summary() const {
  return fmt::format("DepthImageDescriptor({}x{} {}, {}, {})", width, height, detail::depth_unit(dtype),
                     detail::format_bytes(data_size), detail::pool_text(pool_id, slot_id));
}

std::string DepthImage::log_summary() const {
  return fmt::format("DepthImage({}x{} {}, {})", width_, height_, detail::depth_unit(dtype_),
                     detail::format_bytes(data_.size()));
}

DepthImage DepthImage::make(std::uint32_t height, std::uint32_t width, TensorDtype dtype) {
  std::uint64_t bytes = 0;
  const detail::SizeError err = check(height, width, dtype, bytes);
  if (err != detail::SizeError::None)
    throw std::invalid_argument(fmt::format("horus::msg::DepthImage({}x{} {}): {}", width, height,
                                            detail::depth_unit(dtype), detail::size_error_text(err, bytes)));
  DepthImage img;
  img.init(height, width, dtype, bytes);
  return img;
}

}  // namespace horus::msg
