// Perception messages: the fixed-size point types (PointXYZ, PointXYZRGB,
// PointXYZI), PointCloud and DepthImage with their descriptors, and (through
// tensor.hpp, included here) TensorDtype, Device, TensorDescriptor and Tensor.
//
// PointCloud and DepthImage are large-data messages (see tensor.hpp): classes
// whose metadata and bytes are private and always agree. A point cloud is an
// N x K table of one TensorDtype (N points, K fields per point: 3 = XYZ,
// 4 = XYZI, 6 = XYZRGB), stored point after point. A depth image is a
// height x width grid of F32 metres or U16 millimetres, row-major.
// Units: metres for coordinates and depths, ns since the epoch for timestamps.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <limits>
#include <new>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>
#include <tuple>
#include <type_traits>
#include <utility>
#include <vector>

#include "horus/byte_buffer.hpp"
#include "horus/fixed_string.hpp"
#include "horus/msg/point_cloud.hpp"  // PointXYZ*, PointCloud
#include "horus/msg/tensor.hpp"
#include "horus/reflect.hpp"

#include "horus/export.hpp"

HORUS_API_BEGIN

namespace horus::msg {

// ---------------------------------------------------------------------------
/// Fixed-size description of a DepthImage (HORUS's 224-byte
/// DepthImageDescriptor also has min_depth / max_depth, which HORUS's
/// DepthImage does not expose; they are left out here).
struct DepthImageDescriptor {
  std::uint32_t width{};   ///< pixels
  std::uint32_t height{};  ///< pixels
  TensorDtype dtype{TensorDtype::F32};  ///< F32 = metres, U16 = millimetres
  float depth_scale{1.0f};              ///< mm per raw unit (U16 images)
  std::array<char, 32> frame_id{};      ///< camera frame, NUL-terminated, at most 31 characters
  std::uint64_t timestamp_ns{};         ///< ns since the epoch
  std::uint64_t data_size{};            ///< bytes of depth data
  // Location of the bytes: filled by the shared-memory pool (next issue); 0 = heap.
  std::uint32_t pool_id{};     ///< pool holding the bytes; 0 = heap (not in a pool)
  std::uint32_t slot_id{};     ///< slot within the pool
  std::uint64_t generation{};  ///< slot generation (guards against reuse of a freed slot)
  std::uint64_t offset{};      ///< byte offset of the data from the pool base

  bool set_frame_id(std::string_view text) noexcept { return set_fixed_str(frame_id, text); }
  std::string_view frame_id_str() const noexcept { return fixed_str_view(frame_id); }

  /// "DepthImageDescriptor(640x480 meters, 1.2 MiB, heap)".
  std::string log_summary() const;

  friend constexpr bool operator==(const DepthImageDescriptor&, const DepthImageDescriptor&) = default;
};
HORUS_REFLECT(DepthImageDescriptor, width, height, dtype, depth_scale, frame_id, timestamp_ns, data_size, pool_id,
              slot_id, generation, offset)
static_assert(horus::reflect::is_fixed_size<DepthImageDescriptor>,
              "DepthImageDescriptor must be trivially copyable and standard layout");

// ---------------------------------------------------------------------------
/// A depth image: height() x width() depths, row-major, either F32 metres
/// (meters()) or U16 raw units (millimeters(); depth in m = raw *
/// depth_scale() / 1000, depth_scale = mm per unit, 1 by default). A depth of
/// 0, NaN or +-inf (or a negative one) means "no measurement".
///
///   DepthImage depth = DepthImage::meters(480, 640);   // height, width
///   depth.set_depth(100, 200, 1.5f);                   // x = 100, y = 200, metres
///   auto [min_m, max_m, mean_m] = depth.depth_statistics();
///
/// A default-constructed DepthImage is empty (0x0, F32, no data). Copying a
/// DepthImage copies its depths.
class DepthImage : public LargeData<DepthImage, DepthImageDescriptor> {
 public:
  /// Largest encoded message a Topic<DepthImage> carries unless told otherwise: a 1920x1080 F32 depth frame.
  static constexpr std::size_t kDefaultSlotBytes = std::size_t{8} << 20;
  /// Empty depth image: 0x0, F32, no data.
  DepthImage() = default;

