// The functions of horus/msg/image.hpp that produce text with fmt, compiled once here so that
// including the header does not pull in fmt.
#include "horus/msg/image.hpp"

#include <fmt/format.h>

#include <cstdint>
#include <stdexcept>
#include <string>
#include <string_view>

namespace horus::msg {

namespace detail {

std::string encoding_text(ImageEncoding e) {
  const std::string_view name = reflect::enum_name(e);
  return name.empty() ? fmt::format("encoding{}", static_cast<int>(e)) : std::string(name);
}

}  // namespace detail

std::string ImageDescriptor::log_summary() const {
  return fmt::format("ImageDescriptor({}x{} {}, {}, {})", width, height, detail::encoding_text(encoding),
                     detail::format_bytes(data_size), detail::pool_text(pool_id, slot_id));
}

Image::Image(std::uint32_t height, std::uint32_t width, ImageEncoding encoding) {
  std::uint64_t bytes = 0;
  const detail::SizeError err = check(height, width, encoding, bytes);
  if (err != detail::SizeError::None)
    throw std::invalid_argument(fmt::format("horus::msg::Image({}x{} {}): {}", width, height,
                                            detail::encoding_text(encoding), detail::size_error_text(err, bytes)));
  init(height, width, encoding, bytes);
}

std::string Image::log_summary() const {
  return fmt::format("Image({}x{} {}, {})", width_, height_, detail::encoding_text(encoding_),
                     detail::format_bytes(data_.size()));
}

}  // namespace horus::msg
