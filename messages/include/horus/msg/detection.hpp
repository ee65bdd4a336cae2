// Detection messages: BoundingBox2D, BoundingBox3D, Detection, Detection3D.
//
// Fixed-size (trivially copyable) results of object detectors (YOLO, SSD, 3D
// detectors on point clouds). 2D boxes are in pixels, anchored at the top-left
// corner; 3D boxes are in metres, centred, with roll/pitch/yaw in radians
// (see geometry.hpp for the angle convention). The class name is a
// NUL-terminated std::array<char, 32> written through set_fixed_str(): a name
// that does not fit (more than 31 characters) is refused, never cut.
//
// Layout differs from HORUS's Rust structs in two deliberate ways: no private
// padding fields (Rust pads Detection to 72 and BoundingBox3D to 48 bytes), and
// Detection3D's velocity is the spec's [f32; 3] rather than Rust's
// velocity_x/_y/_z (same place in the struct, before instance_id).
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>

#include "horus/fixed_string.hpp"
#include "horus/reflect.hpp"

#include "horus/export.hpp"

HORUS_API_BEGIN

namespace horus::msg {

// ---------------------------------------------------------------------------
/// An axis-aligned 2D box in pixels: top-left corner (x, y), then width and
/// height (expected >= 0). It covers [x, x + width] x [y, y + height].
struct BoundingBox2D {
  float x{};       ///< px, left edge
  float y{};       ///< px, top edge
  float width{};   ///< px
  float height{};  ///< px

  /// The spec's BoundingBox2D::new(x, y, width, height): top-left corner and size.
  static constexpr BoundingBox2D make(float x_px, float y_px, float width_px, float height_px) noexcept {
    return BoundingBox2D{x_px, y_px, width_px, height_px};
  }
  /// From the centre and size (YOLO's cx, cy, w, h).
  static constexpr BoundingBox2D from_center(float cx_px, float cy_px, float width_px, float height_px) noexcept {
    return BoundingBox2D{cx_px - width_px / 2.0f, cy_px - height_px / 2.0f, width_px, height_px};
  }

  constexpr float center_x() const noexcept { return x + width / 2.0f; }
  constexpr float center_y() const noexcept { return y + height / 2.0f; }
  /// (center_x, center_y) in pixels.
  constexpr std::pair<float, float> center() const noexcept { return {center_x(), center_y()}; }

  /// width * height in px^2.
  constexpr float area() const noexcept { return width * height; }

  /// True when (px, py) lies in the box, edges included. False for NaN.
  constexpr bool contains(float px, float py) const noexcept {
    return px >= x && px <= x + width && py >= y && py <= y + height;
  }

  /// Intersection over union, in [0, 1]: 1 for identical boxes, 0 for boxes
  /// that are disjoint or only touch. 0 when the union has no area (two empty
  /// boxes) and when a coordinate is NaN.
  float iou(const BoundingBox2D& other) const noexcept {
    const float x1 = std::max(x, other.x);
    const float y1 = std::max(y, other.y);
    const float x2 = std::min(x + width, other.x + other.width);
    const float y2 = std::min(y + height, other.y + other.height);
    const float iw = x2 - x1 > 0.0f ? x2 - x1 : 0.0f;
    const float ih = y2 - y1 > 0.0f ? y2 - y1 : 0.0f;
    const float inter = iw * ih;
    const float uni = area() + other.area() - inter;
    if (!(uni > 0.0f) || std::isnan(inter)) return 0.0f;
    return inter / uni;
  }

  friend constexpr bool operator==(const BoundingBox2D&, const BoundingBox2D&) = default;
};
HORUS_REFLECT(BoundingBox2D, x, y, width, height)

// ---------------------------------------------------------------------------
/// An oriented 3D box in metres: centre (cx, cy, cz), extents along the box's
/// own X (length), Y (width) and Z (height), orientation roll/pitch/yaw in
/// radians (Euler angles rather than a quaternion, as in HORUS).
struct BoundingBox3D {
  float cx{};      ///< m
  float cy{};      ///< m
  float cz{};      ///< m
  float length{};  ///< m, along X
  float width{};   ///< m, along Y
  float height{};  ///< m, along Z
  float roll{};    ///< rad
  float pitch{};   ///< rad
  float yaw{};     ///< rad

  /// The spec's BoundingBox3D::new(cx, cy, cz, length, width, height, yaw):
  /// rotated about Z only (roll = pitch = 0).
  static constexpr BoundingBox3D make(float cx_m, float cy_m, float cz_m, float length_m, float width_m,
                                      float height_m, float yaw_rad) noexcept {
    return BoundingBox3D{cx_m, cy_m, cz_m, length_m, width_m, height_m, 0.0f, 0.0f, yaw_rad};
  }
  /// With a full rotation.
  static constexpr BoundingBox3D with_rotation(float cx_m, float cy_m, float cz_m, float length_m, float width_m,
                                               float height_m, float roll_rad, float pitch_rad,
                                               float yaw_rad) noexcept {
    return BoundingBox3D{cx_m, cy_m, cz_m, length_m, width_m, height_m, roll_rad, pitch_rad, yaw_rad};
  }

  /// length * width * height in m^3 (rotation does not change it).
  constexpr float volume() const noexcept { return length * width * height; }