  /// A zero-filled (no measurement) height x width image of F32 metres. Throws
  /// std::invalid_argument naming the problem when a dimension is 0 or the
  /// size exceeds kMaxLargeDataBytes (2 GiB).
  static DepthImage meters(std::uint32_t height, std::uint32_t width) {
    return make(height, width, TensorDtype::F32);
  }
  /// Same with U16 millimetres (depth_scale 1).
  static DepthImage millimeters(std::uint32_t height, std::uint32_t width) {
    return make(height, width, TensorDtype::U16);
  }
  /// Non-throwing forms: nullopt for invalid arguments or when the memory cannot be allocated.
  static std::optional<DepthImage> create_meters(std::uint32_t height, std::uint32_t width) noexcept {
    return create(height, width, TensorDtype::F32);
  }
  static std::optional<DepthImage> create_millimeters(std::uint32_t height, std::uint32_t width) noexcept {
    return create(height, width, TensorDtype::U16);
  }

  // --- metadata -----------------------------------------------------------
  std::uint32_t width() const noexcept { return width_; }    ///< pixels
  std::uint32_t height() const noexcept { return height_; }  ///< pixels
  TensorDtype dtype() const noexcept { return dtype_; }      ///< F32 or U16
  bool is_meters() const noexcept { return dtype_ == TensorDtype::F32; }
  bool is_millimeters() const noexcept { return dtype_ == TensorDtype::U16; }
  /// Millimetres per raw unit of a U16 image (1 = raw values are mm).
  float depth_scale() const noexcept { return depth_scale_; }
  /// Sets the scale; false, changing nothing, unless it is finite and > 0.
  bool set_depth_scale(float mm_per_unit) noexcept {
    if (!std::isfinite(mm_per_unit) || mm_per_unit <= 0.0f) return false;
    depth_scale_ = mm_per_unit;
    return true;
  }

  std::string_view frame_id() const noexcept { return fixed_str_view(frame_id_); }
  /// False, changing nothing, when the name does not fit (at most 31 characters, no NUL).
  bool set_frame_id(std::string_view id) noexcept { return set_fixed_str(frame_id_, id); }
  std::uint64_t timestamp_ns() const noexcept { return timestamp_ns_; }
  DepthImage& set_timestamp_ns(std::uint64_t ns) noexcept {
    timestamp_ns_ = ns;
    return *this;
  }

  // --- depths -------------------------------------------------------------
  std::span<const std::uint8_t> data() const noexcept { return data_.view(); }
  /// Writable bytes; a received (borrowed, read-only) buffer is copied first (ByteBuffer).
  std::span<std::uint8_t> data_mut() { return data_.mutable_view(); }

  /// Depth at (x, y) in metres (U16: raw * depth_scale / 1000; invalid pixels
  /// come back as stored: 0 or NaN). nullopt when out of bounds.
  std::optional<float> get_depth(std::uint32_t x, std::uint32_t y) const noexcept {
    const auto off = offset_of(x, y);
    if (!off) return std::nullopt;
    if (is_meters()) return detail::load_at<float>(data_, *off);
    const auto raw = detail::load_at<std::uint16_t>(data_, *off);
    return static_cast<float>(static_cast<double>(raw) * static_cast<double>(depth_scale_) / 1000.0);
  }

  /// Raw U16 value at (x, y); nullopt when out of bounds or the image is F32.
  std::optional<std::uint16_t> get_depth_u16(std::uint32_t x, std::uint32_t y) const noexcept {
    if (!is_millimeters()) return std::nullopt;
    const auto off = offset_of(x, y);
    if (!off) return std::nullopt;
    return detail::load_at<std::uint16_t>(data_, *off);
  }

