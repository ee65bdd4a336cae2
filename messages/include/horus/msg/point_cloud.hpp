// Point clouds (part of the perception domain; perception.hpp includes this file): the
// fixed-size point types PointXYZ, PointXYZRGB, PointXYZI, and the large-data PointCloud with
// its descriptor, an N x K table of one TensorDtype (N points, K fields per point: 3 = XYZ,
// 4 = XYZI, 6 = XYZRGB), stored point after point. Units: metres, ns since the epoch.
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
#include "horus/msg/tensor.hpp"
#include "horus/reflect.hpp"

#include "horus/export.hpp"

HORUS_API_BEGIN

namespace horus::msg {

// ---------------------------------------------------------------------------
/// A 3D point in metres (12 bytes).
struct PointXYZ {
  float x{};
  float y{};
  float z{};

  static constexpr PointXYZ make(float x_m, float y_m, float z_m) noexcept { return PointXYZ{x_m, y_m, z_m}; }

  /// Distance from the origin in metres.
  float distance() const noexcept { return std::sqrt(x * x + y * y + z * z); }
  /// Distance to other in metres.
  float distance_to(const PointXYZ& other) const noexcept {
    const float dx = x - other.x, dy = y - other.y, dz = z - other.z;
    return std::sqrt(dx * dx + dy * dy + dz * dz);
  }

  friend constexpr bool operator==(const PointXYZ&, const PointXYZ&) = default;
};
HORUS_REFLECT(PointXYZ, x, y, z)

/// A 3D point in metres with an 8-bit colour (16 bytes; RGB-D cameras).
struct PointXYZRGB {
  float x{};
  float y{};
  float z{};
  std::uint8_t r{};  ///< 0..255
  std::uint8_t g{};
  std::uint8_t b{};
  std::uint8_t a{};  ///< alpha (or padding); make() and from_xyz() set 255

  /// Opaque colour (a = 255), as HORUS's PointXYZRGB::new.
  static constexpr PointXYZRGB make(float x_m, float y_m, float z_m, std::uint8_t red, std::uint8_t green,
                                    std::uint8_t blue) noexcept {
    return PointXYZRGB{x_m, y_m, z_m, red, green, blue, 255};
  }
  /// The point in opaque white.
  static constexpr PointXYZRGB from_xyz(const PointXYZ& p) noexcept { return make(p.x, p.y, p.z, 255, 255, 255); }

  /// Colour packed as 0xRRGGBBAA.
  constexpr std::uint32_t rgb_packed() const noexcept {
    return (std::uint32_t{r} << 24) | (std::uint32_t{g} << 16) | (std::uint32_t{b} << 8) | std::uint32_t{a};
  }
  constexpr PointXYZ xyz() const noexcept { return PointXYZ{x, y, z}; }

  friend constexpr bool operator==(const PointXYZRGB&, const PointXYZRGB&) = default;
};
HORUS_REFLECT(PointXYZRGB, x, y, z, r, g, b, a)

/// A 3D point in metres with a lidar intensity (reflectance, sensor units;
/// typically 0..255 or 0..65535) (16 bytes).
struct PointXYZI {
  float x{};
  float y{};
  float z{};
  float intensity{};

  static constexpr PointXYZI make(float x_m, float y_m, float z_m, float intensity_) noexcept {
    return PointXYZI{x_m, y_m, z_m, intensity_};
  }
  /// The point with intensity 0.
  static constexpr PointXYZI from_xyz(const PointXYZ& p) noexcept { return PointXYZI{p.x, p.y, p.z, 0.0f}; }
  constexpr PointXYZ xyz() const noexcept { return PointXYZ{x, y, z}; }

