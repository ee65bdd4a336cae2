// Vision messages: CameraInfo, StereoInfo, RegionOfInterest, CompressedImage.
//
// (Image and ImageEncoding live in horus/msg/image.hpp.)
//
// CameraInfo, StereoInfo and RegionOfInterest are fixed-size (trivially
// copyable). CompressedImage carries its bytes in a std::vector and is NOT
// fixed-size, as the spec says ("variable-size, not POD").
//
// As for every message, `T{}` is all zeros: a zero CameraInfo has a zero
// rectification matrix, where HORUS's Rust Default puts the identity. Build a
// usable one with CameraInfo::make(), which sets the identity.
//
// Text fields are NUL-terminated std::array<char, N>, written through
// set_fixed_str(): text that does not fit is refused, never cut. Pixel
// coordinates are in pixels, focal lengths and principal points in pixels,
// baselines and depths in metres, timestamps in ns since the epoch.
#pragma once

#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "horus/fixed_string.hpp"
#include "horus/reflect.hpp"

#include "horus/export.hpp"

HORUS_API_BEGIN

namespace horus::msg {

// ---------------------------------------------------------------------------
/// Calibration of one pinhole camera, laid out like ROS sensor_msgs/CameraInfo.
/// camera_matrix K is 3x3 row-major [fx 0 cx; 0 fy cy; 0 0 1]; projection_matrix
/// P is 3x4 row-major [fx' 0 cx' Tx; 0 fy' cy' Ty; 0 0 1 0]; distortion
/// coefficients are [k1, k2, p1, p2, k3, k4, k5, k6] for the named model
/// ("plumb_bob", "rational_polynomial", ...).
struct CameraInfo {
  std::uint32_t width{};                             ///< px
  std::uint32_t height{};                            ///< px
  std::array<char, 16> distortion_model{};           ///< NUL-terminated, at most 15 characters
  std::array<double, 8> distortion_coefficients{};   ///< k1, k2, p1, p2, k3, k4, k5, k6
  std::array<double, 9> camera_matrix{};             ///< K, 3x3 row-major, px
  std::array<double, 9> rectification_matrix{};      ///< R, 3x3 row-major
  std::array<double, 12> projection_matrix{};        ///< P, 3x4 row-major, px
  std::array<char, 32> frame_id{};                   ///< NUL-terminated, at most 31 characters
  std::uint64_t timestamp_ns{};

  /// The spec's CameraInfo::new(width, height, fx, fy, cx, cy): K and P from the
  /// intrinsics (px), identity rectification, no distortion, no names, timestamp 0.
  static constexpr CameraInfo make(std::uint32_t width_px, std::uint32_t height_px, double fx, double fy, double cx,
                                   double cy) noexcept {
    CameraInfo c{};
    c.width = width_px;
    c.height = height_px;
    c.camera_matrix = {fx, 0.0, cx, 0.0, fy, cy, 0.0, 0.0, 1.0};
    c.rectification_matrix = {1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0};
    c.projection_matrix = {fx, 0.0, cx, 0.0, 0.0, fy, cy, 0.0, 0.0, 0.0, 1.0, 0.0};
    return c;
  }

  /// (fx, fy) in pixels, read from camera_matrix.
  constexpr std::pair<double, double> focal_lengths() const noexcept { return {camera_matrix[0], camera_matrix[4]}; }
  /// (cx, cy) in pixels, read from camera_matrix.
  constexpr std::pair<double, double> principal_point() const noexcept { return {camera_matrix[2], camera_matrix[5]}; }

  /// Sets the distortion model name; returns false, changing nothing, when it
  /// does not fit (at most 15 characters, no NUL).
  constexpr bool set_distortion_model(std::string_view model) noexcept {
    return set_fixed_str(distortion_model, model);
  }
  constexpr std::string_view distortion_model_str() const noexcept { return fixed_str_view(distortion_model); }

  /// A copy with the distortion model set (the spec's with_distortion_model).
  /// Throws std::invalid_argument when the name does not fit (at most 15
  /// characters): HORUS's Rust version cuts it, which would silently turn
  /// "rational_polynomial" into another model's name.
  [[nodiscard]] CameraInfo with_distortion_model(std::string_view model) const {
    CameraInfo c = *this;
    if (!c.set_distortion_model(model))
      throw std::invalid_argument("CameraInfo distortion model '" + std::string(model) + "' has " +
                                  std::to_string(model.size()) + " characters; at most 15 fit");
    return c;
  }