  /// Stores a depth in metres at (x, y). F32 images store any value (NaN or 0
  /// marks "no measurement"). U16 images store round(metres * 1000 /
  /// depth_scale); false when that is NaN, infinite, negative or above 65535
  /// (HORUS returns an error there, and truncates instead of rounding).
  /// False, changing nothing, when (x, y) is out of bounds. (HORUS returns
  /// &mut Self; the bool lets a caller notice a refused value.)
  bool set_depth(std::uint32_t x, std::uint32_t y, float metres) {
    const auto off = offset_of(x, y);
    if (!off) return false;
    if (is_meters()) {
      detail::store_at(data_mut(), *off, metres);
      return true;
    }
    const double raw = std::round(static_cast<double>(metres) * 1000.0 / static_cast<double>(depth_scale_));
    if (!std::isfinite(raw) || raw < 0.0 || raw > 65535.0) return false;
    detail::store_at(data_mut(), *off, static_cast<std::uint16_t>(raw));
    return true;
  }

  /// (min, max, mean) in metres over the valid pixels: those whose depth is
  /// finite and > 0 (0, NaN, +-inf and negative depths are skipped, as HORUS).
  /// (0, 0, 0) when no pixel is valid (newer HORUS returns None there).
  std::tuple<float, float, float> depth_statistics() const noexcept {
    float lo = std::numeric_limits<float>::max();
    float hi = std::numeric_limits<float>::lowest();
    double sum = 0.0;
    std::uint64_t count = 0;
    for (std::uint32_t y = 0; y < height_; ++y)
      for (std::uint32_t x = 0; x < width_; ++x) {
        const auto d = get_depth(x, y);
        if (!d || !std::isfinite(*d) || *d <= 0.0f) continue;
        lo = std::min(lo, *d);
        hi = std::max(hi, *d);
        sum += static_cast<double>(*d);
        ++count;
      }
    if (count == 0) return {0.0f, 0.0f, 0.0f};
    return {lo, hi, static_cast<float>(sum / static_cast<double>(count))};
  }

  /// Copies all depth data (src.size() must equal data().size()). False,
  /// copying nothing, otherwise.
  bool copy_from(std::span<const std::uint8_t> src) {
    if (src.size() != data_.size()) return false;
    if (!src.empty()) std::memcpy(data_.data(), src.data(), src.size());
    return true;
  }

  // --- descriptor ---------------------------------------------------------
  /// The fixed-size description of this depth image (pool fields 0: heap).
  DepthImageDescriptor descriptor() const noexcept {
    DepthImageDescriptor d{};
    d.width = width_;
    d.height = height_;
    d.dtype = dtype_;
    d.depth_scale = depth_scale_;
    d.frame_id = frame_id_;
    d.timestamp_ns = timestamp_ns_;
    d.data_size = data_.size();
    return d;
  }

  /// The descriptor of such a message without allocating its bytes: what Topic<DepthImage>::loan
  /// takes to lend a pool slot. nullopt for the arguments the constructor refuses.
  static std::optional<DepthImageDescriptor> describe(std::uint32_t height, std::uint32_t width, TensorDtype dtype = TensorDtype::F32) noexcept {
    std::uint64_t bytes = 0;
    if (check(height, width, dtype, bytes) != detail::SizeError::None) return std::nullopt;
    DepthImage x;
    x.init_meta(height, width, dtype);
    DepthImageDescriptor d = x.descriptor();
    d.data_size = bytes;
    return d;
  }

 private:
  friend class LargeData<DepthImage, DepthImageDescriptor>;
  /// What from_descriptor and adopt (LargeData) call.
  /// Rebuilds a depth image from its descriptor and bytes (copied). nullopt
  /// unless dtype is F32 or U16, width and height are > 0, data_size == width *
  /// height * element size <= kMaxLargeDataBytes, bytes.size() == data_size,
  /// depth_scale is finite and > 0 and frame_id is NUL-terminated.
  template <class Bytes>
  static std::optional<DepthImage> build(const DepthImageDescriptor& desc, Bytes&& bytes) {
    std::uint64_t size = 0;
    if (check(desc.height, desc.width, desc.dtype, size) != detail::SizeError::None) return std::nullopt;
    if (size != desc.data_size || bytes.size() != size || !detail::has_terminator(desc.frame_id)) return std::nullopt;
    DepthImage img;
    if (!img.set_depth_scale(desc.depth_scale)) return std::nullopt;
    img.width_ = desc.width;
    img.height_ = desc.height;
    img.dtype_ = desc.dtype;
    img.frame_id_ = desc.frame_id;
    img.timestamp_ns_ = desc.timestamp_ns;
    img.data_ = keep(std::forward<Bytes>(bytes));
    return img;
  }