  friend constexpr bool operator==(const PointXYZI&, const PointXYZI&) = default;
};
HORUS_REFLECT(PointXYZI, x, y, z, intensity)

static_assert(horus::reflect::is_fixed_size<PointXYZ>, "PointXYZ must be trivially copyable and standard layout");
static_assert(horus::reflect::is_fixed_size<PointXYZRGB>,
              "PointXYZRGB must be trivially copyable and standard layout");
static_assert(horus::reflect::is_fixed_size<PointXYZI>, "PointXYZI must be trivially copyable and standard layout");
static_assert(sizeof(PointXYZ) == 12 && sizeof(PointXYZRGB) == 16 && sizeof(PointXYZI) == 16,
              "point sizes are HORUS's: 12, 16, 16 bytes");

namespace detail {
/// "xyz", "xyzi", "xyzrgb" or "5 fields".
std::string cloud_kind(std::uint32_t fields);
/// "meters", "millimeters", or the dtype in lower case.
inline std::string depth_unit(TensorDtype d) {
  if (d == TensorDtype::F32) return "meters";
  if (d == TensorDtype::U16) return "millimeters";
  return ascii_lower(dtype_text(d));
}
}  // namespace detail

// ---------------------------------------------------------------------------
/// Fixed-size description of a PointCloud (HORUS's 272-byte
/// PointCloudDescriptor also carries per-field names, offsets and types, which
/// this PointCloud does not model: fields are positional, see PointCloud).
struct PointCloudDescriptor {
  std::uint64_t point_count{};
  std::uint32_t fields_per_point{};
  TensorDtype dtype{TensorDtype::F32};
  std::array<char, 32> frame_id{};  ///< reference frame, NUL-terminated, at most 31 characters
  std::uint64_t timestamp_ns{};     ///< ns since the epoch
  std::uint64_t data_size{};        ///< bytes of point data
  // Location of the bytes: filled by the shared-memory pool (next issue); 0 = heap.
  std::uint32_t pool_id{};     ///< pool holding the bytes; 0 = heap (not in a pool)
  std::uint32_t slot_id{};     ///< slot within the pool
  std::uint64_t generation{};  ///< slot generation (guards against reuse of a freed slot)
  std::uint64_t offset{};      ///< byte offset of the data from the pool base

  bool set_frame_id(std::string_view text) noexcept { return set_fixed_str(frame_id, text); }
  std::string_view frame_id_str() const noexcept { return fixed_str_view(frame_id); }

  /// "PointCloudDescriptor(1000 points xyz f32, 11.7 KiB, heap)".
  std::string log_summary() const;

  friend constexpr bool operator==(const PointCloudDescriptor&, const PointCloudDescriptor&) = default;
};
HORUS_REFLECT(PointCloudDescriptor, point_count, fields_per_point, dtype, frame_id, timestamp_ns, data_size, pool_id,
              slot_id, generation, offset)
static_assert(horus::reflect::is_fixed_size<PointCloudDescriptor>,
              "PointCloudDescriptor must be trivially copyable and standard layout");

// ---------------------------------------------------------------------------
/// A point cloud: point_count() points of fields_per_point() values of dtype()
/// each, point after point. Field meaning by position: 0-2 = x, y, z (m);
/// with 4 or 5 fields, 3 = intensity; with 6 or more, 3-5 = r, g, b.
///
///   std::vector<std::array<float, 3>> pts = ...;
///   PointCloud cloud = PointCloud::from_xyz(pts);     // F32, 3 fields
///   auto xyz = cloud.extract_xyz();                   // optional<vector<array<float, 3>>>
///
/// A default-constructed PointCloud is empty (0 points, 0 fields, F32). An
/// empty cloud (0 points) is a valid message ("nothing seen"). Copying a
/// PointCloud copies its points.
class PointCloud : public LargeData<PointCloud, PointCloudDescriptor> {
 public:
  /// Largest encoded message a Topic<PointCloud> carries unless told otherwise: a 130,000-point XYZI cloud (a 64-beam lidar) fits twice over.
  static constexpr std::size_t kDefaultSlotBytes = std::size_t{8} << 20;
  /// Empty cloud: 0 points, 0 fields, F32, no data.
  PointCloud() = default;

