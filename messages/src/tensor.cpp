// The functions of horus/msg/tensor.hpp that produce text with fmt, compiled once here so that
// including the header does not pull in fmt.
#include "horus/msg/tensor.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>

namespace horus::msg {

namespace detail {

std::string dtype_text(TensorDtype d) {
  const std::string_view name = reflect::enum_name(d);
  return name.empty() ? fmt::format("dtype{}", static_cast<int>(d)) : std::string(name);
}

}  // namespace detail

std::string Device::log_summary() const {
  if (is_cpu()) return "cpu";
  if (is_cuda()) return fmt::format("cuda:{}", device_id);
  return fmt::format("device{}:{}", static_cast<int>(device_type), device_id);
}

std::string TensorDescriptor::log_summary() const {
  const std::span<const std::uint64_t> dims(shape.data(), std::min<std::size_t>(ndim, kMaxDims));
  return fmt::format("TensorDescriptor([{}] {} {}, {}, {})", detail::join_dims(dims), detail::dtype_text(dtype),
                     device.log_summary(), detail::format_bytes(data_size), detail::pool_text(pool_id, slot_id));
}

Tensor::Tensor(std::span<const std::uint64_t> shape, TensorDtype dtype, Device device) {
  std::uint64_t bytes = 0;
  const detail::SizeError err = check(shape, dtype, bytes);
  if (err != detail::SizeError::None)
    throw std::invalid_argument(fmt::format("horus::msg::Tensor([{}] {}): {}", detail::join_dims(shape),
                                            detail::dtype_text(dtype), detail::size_error_text(err, bytes)));
  init(shape, dtype, device, bytes);
}

std::string Tensor::log_summary() const {
  return fmt::format("Tensor([{}] {} {}, {})", detail::join_dims(shape()), detail::dtype_text(dtype_),
                     device_.log_summary(), detail::format_bytes(nbytes()));
}

}  // namespace horus::msg