 public:

  /// True when dtype is F32 or U16 and data().size() == width * height *
  /// element size (always for an image made here; maybe not for hand-edited JSON).
  bool is_consistent() const noexcept {
    if (!is_meters() && !is_millimeters()) return false;
    std::uint64_t size = 0;
    return detail::checked_mul(std::uint64_t{width_} * height_, element_size(dtype_), size) && size == data_.size();
  }

  /// "DepthImage(640x480 meters, 1.2 MiB)" or "DepthImage(640x480 millimeters, 600 KiB)".
  std::string log_summary() const;

  friend bool operator==(const DepthImage&, const DepthImage&) = default;

 private:
  std::uint32_t width_{};
  std::uint32_t height_{};
  TensorDtype dtype_{TensorDtype::F32};
  float depth_scale_{1.0f};
  std::array<char, 32> frame_id_{};
  std::uint64_t timestamp_ns_{};
  ByteBuffer data_;

  HORUS_REFLECT_FRIEND(DepthImage)

  static detail::SizeError check(std::uint32_t height, std::uint32_t width, TensorDtype dtype,
                                 std::uint64_t& bytes) noexcept {
    if (dtype != TensorDtype::F32 && dtype != TensorDtype::U16) return detail::SizeError::UnknownType;
    if (width == 0 || height == 0) return detail::SizeError::ZeroDimension;
    std::uint64_t n = 0;  // width * height < 2^64, but times the element size may overflow
    if (!detail::checked_mul(std::uint64_t{width} * height, element_size(dtype), n)) return detail::SizeError::Overflow;
    bytes = n;
    return n > kMaxLargeDataBytes ? detail::SizeError::TooLarge : detail::SizeError::None;
  }

  static DepthImage make(std::uint32_t height, std::uint32_t width, TensorDtype dtype);

  static std::optional<DepthImage> create(std::uint32_t height, std::uint32_t width, TensorDtype dtype) noexcept {
    std::uint64_t bytes = 0;
    if (check(height, width, dtype, bytes) != detail::SizeError::None) return std::nullopt;
    try {
      DepthImage img;
      img.init(height, width, dtype, bytes);
      return img;
    } catch (const std::bad_alloc&) {
      return std::nullopt;
    }
  }

  void init(std::uint32_t height, std::uint32_t width, TensorDtype dtype, std::uint64_t bytes) {
    init_meta(height, width, dtype);
    data_.assign(static_cast<std::size_t>(bytes), std::uint8_t{0});
  }
  void init_meta(std::uint32_t height, std::uint32_t width, TensorDtype dtype) noexcept {
    width_ = width;
    height_ = height;
    dtype_ = dtype;
  }

  // Byte offset of pixel (x, y) when it is inside the image and inside data_.
  std::optional<std::size_t> offset_of(std::uint32_t x, std::uint32_t y) const noexcept {
    if (x >= width_ || y >= height_ || (!is_meters() && !is_millimeters())) return std::nullopt;
    const std::uint64_t elem = element_size(dtype_);
    const std::uint64_t off = (std::uint64_t{y} * width_ + x) * elem;
    if (off + elem > data_.size()) return std::nullopt;
    return static_cast<std::size_t>(off);
  }
};
HORUS_REFLECT_AS(DepthImage, (width, width_), (height, height_), (dtype, dtype_), (depth_scale, depth_scale_),
                 (frame_id, frame_id_), (timestamp_ns, timestamp_ns_), (data, data_))

// The standard messages of this header (Topic<T> takes their network codecs from the library).
HORUS_STANDARD_MESSAGES(DepthImage, DepthImageDescriptor)

}  // namespace horus::msg

HORUS_API_END
