// The functions of horus/msg/point_cloud.hpp that produce text with fmt, compiled once here so that
// including the header does not pull in fmt.
#include "horus/msg/point_cloud.hpp"

#include <fmt/format.h>

#include <cstdint>
#include <stdexcept>
#include <string>

namespace horus::msg {

namespace detail {

std::string cloud_kind(std::uint32_t fields) {
  switch (fields) {
    case 3: return "xyz";
    case 4: return "xyzi";
    case 6: return "xyzrgb";
    default: return fmt::format("{} fields", fields);
  }
}

}  // namespace detail

std::string PointCloudDescriptor::log_summary() const {
  return fmt::format("PointCloudDescriptor({} points {} {}, {}, {})", point_count,
                     detail::cloud_kind(fields_per_point), detail::ascii_lower(detail::dtype_text(dtype)),
                     detail::format_bytes(data_size), detail::pool_text(pool_id, slot_id));
}

PointCloud PointCloud::make(std::uint64_t num_points, std::uint32_t fields_per_point, TensorDtype dtype) {
  std::uint64_t bytes = 0;
  const detail::SizeError err = check(num_points, fields_per_point, dtype, bytes);
  if (err != detail::SizeError::None)
    throw std::invalid_argument(fmt::format(
        "horus::msg::PointCloud({} points x {} fields {}): {}", num_points, fields_per_point,
        detail::dtype_text(dtype),
        err == detail::SizeError::ZeroDimension ? std::string("fields_per_point must be greater than zero")
                                                : detail::size_error_text(err, bytes)));
  PointCloud pc;
  pc.init(num_points, fields_per_point, dtype, bytes);
  return pc;
}

std::string PointCloud::log_summary() const {
  return fmt::format("PointCloud({} points {} {}, {})", point_count_, detail::cloud_kind(fields_per_point_),
                     detail::ascii_lower(detail::dtype_text(dtype_)), detail::format_bytes(data_.size()));
}

}  // namespace horus::msg