  /// Sets the camera frame; returns false, changing nothing, when it does not
  /// fit (at most 31 characters, no NUL).
  constexpr bool set_frame_id(std::string_view frame) noexcept { return set_fixed_str(frame_id, frame); }
  constexpr std::string_view frame_id_str() const noexcept { return fixed_str_view(frame_id); }

  /// "CameraInfo(640x480 px, f 525.0/525.0 px, c 320.0/240.0 px, plumb_bob, frame camera)";
  /// the model and frame parts are left out when empty.
  std::string log_summary() const;

  friend constexpr bool operator==(const CameraInfo&, const CameraInfo&) = default;
};
HORUS_REFLECT(CameraInfo, width, height, distortion_model, distortion_coefficients, camera_matrix,
              rectification_matrix, projection_matrix, frame_id, timestamp_ns)

// ---------------------------------------------------------------------------
/// A calibrated stereo pair. Depth follows the rectified-stereo relation
/// depth = baseline * fx / disparity, with fx the left camera's focal length
/// (camera_matrix[0], px), baseline in metres and disparity in pixels.
/// depth_scale is carried for the consumer (e.g. the unit of a depth image
/// made from this pair); as in HORUS, the two helpers below do not apply it.
struct StereoInfo {
  CameraInfo left_camera{};
  CameraInfo right_camera{};
  double baseline{};     ///< m, distance between the optical centres
  double depth_scale{};  ///< depth scaling factor (not applied by the helpers)

  /// Depth in metres of a point seen with this disparity (px).
  /// - disparity <= 0 (no match, or a point at infinity): +infinity;
  /// - disparity +infinity: 0; NaN: NaN;
  /// - baseline or fx zero: 0 (an uncalibrated pair gives no depth).
  float depth_from_disparity(float disparity_px) const noexcept {
    if (disparity_px <= 0.0f) return std::numeric_limits<float>::infinity();
    return static_cast<float>(baseline * left_camera.camera_matrix[0] / static_cast<double>(disparity_px));
  }

  /// Disparity in pixels of a point at this depth (m); the inverse of depth_from_disparity.
  /// - depth <= 0 (behind or on the camera): 0;
  /// - depth +infinity: 0; NaN: NaN.
  float disparity_from_depth(float depth_m) const noexcept {
    if (depth_m <= 0.0f) return 0.0f;
    return static_cast<float>(baseline * left_camera.camera_matrix[0] / static_cast<double>(depth_m));
  }

  /// "StereoInfo(640x480 px, baseline 0.120 m, fx 525.0 px, depth scale 0.001)".
  std::string log_summary() const;

  friend constexpr bool operator==(const StereoInfo&, const StereoInfo&) = default;
};
HORUS_REFLECT(StereoInfo, left_camera, right_camera, baseline, depth_scale)

// ---------------------------------------------------------------------------
/// A rectangle of an image in pixels: columns [x_offset, x_offset + width),
/// rows [y_offset, y_offset + height). do_rectify: true when the region is
/// given in (and should be taken from) the rectified image.
struct RegionOfInterest {
  std::uint32_t x_offset{};  ///< px, left column
  std::uint32_t y_offset{};  ///< px, top row
  std::uint32_t width{};     ///< px
  std::uint32_t height{};    ///< px
  bool do_rectify{};

  /// The spec's RegionOfInterest::new(x, y, width, height); do_rectify false.
  static constexpr RegionOfInterest make(std::uint32_t x_px, std::uint32_t y_px, std::uint32_t width_px,
                                         std::uint32_t height_px) noexcept {
    return RegionOfInterest{x_px, y_px, width_px, height_px, false};
  }

  /// True when pixel (x, y) is inside: the left and top edges are in, the right
  /// and bottom edges (x_offset + width, y_offset + height) are out, so an empty
  /// region (width or height 0) contains nothing. Exact for regions that reach
  /// past 2^32 (no overflow).
  constexpr bool contains(std::uint32_t x, std::uint32_t y) const noexcept {
    return x >= x_offset && x - x_offset < width && y >= y_offset && y - y_offset < height;
  }

  /// Number of pixels, width * height. 64-bit so that it cannot overflow (the
  /// Rust version returns u32).
  constexpr std::uint64_t area() const noexcept {
    return static_cast<std::uint64_t>(width) * static_cast<std::uint64_t>(height);
  }