  /// A zero-filled cloud of num_points points of fields_per_point values of
  /// dtype (HORUS's PointCloud::new). Throws std::invalid_argument naming the
  /// problem when fields_per_point is 0, dtype is unknown, or the size
  /// overflows or exceeds kMaxLargeDataBytes (2 GiB). num_points may be 0.
  static PointCloud make(std::uint64_t num_points, std::uint32_t fields_per_point, TensorDtype dtype);

  /// Non-throwing form of make(): nullopt for invalid arguments or when the
  /// memory cannot be allocated.
  static std::optional<PointCloud> create(std::uint64_t num_points, std::uint32_t fields_per_point,
                                          TensorDtype dtype) noexcept {
    std::uint64_t bytes = 0;
    if (check(num_points, fields_per_point, dtype, bytes) != detail::SizeError::None) return std::nullopt;
    try {
      PointCloud pc;
      pc.init(num_points, fields_per_point, dtype, bytes);
      return pc;
    } catch (const std::bad_alloc&) {
      return std::nullopt;
    }
  }

  /// An F32 XYZ cloud (3 fields) holding a copy of points. Throws
  /// std::invalid_argument when it would exceed kMaxLargeDataBytes.
  static PointCloud from_xyz(std::span<const std::array<float, 3>> points) {
    PointCloud pc = make(points.size(), 3, TensorDtype::F32);
    for (std::size_t i = 0; i < points.size(); ++i) pc.put_floats(i, points[i]);
    return pc;
  }
  static PointCloud from_xyz(std::span<const PointXYZ> points) {
    PointCloud pc = make(points.size(), 3, TensorDtype::F32);
    for (std::size_t i = 0; i < points.size(); ++i)
      pc.put_floats(i, std::array<float, 3>{points[i].x, points[i].y, points[i].z});
    return pc;
  }

  /// An F32 XYZI cloud (4 fields: x, y, z, intensity) holding a copy of points.
  static PointCloud from_xyzi(std::span<const std::array<float, 4>> points) {
    PointCloud pc = make(points.size(), 4, TensorDtype::F32);
    for (std::size_t i = 0; i < points.size(); ++i) pc.put_floats(i, points[i]);
    return pc;
  }
  static PointCloud from_xyzi(std::span<const PointXYZI> points) {
    PointCloud pc = make(points.size(), 4, TensorDtype::F32);
    for (std::size_t i = 0; i < points.size(); ++i)
      pc.put_floats(i, std::array<float, 4>{points[i].x, points[i].y, points[i].z, points[i].intensity});
    return pc;
  }

  /// An F32 XYZRGB cloud (6 fields: x, y, z, r, g, b) holding a copy of points,
  /// as HORUS's from_xyzrgb(&[[f32; 6]]).
  static PointCloud from_xyzrgb(std::span<const std::array<float, 6>> points) {
    PointCloud pc = make(points.size(), 6, TensorDtype::F32);
    for (std::size_t i = 0; i < points.size(); ++i) pc.put_floats(i, points[i]);
    return pc;
  }
  /// Same from PointXYZRGB: r, g, b become floats 0..255; alpha is dropped.
  static PointCloud from_xyzrgb(std::span<const PointXYZRGB> points) {
    PointCloud pc = make(points.size(), 6, TensorDtype::F32);
    for (std::size_t i = 0; i < points.size(); ++i) {
      const PointXYZRGB& p = points[i];
      pc.put_floats(i, std::array<float, 6>{p.x, p.y, p.z, static_cast<float>(p.r), static_cast<float>(p.g),
                                            static_cast<float>(p.b)});
    }
    return pc;
  }

  // --- metadata -----------------------------------------------------------
  std::uint64_t point_count() const noexcept { return point_count_; }
  /// Values per point (3 = XYZ, 4 = XYZI, 6 = XYZRGB).
  std::uint32_t fields_per_point() const noexcept { return fields_per_point_; }
  TensorDtype dtype() const noexcept { return dtype_; }
  /// Exactly 3 fields per point.
  bool is_xyz() const noexcept { return fields_per_point_ == 3; }
  /// 4 or 5 fields per point: field 3 is intensity. (HORUS says >= 4, which
  /// would call field 3 of an XYZRGB cloud, the red value, an intensity.)
  bool has_intensity() const noexcept { return fields_per_point_ >= 4 && !has_color(); }
  /// 6 or more fields per point: fields 3-5 are r, g, b (as HORUS).
  bool has_color() const noexcept { return fields_per_point_ >= 6; }
  /// Bytes per point.
  std::uint64_t point_size() const noexcept { return std::uint64_t{fields_per_point_} * element_size(dtype_); }