  friend constexpr bool operator==(const BoundingBox3D&, const BoundingBox3D&) = default;
};
HORUS_REFLECT(BoundingBox3D, cx, cy, cz, length, width, height, roll, pitch, yaw)

// ---------------------------------------------------------------------------
/// One 2D detection: box (px), confidence in [0, 1], numeric class, class name
/// and an instance id (for instance segmentation; 0 when unused).
struct Detection {
  BoundingBox2D bbox{};
  float confidence{};                 ///< 0..1
  std::uint32_t class_id{};
  std::array<char, 32> class_name{};  ///< NUL-terminated, at most 31 characters
  std::uint32_t instance_id{};

  /// The detection, or nullopt when the class name does not fit (at most 31
  /// characters, no NUL). class_id and instance_id are 0.
  static constexpr std::optional<Detection> create(std::string_view name, float confidence_01, float x_px,
                                                   float y_px, float width_px, float height_px) noexcept {
    Detection d{};
    if (!d.set_class_name(name)) return std::nullopt;
    d.bbox = BoundingBox2D::make(x_px, y_px, width_px, height_px);
    d.confidence = confidence_01;
    return d;
  }

  /// The spec's Detection::new(class_name, confidence, x, y, width, height).
  /// Throws std::invalid_argument when the name does not fit (HORUS's Rust
  /// version cuts it at 31 characters).
  static Detection make(std::string_view name, float confidence_01, float x_px, float y_px, float width_px,
                        float height_px) {
    if (auto d = create(name, confidence_01, x_px, y_px, width_px, height_px)) return *d;
    throw std::invalid_argument("Detection class name '" + std::string(name) + "' has " +
                                std::to_string(name.size()) + " characters; at most 31 fit");
  }

  /// A detection known by class id only (empty class name).
  static constexpr Detection with_class_id(std::uint32_t id, float confidence_01, const BoundingBox2D& box) noexcept {
    Detection d{};
    d.bbox = box;
    d.confidence = confidence_01;
    d.class_id = id;
    return d;
  }

  /// Sets the class name; returns false, changing nothing, when it does not fit.
  constexpr bool set_class_name(std::string_view name) noexcept { return set_fixed_str(class_name, name); }
  constexpr std::string_view class_name_str() const noexcept { return fixed_str_view(class_name); }

  /// confidence >= threshold (so a detection exactly at the threshold passes).
  /// False when either is NaN.
  constexpr bool is_confident(float threshold) const noexcept { return confidence >= threshold; }

  friend constexpr bool operator==(const Detection&, const Detection&) = default;
};
HORUS_REFLECT(Detection, bbox, confidence, class_id, class_name, instance_id)

// ---------------------------------------------------------------------------
/// One 3D detection: box (m, rad), confidence in [0, 1], class, velocity
/// [vx, vy, vz] in m/s (for tracking-enabled detectors, else 0) and an
/// instance / track id.
struct Detection3D {
  BoundingBox3D bbox{};
  float confidence{};                 ///< 0..1
  std::uint32_t class_id{};
  std::array<char, 32> class_name{};  ///< NUL-terminated, at most 31 characters
  std::array<float, 3> velocity{};    ///< m/s, [vx, vy, vz]
  std::uint32_t instance_id{};

  /// The detection, or nullopt when the class name does not fit (at most 31
  /// characters, no NUL). Velocity, class_id and instance_id are 0.
  static constexpr std::optional<Detection3D> create(std::string_view name, float confidence_01,
                                                     const BoundingBox3D& box) noexcept {
    Detection3D d{};
    if (!d.set_class_name(name)) return std::nullopt;
    d.bbox = box;
    d.confidence = confidence_01;
    return d;
  }

  /// The spec's Detection3D::new(class_name, confidence, bbox). Throws
  /// std::invalid_argument when the name does not fit (at most 31 characters).
  static Detection3D make(std::string_view name, float confidence_01, const BoundingBox3D& box) {
    if (auto d = create(name, confidence_01, box)) return *d;
    throw std::invalid_argument("Detection3D class name '" + std::string(name) + "' has " +
                                std::to_string(name.size()) + " characters; at most 31 fit");
  }

  /// A copy with the velocity set (m/s).
  [[nodiscard]] constexpr Detection3D with_velocity(float vx, float vy, float vz) const noexcept {
    Detection3D d = *this;
    d.velocity = {vx, vy, vz};
    return d;
  }

  /// Sets the class name; returns false, changing nothing, when it does not fit.
  constexpr bool set_class_name(std::string_view name) noexcept { return set_fixed_str(class_name, name); }
  constexpr std::string_view class_name_str() const noexcept { return fixed_str_view(class_name); }

  /// confidence >= threshold; false when either is NaN.
  constexpr bool is_confident(float threshold) const noexcept { return confidence >= threshold; }

  /// Magnitude of the velocity in m/s.
  float speed() const noexcept { return std::hypot(velocity[0], velocity[1], velocity[2]); }

  friend constexpr bool operator==(const Detection3D&, const Detection3D&) = default;
};
HORUS_REFLECT(Detection3D, bbox, confidence, class_id, class_name, velocity, instance_id)

static_assert(horus::reflect::is_fixed_size<BoundingBox2D>,
              "BoundingBox2D must be trivially copyable and standard layout");
static_assert(horus::reflect::is_fixed_size<BoundingBox3D>,
              "BoundingBox3D must be trivially copyable and standard layout");
static_assert(horus::reflect::is_fixed_size<Detection>, "Detection must be trivially copyable and standard layout");
static_assert(horus::reflect::is_fixed_size<Detection3D>, "Detection3D must be trivially copyable and standard layout");

// The standard messages of this header (Topic<T> takes their network codecs from the library).
HORUS_STANDARD_MESSAGES(BoundingBox2D, BoundingBox3D, Detection, Detection3D)

}  // namespace horus::msg

HORUS_API_END