  /// True when the region lies entirely inside an image of image_width x
  /// image_height pixels (an empty region at the image's edge fits).
  constexpr bool fits_in(std::uint32_t image_width, std::uint32_t image_height) const noexcept {
    return std::uint64_t{x_offset} + width <= image_width && std::uint64_t{y_offset} + height <= image_height;
  }

  /// "RegionOfInterest(x 10 px, y 20 px, 100x80 px, rectified)" (", raw" when do_rectify is false).
  std::string log_summary() const;

  friend constexpr bool operator==(const RegionOfInterest&, const RegionOfInterest&) = default;
};
HORUS_REFLECT(RegionOfInterest, x_offset, y_offset, width, height, do_rectify)

// ---------------------------------------------------------------------------
/// An encoded image (JPEG, PNG, WebP ...): the encoded bytes, the format name
/// ("jpeg", "png", "webp"; at most 7 characters) and, when known, the size of
/// the decoded image (0 when unknown). Variable-size: not trivially copyable.
struct CompressedImage {
  /// Largest encoded message a Topic<CompressedImage> carries unless told otherwise (a 1080p JPEG fits).
  static constexpr std::size_t kDefaultSlotBytes = std::size_t{2} << 20;
  std::array<char, 8> format{};     ///< NUL-terminated, at most 7 characters
  std::vector<std::uint8_t> data;   ///< encoded bytes
  std::uint32_t width{};            ///< px of the decoded image, 0 = unknown
  std::uint32_t height{};           ///< px of the decoded image, 0 = unknown
  std::array<char, 32> frame_id{};  ///< NUL-terminated, at most 31 characters
  std::uint64_t timestamp_ns{};

  /// The encoded image, or nullopt when the format name does not fit (at most 7
  /// characters, no NUL). width/height 0 mean unknown; frame and timestamp are
  /// left empty.
  static std::optional<CompressedImage> create(std::string_view format_name, std::vector<std::uint8_t> bytes,
                                               std::uint32_t width_px = 0, std::uint32_t height_px = 0) {
    CompressedImage img{};
    if (!img.set_format(format_name)) return std::nullopt;
    img.data = std::move(bytes);
    img.width = width_px;
    img.height = height_px;
    return img;
  }

  /// The spec's CompressedImage::new(format, data), with the optional decoded
  /// size. Throws std::invalid_argument when the format name does not fit (at
  /// most 7 characters; HORUS's Rust version cuts it).
  static CompressedImage make(std::string_view format_name, std::vector<std::uint8_t> bytes,
                              std::uint32_t width_px = 0, std::uint32_t height_px = 0) {
    if (auto img = create(format_name, std::move(bytes), width_px, height_px)) return std::move(*img);
    throw std::invalid_argument("CompressedImage format '" + std::string(format_name) + "' has " +
                                std::to_string(format_name.size()) + " characters; at most 7 fit");
  }

  /// Sets the format name; returns false, changing nothing, when it does not fit.
  constexpr bool set_format(std::string_view format_name) noexcept { return set_fixed_str(format, format_name); }
  constexpr std::string_view format_str() const noexcept { return fixed_str_view(format); }

  /// Sets the camera frame; returns false, changing nothing, when it does not fit.
  constexpr bool set_frame_id(std::string_view frame) noexcept { return set_fixed_str(frame_id, frame); }
  constexpr std::string_view frame_id_str() const noexcept { return fixed_str_view(frame_id); }

  /// "CompressedImage(jpeg 640x480, 35.2 KiB)". The size is in B below 1 KiB,
  /// then KiB, then MiB; "?x?" stands for an unknown decoded size and
  /// "unknown" for an empty format name.
  std::string log_summary() const;

  friend bool operator==(const CompressedImage&, const CompressedImage&) = default;
};
HORUS_REFLECT(CompressedImage, format, data, width, height, frame_id, timestamp_ns)

static_assert(horus::reflect::is_fixed_size<CameraInfo>, "CameraInfo must be trivially copyable and standard layout");
static_assert(horus::reflect::is_fixed_size<StereoInfo>, "StereoInfo must be trivially copyable and standard layout");
static_assert(horus::reflect::is_fixed_size<RegionOfInterest>,
              "RegionOfInterest must be trivially copyable and standard layout");
static_assert(!horus::reflect::is_fixed_size<CompressedImage>,
              "CompressedImage is variable-size (its bytes live in a std::vector)");

// The standard messages of this header (Topic<T> takes their network codecs from the library).
HORUS_STANDARD_MESSAGES(CompressedImage, CameraInfo, StereoInfo, RegionOfInterest)

}  // namespace horus::msg

HORUS_API_END