  std::string_view frame_id() const noexcept { return fixed_str_view(frame_id_); }
  /// False, changing nothing, when the name does not fit (at most 31 characters, no NUL).
  bool set_frame_id(std::string_view id) noexcept { return set_fixed_str(frame_id_, id); }
  std::uint64_t timestamp_ns() const noexcept { return timestamp_ns_; }
  PointCloud& set_timestamp_ns(std::uint64_t ns) noexcept {
    timestamp_ns_ = ns;
    return *this;
  }

  // --- points -------------------------------------------------------------
  std::span<const std::uint8_t> data() const noexcept { return data_.view(); }
  /// Writable bytes; a received (borrowed, read-only) buffer is copied first (ByteBuffer).
  std::span<std::uint8_t> data_mut() { return data_.mutable_view(); }

  /// The bytes of point idx (point_size() bytes), or nullopt when idx >= point_count().
  std::optional<std::span<const std::uint8_t>> point_at(std::uint64_t idx) const noexcept {
    const std::uint64_t size = point_size();
    if (idx >= point_count_ || size == 0 || idx >= data_.size() / size) return std::nullopt;
    return std::span<const std::uint8_t>(data_).subspan(static_cast<std::size_t>(idx * size),
                                                        static_cast<std::size_t>(size));
  }

  /// x, y, z (fields 0-2) of every point. nullopt when dtype() is not F32 or
  /// there are fewer than 3 fields per point (or the cloud is inconsistent).
  std::optional<std::vector<std::array<float, 3>>> extract_xyz() const {
    if (dtype_ != TensorDtype::F32 || fields_per_point_ < 3 || !is_consistent()) return std::nullopt;
    std::vector<std::array<float, 3>> out(static_cast<std::size_t>(point_count_));
    const std::size_t stride = static_cast<std::size_t>(point_size());
    for (std::size_t i = 0; i < out.size(); ++i)
      std::memcpy(out[i].data(), data_.data() + i * stride, 3 * sizeof(float));
    return out;
  }

  /// Copies all point data (src.size() must equal data().size()). False,
  /// copying nothing, otherwise (HORUS panics).
  bool copy_from(std::span<const std::uint8_t> src) {
    if (src.size() != data_.size()) return false;
    if (!src.empty()) std::memcpy(data_.data(), src.data(), src.size());
    return true;
  }

  // --- descriptor ---------------------------------------------------------
  /// The fixed-size description of this cloud (pool fields 0: heap).
  PointCloudDescriptor descriptor() const noexcept {
    PointCloudDescriptor d{};
    d.point_count = point_count_;
    d.fields_per_point = fields_per_point_;
    d.dtype = dtype_;
    d.frame_id = frame_id_;
    d.timestamp_ns = timestamp_ns_;
    d.data_size = data_.size();
    return d;
  }

  /// The descriptor of such a message without allocating its bytes: what Topic<PointCloud>::loan
  /// takes to lend a pool slot. nullopt for the arguments the constructor refuses.
  static std::optional<PointCloudDescriptor> describe(std::uint64_t num_points, std::uint32_t fields_per_point, TensorDtype dtype) noexcept {
    std::uint64_t bytes = 0;
    if (check(num_points, fields_per_point, dtype, bytes) != detail::SizeError::None) return std::nullopt;
    PointCloud x;
    x.init_meta(num_points, fields_per_point, dtype);
    PointCloudDescriptor d = x.descriptor();
    d.data_size = bytes;
    return d;
  }

