// The functions of horus/msg/vision.hpp that produce text with fmt, compiled once here so that
// including the header does not pull in fmt.
#include "horus/msg/vision.hpp"

#include <fmt/format.h>

#include <string>
#include <string_view>

namespace horus::msg {

std::string CameraInfo::log_summary() const {
  const auto [fx, fy] = focal_lengths();
  const auto [cx, cy] = principal_point();
  std::string out = fmt::format("CameraInfo({}x{} px, f {:.1f}/{:.1f} px, c {:.1f}/{:.1f} px", width, height, fx,
                                fy, cx, cy);
  if (!distortion_model_str().empty()) out += fmt::format(", {}", distortion_model_str());
  if (!frame_id_str().empty()) out += fmt::format(", frame {}", frame_id_str());
  out += ')';
  return out;
}

std::string StereoInfo::log_summary() const {
  return fmt::format("StereoInfo({}x{} px, baseline {:.3f} m, fx {:.1f} px, depth scale {})", left_camera.width,
                     left_camera.height, baseline, left_camera.camera_matrix[0], depth_scale);
}

std::string RegionOfInterest::log_summary() const {
  return fmt::format("RegionOfInterest(x {} px, y {} px, {}x{} px, {})", x_offset, y_offset, width, height,
                     do_rectify ? "rectified" : "raw");
}

std::string CompressedImage::log_summary() const {
  const std::string_view fmt_name = format_str().empty() ? std::string_view("unknown") : format_str();
  const std::string dims =
      width == 0 || height == 0 ? std::string("?x?") : fmt::format("{}x{}", width, height);
  const double bytes = static_cast<double>(data.size());
  std::string size;
  if (data.size() < 1024) {
    size = fmt::format("{} B", data.size());
  } else if (data.size() < 1024 * 1024) {
    size = fmt::format("{:.1f} KiB", bytes / 1024.0);
  } else {
    size = fmt::format("{:.1f} MiB", bytes / (1024.0 * 1024.0));
  }
  return fmt::format("CompressedImage({} {}, {})", fmt_name, dims, size);
}

}  // namespace horus::msg