 private:
  friend class LargeData<PointCloud, PointCloudDescriptor>;
  /// What from_descriptor and adopt (LargeData) call.
  /// Rebuilds a cloud from its descriptor and bytes (copied). nullopt unless
  /// fields_per_point > 0, dtype is known, data_size == point_count *
  /// fields_per_point * element size <= kMaxLargeDataBytes, bytes.size() ==
  /// data_size and frame_id is NUL-terminated. The pool fields are not used.
  template <class Bytes>
  static std::optional<PointCloud> build(const PointCloudDescriptor& desc, Bytes&& bytes) {
    std::uint64_t size = 0;
    if (check(desc.point_count, desc.fields_per_point, desc.dtype, size) != detail::SizeError::None)
      return std::nullopt;
    if (size != desc.data_size || bytes.size() != size || !detail::has_terminator(desc.frame_id)) return std::nullopt;
    PointCloud pc;
    pc.point_count_ = desc.point_count;
    pc.fields_per_point_ = desc.fields_per_point;
    pc.dtype_ = desc.dtype;
    pc.frame_id_ = desc.frame_id;
    pc.timestamp_ns_ = desc.timestamp_ns;
    pc.data_ = keep(std::forward<Bytes>(bytes));
    return pc;
  }

 public:

  /// True when data().size() == point_count * point_size() and dtype is known
  /// (always for a cloud made here; maybe not for hand-edited JSON).
  bool is_consistent() const noexcept {
    if (element_size(dtype_) == 0) return false;
    std::uint64_t size = 0;
    return detail::checked_mul(point_count_, point_size(), size) && size == data_.size();
  }

  /// "PointCloud(1000 points xyz f32, 11.7 KiB)".
  std::string log_summary() const;

  friend bool operator==(const PointCloud&, const PointCloud&) = default;

 private:
  std::uint64_t point_count_{};
  std::uint32_t fields_per_point_{};
  TensorDtype dtype_{TensorDtype::F32};
  std::array<char, 32> frame_id_{};
  std::uint64_t timestamp_ns_{};
  ByteBuffer data_;

  HORUS_REFLECT_FRIEND(PointCloud)

  static detail::SizeError check(std::uint64_t num_points, std::uint32_t fields, TensorDtype dtype,
                                 std::uint64_t& bytes) noexcept {
    const std::size_t elem = element_size(dtype);
    if (elem == 0) return detail::SizeError::UnknownType;
    if (fields == 0) return detail::SizeError::ZeroDimension;
    std::uint64_t n = 0;
    if (!detail::checked_mul(num_points, std::uint64_t{fields} * elem, n)) return detail::SizeError::Overflow;
    bytes = n;
    return n > kMaxLargeDataBytes ? detail::SizeError::TooLarge : detail::SizeError::None;
  }

  void init(std::uint64_t num_points, std::uint32_t fields, TensorDtype dtype, std::uint64_t bytes) {
    init_meta(num_points, fields, dtype);
    data_.assign(static_cast<std::size_t>(bytes), std::uint8_t{0});
  }
  void init_meta(std::uint64_t num_points, std::uint32_t fields, TensorDtype dtype) noexcept {
    point_count_ = num_points;
    fields_per_point_ = fields;
    dtype_ = dtype;
  }

  // Writes the floats of point i (F32 clouds built by the factories).
  template <std::size_t N>
  void put_floats(std::size_t i, const std::array<float, N>& values) noexcept {
    std::memcpy(data_.data() + i * N * sizeof(float), values.data(), N * sizeof(float));
  }
};
HORUS_REFLECT_AS(PointCloud, (point_count, point_count_), (fields_per_point, fields_per_point_), (dtype, dtype_),
                 (frame_id, frame_id_), (timestamp_ns, timestamp_ns_), (data, data_))

// The standard messages of this header (Topic<T> takes their network codecs from the library).
HORUS_STANDARD_MESSAGES(PointCloud, PointXYZ, PointXYZRGB, PointXYZI, PointCloudDescriptor)

}  // namespace horus::msg

HORUS_API_END
