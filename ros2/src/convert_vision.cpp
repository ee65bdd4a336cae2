// The vision conversions (convert.hpp): images, compressed images, camera calibrations, point
// clouds. Pixel and point bytes go as one run each way (memcpy speed), into the topic's pool
// slot when the bridge gives a ByteSink.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <optional>
#include <string>
#include <utility>

#include "cdr_io.hpp"
#include "horus/msg/image.hpp"
#include "horus/msg/point_cloud.hpp"
#include "horus/msg/vision.hpp"

namespace horus::ros2::detail {
namespace {

/// n bytes of the body (their count already read and checked) into a ByteBuffer: a pool slot
/// from the reader's ByteSink when there is one, else the heap.
bool vision_take_bytes(In& in, std::size_t n, ByteBuffer& out, std::string_view field) {
  const ByteSink* sink = in.r.sink;
  if (sink != nullptr && sink->place != nullptr && !sink->place(sink->context, n, out))
    return in.over(field, "no pool slot for " + std::to_string(n) + " bytes");
  const auto* p = reinterpret_cast<const std::uint8_t*>(in.r.here());
  out.assign(p, p + n);  // a writable slot of n bytes: one memcpy
  in.r.skip(n);
  return true;
}

// -- sensor_msgs/msg/Image ------------------------------------------------------------------------

struct VisionEncodingName {
  msg::ImageEncoding encoding;
  std::string_view ros;  // sensor_msgs/image_encodings.hpp's name
};
constexpr std::array<VisionEncodingName, 11> kVisionEncodings{{
    {msg::ImageEncoding::Mono8, "mono8"},
    {msg::ImageEncoding::Mono16, "mono16"},
    {msg::ImageEncoding::Rgb8, "rgb8"},
    {msg::ImageEncoding::Bgr8, "bgr8"},
    {msg::ImageEncoding::Rgba8, "rgba8"},
    {msg::ImageEncoding::Bgra8, "bgra8"},
    {msg::ImageEncoding::Yuv422, "yuv422"},
    {msg::ImageEncoding::Mono32F, "32FC1"},
    {msg::ImageEncoding::Rgb32F, "32FC3"},
    {msg::ImageEncoding::BayerRggb8, "bayer_rggb8"},
    {msg::ImageEncoding::Depth16, "16UC1"},
}};

std::string_view vision_encoding_name(msg::ImageEncoding e) noexcept {
  for (const auto& n : kVisionEncodings)
    if (n.encoding == e) return n.ros;
  return {};
}
std::optional<msg::ImageEncoding> vision_encoding_of(std::string_view ros) noexcept {
  for (const auto& n : kVisionEncodings)
    if (n.ros == ros) return n.encoding;
  return std::nullopt;
}
std::string vision_encoding_list() {
  std::string out;
  for (const auto& n : kVisionEncodings) out += (out.empty() ? "" : ", ") + std::string(n.ros);
  return out;
}

/// Why an Image's descriptor and byte count cannot be a horus::msg::Image (false), before the
/// bytes are placed; true when they can.
bool vision_image_fits(In& in, const msg::ImageDescriptor& d, std::size_t n) {
  const std::uint64_t row = std::uint64_t{d.width} * msg::bytes_per_pixel(d.encoding);
  const std::uint64_t size = std::uint64_t{d.step} * d.height;
  const std::string dims = std::to_string(d.width) + "x" + std::to_string(d.height);
  if (d.width == 0 || d.height == 0)
    return in.over("width", "a " + dims + " image; horus::msg::Image needs a width and height above 0");
  if (d.step < row)
    return in.malformed("step", std::to_string(d.step) + " bytes, below the " + std::to_string(row) +
                                    " of a " + dims + " row");
  if (n != size)
    return in.malformed("data", std::to_string(n) + " bytes, expected step * height = " + std::to_string(size));
  if (size > msg::kMaxLargeDataBytes)
    return in.over("data", std::to_string(size) + " bytes; horus::msg::Image holds at most 2 GiB");
  return true;
}

struct ImageImage {
  using Horus = msg::Image;
  static constexpr std::string_view kRos = "sensor_msgs/msg/Image";
  static constexpr bool kPreferred = true;
  static constexpr std::string_view kLoses =
      "to ROS 2: header.frame_id is the rule's frame_id when frame_id is empty; encodings as "
      "sensor_msgs/image_encodings names them (Mono32F 32FC1, Rgb32F 32FC3, Depth16 16UC1), is_bigendian 0; "
      "from ROS 2: an encoding horus has no ImageEncoding for, big-endian 16- or 32-bit pixels and a 0x0 image "
      "are refused";
  template <class S>
  static void put(Out<S>& o, const Horus& m, const Context& ctx) {
    o.header(m.timestamp_ns(), frame_or(m.frame_id(), ctx.frame_id));
    o.num(m.height());
    o.num(m.width());
    o.string(vision_encoding_name(m.encoding()));
    o.num(std::uint8_t{0});  // is_bigendian
    o.num(m.step());
    o.sequence(m.data());  // one run: memcpy speed
  }
  static bool get(In& in, Horus& m) {
    msg::ImageDescriptor d{};
    std::string_view frame, encoding;
    std::uint8_t big_endian = 0;
    if (!in.header(d.timestamp_ns, frame) ||
        !in.text(d.frame_id, frame, "header.frame_id", "horus::msg::Image.frame_id") || !in.num(d.height, "height") || !in.num(d.width, "width") || !in.string_view(encoding, "encoding"))
      return false;
    const auto enc = vision_encoding_of(encoding);
    if (!enc)
      return in.over("encoding", "'" + std::string(encoding.substr(0, 40)) + "'; horus::msg::ImageEncoding holds " +
                                     vision_encoding_list());
    d.encoding = *enc;
    if (!in.num(big_endian, "is_bigendian")) return false;
    if (big_endian != 0 && msg::bytes_per_pixel(d.encoding) / msg::channels(d.encoding) > 1)
      return in.over("is_bigendian", "big-endian " + std::string(encoding) + " pixels; horus images are little-endian");
    std::size_t n = 0;
    if (!in.num(d.step, "step") || !in.count(n, 1, "data") || !vision_image_fits(in, d, n)) return false;
    ByteBuffer bytes;
    if (!vision_take_bytes(in, n, bytes, "data")) return false;
    d.data_size = n;
    auto image = msg::Image::adopt(d, std::move(bytes));
    if (!image) return in.malformed("data", "not an image horus can hold (" + std::string(encoding) + ")");
    m = std::move(*image);
    return true;
  }
};

// -- sensor_msgs/msg/CompressedImage ----------------------------------------------------------------

struct CompressedImageCompressedImage {
  using Horus = msg::CompressedImage;
  static constexpr std::string_view kRos = "sensor_msgs/msg/CompressedImage";
  static constexpr bool kPreferred = true;
  static constexpr std::string_view kLoses =
      "to ROS 2: width and height (ROS 2 has none), header.frame_id is the rule's frame_id when frame_id is "
      "empty; from ROS 2: width and height are 0 (unknown); image_transport's format (\"rgb8; jpeg compressed "
      "bgr8\") is its compression, jpeg or png; another format over 7 characters is refused";
  template <class S>
  static void put(Out<S>& o, const Horus& m, const Context& ctx) {
    o.header(m.timestamp_ns, frame_or(m.frame_id_str(), ctx.frame_id));
    o.string(m.format);
    o.sequence(std::span<const std::uint8_t>(m.data));
  }
  static bool get(In& in, Horus& m) {
    std::string_view frame;
    std::size_t n = 0;
    std::string_view format;
    if (!in.header(m.timestamp_ns, frame) ||
        !in.text(m.frame_id, frame, "header.frame_id", "horus::msg::CompressedImage.frame_id") ||
        !in.string_view(format, "format"))
      return false;
    // image_transport writes "<encoding>; <jpeg|png> compressed <encoding>": the compression is the format.
    if (format.size() >= m.format.size() && format.find(" compressed") != std::string_view::npos)
      format = format.find("png") != std::string_view::npos ? "png" : format.find("jpeg") != std::string_view::npos ? "jpeg" : format;
    if (!in.text(m.format, format, "format", "horus::msg::CompressedImage.format") || !in.count(n, 1, "data")) return false;
    const auto* p = reinterpret_cast<const std::uint8_t*>(in.r.here());
    m.data.assign(p, p + n);
    in.r.skip(n);
    m.width = 0;
    m.height = 0;
    return true;
  }
};

// -- sensor_msgs/msg/CameraInfo ---------------------------------------------------------------------

/// The distortion coefficients ROS 2 gets: plumb_bob's 5, equidistant's 4, none for no model and
/// no coefficients, else all 8 (rational_polynomial's).
std::size_t vision_distortion_count(const msg::CameraInfo& m) noexcept {
  const std::string_view model = m.distortion_model_str();
  if (model == "plumb_bob") return 5;
  if (model == "equidistant") return 4;
  const auto& d = m.distortion_coefficients;
  if (model.empty() && std::all_of(d.begin(), d.end(), [](double v) { return v == 0.0; })) return 0;
  return d.size();
}

struct CameraInfoCameraInfo {
  using Horus = msg::CameraInfo;
  static constexpr std::string_view kRos = "sensor_msgs/msg/CameraInfo";
  static constexpr bool kPreferred = true;
  static constexpr std::string_view kLoses =
      "to ROS 2: d has plumb_bob's 5 coefficients, equidistant's 4, none without a model and coefficients, else "
      "all 8; binning 0 and an empty roi (full resolution); header.frame_id is the rule's frame_id when frame_id is "
      "empty; from ROS 2: binning_x, binning_y and roi are dropped, missing coefficients are 0; a distortion_model "
      "over 15 characters or more than 8 coefficients are refused";
  template <class S>
  static void put(Out<S>& o, const Horus& m, const Context& ctx) {
    o.header(m.timestamp_ns, frame_or(m.frame_id_str(), ctx.frame_id));
    o.num(m.height);
    o.num(m.width);
    o.string(m.distortion_model);
    o.sequence(std::span<const double>(m.distortion_coefficients.data(), vision_distortion_count(m)));
    o.run(std::span<const double>(m.camera_matrix));
    o.run(std::span<const double>(m.rectification_matrix));
    o.run(std::span<const double>(m.projection_matrix));
    o.num(std::uint32_t{0});  // binning_x
    o.num(std::uint32_t{0});  // binning_y
    for (int i = 0; i < 4; ++i) o.num(std::uint32_t{0});  // roi x_offset, y_offset, height, width
    o.boolean(false);                                     // roi.do_rectify
  }
  static bool get(In& in, Horus& m) {
    std::string_view frame;
    std::size_t n = 0;
    m.distortion_coefficients.fill(0.0);
    if (!in.header(m.timestamp_ns, frame) ||
        !in.text(m.frame_id, frame, "header.frame_id", "horus::msg::CameraInfo.frame_id") ||
        !in.num(m.height, "height") || !in.num(m.width, "width") ||
        !in.string(m.distortion_model, "distortion_model", "horus::msg::CameraInfo.distortion_model") ||
        !in.sequence(m.distortion_coefficients.data(), m.distortion_coefficients.size(), n, "d",
                     "horus::msg::CameraInfo.distortion_coefficients", "coefficients") ||
        !in.run(m.camera_matrix.data(), 9, "k") || !in.run(m.rectification_matrix.data(), 9, "r") ||
        !in.run(m.projection_matrix.data(), 12, "p"))
      return false;
    std::array<std::uint32_t, 6> dropped{};  // binning_x, binning_y, roi's offsets and size
    bool rectify = false;
    return in.run(dropped.data(), 2, "binning_x") && in.run(dropped.data() + 2, 4, "roi") &&
           in.boolean(rectify, "roi.do_rectify");
  }
};

// -- sensor_msgs/msg/PointCloud2 --------------------------------------------------------------------

// sensor_msgs/msg/PointField's datatypes.
constexpr std::uint8_t kPointUint8 = 2;

/// The PointField datatype of a TensorDtype (0: none) and of a datatype the TensorDtype.
std::uint8_t vision_point_datatype(msg::TensorDtype d) noexcept {
  switch (d) {
    case msg::TensorDtype::I8: return 1;
    case msg::TensorDtype::U8: return 2;
    case msg::TensorDtype::I16: return 3;
    case msg::TensorDtype::U16: return 4;
    case msg::TensorDtype::I32: return 5;
    case msg::TensorDtype::U32: return 6;
    case msg::TensorDtype::F32: return 7;
    case msg::TensorDtype::F64: return 8;
    default: return 0;
  }
}
std::optional<msg::TensorDtype> vision_point_dtype(std::uint8_t datatype) noexcept {
  constexpr std::array<msg::TensorDtype, 8> kDtypes{msg::TensorDtype::I8,  msg::TensorDtype::U8,  msg::TensorDtype::I16,
                                                    msg::TensorDtype::U16, msg::TensorDtype::I32, msg::TensorDtype::U32,
                                                    msg::TensorDtype::F32, msg::TensorDtype::F64};
  if (datatype < 1 || datatype > kDtypes.size()) return std::nullopt;
  return kDtypes[datatype - 1];
}

/// The name of field i of a horus cloud of k fields, by position (point_cloud.hpp): x, y, z; with 4
/// or 5 fields, intensity; with 6 or more, r, g, b; any other "field<i>".
std::string vision_point_name(std::size_t i, std::size_t k) {
  static constexpr std::array<std::string_view, 6> kNames{"x", "y", "z", "r", "g", "b"};
  if (i < 3 || (k >= 6 && i < 6)) return std::string(kNames[i]);
  if (i == 3 && (k == 4 || k == 5)) return "intensity";
  return "field" + std::to_string(i);
}
/// True for a field whose name horus gives a meaning (x, y, z, intensity, r, g, b).
bool vision_point_named(std::size_t i, std::size_t k) noexcept {
  return i < 3 || (k >= 4 && k <= 5 && i == 3) || (k >= 6 && i < 6);
}

/// No NaN or infinity among the values of a floating-point cloud (PointCloud2.is_dense).
bool vision_cloud_dense(const msg::PointCloud& m) noexcept {
  const auto data = m.data();
  if (m.dtype() == msg::TensorDtype::F32) {
    for (std::size_t i = 0; i + sizeof(float) <= data.size(); i += sizeof(float))
      if (!std::isfinite(msg::detail::load_at<float>(data, i))) return false;
  } else if (m.dtype() == msg::TensorDtype::F64) {
    for (std::size_t i = 0; i + sizeof(double) <= data.size(); i += sizeof(double))
      if (!std::isfinite(msg::detail::load_at<double>(data, i))) return false;
  }
  return true;
}

/// Reads PointCloud2.fields: one datatype horus holds, count 1 each, back to back from offset 0,
/// named as horus's positions mean (x, y, z, then intensity or r, g, b). k: the number of fields.
bool vision_read_fields(In& in, std::size_t& k, msg::TensorDtype& dtype) {
  if (!in.count(k, 12, "fields")) return false;
  if (k == 0) return in.over("fields", "no fields; horus::msg::PointCloud needs at least one");
  std::uint8_t first = 0;
  for (std::size_t i = 0; i < k; ++i) {
    const std::string at = "fields[" + std::to_string(i) + "]";
    std::string_view name;
    std::uint32_t offset = 0, count = 0;
    std::uint8_t datatype = 0;
    if (!in.string_view(name, at + ".name") || !in.num(offset, at + ".offset") || !in.num(datatype, at + ".datatype") ||
        !in.num(count, at + ".count"))
      return false;
    const auto d = vision_point_dtype(datatype);
    if (!d)
      return in.over(at + ".datatype", std::to_string(datatype) + " ('" + std::string(name) +
                                           "'); horus::msg::PointCloud holds INT8..FLOAT64 (1..8)");
    if (i == 0) {
      first = datatype;
      dtype = *d;
    }
    if (datatype != first)
      return in.over(at + ".datatype", std::to_string(datatype) + " ('" + std::string(name) + "'), fields[0] is " +
                                           std::to_string(first) + "; horus::msg::PointCloud holds one datatype");
    if (count != 1)
      return in.over(at + ".count", std::to_string(count) + " ('" + std::string(name) +
                                        "'); horus::msg::PointCloud holds one value per field");
    const std::uint64_t expected = std::uint64_t{i} * msg::element_size(*d);
    if (offset != expected)
      return in.over(at + ".offset", std::to_string(offset) + " ('" + std::string(name) + "'), expected " +
                                         std::to_string(expected) + "; horus::msg::PointCloud holds packed fields");
    if (vision_point_named(i, k) && name != vision_point_name(i, k))
      return in.over(at + ".name", "'" + std::string(name) + "'; field " + std::to_string(i) + " of a horus cloud of " +
                                       std::to_string(k) + " fields is " + vision_point_name(i, k));
  }
  return true;
}

struct PointCloudPointCloud2 {
  using Horus = msg::PointCloud;
  static constexpr std::string_view kRos = "sensor_msgs/msg/PointCloud2";
  static constexpr bool kPreferred = true;
  static constexpr std::string_view kLoses =
      "to ROS 2: one PointField per horus field, named by position (x, y, z; intensity with 4 or 5 fields; r, g, b "
      "with 6 or more; field<i> beyond), height 1, is_dense false only when a float value is NaN or infinite; "
      "F16, BF16, I64 and U64 (no PointField datatype) go as UINT8 fields of count 2 or 8, Bool as UINT8; "
      "header.frame_id is the rule's frame_id when frame_id is empty; from ROS 2: height (an organized cloud is "
      "flattened row after row), is_dense, the field names; fields of mixed datatypes, padded or out of order, "
      "with a count other than 1, or whose names do not mean what horus's positions do (x, y, z, intensity, "
      "r, g, b) are refused, as are big-endian clouds of multi-byte values";
  template <class S>
  static void put(Out<S>& o, const Horus& m, const Context& ctx) {
    o.header(m.timestamp_ns(), frame_or(m.frame_id(), ctx.frame_id));
    const std::size_t k = m.fields_per_point();
    const auto size = static_cast<std::uint32_t>(msg::element_size(m.dtype()));
    const std::uint8_t datatype = vision_point_datatype(m.dtype());
    const auto width = static_cast<std::uint32_t>(m.point_count());
    const auto step = static_cast<std::uint32_t>(m.point_size());
    o.num(std::uint32_t{1});  // height
    o.num(width);
    o.count(k);
    for (std::size_t i = 0; i < k; ++i) {
      o.string(vision_point_name(i, k));
      o.num(static_cast<std::uint32_t>(i * size));
      o.num(datatype != 0 ? datatype : kPointUint8);
      o.num(datatype != 0 ? std::uint32_t{1} : size);
    }
    o.boolean(false);  // is_bigendian
    o.num(step);
    o.num(step * width);  // row_step
    o.sequence(m.data());
    bool dense = true;
    if constexpr (!S::kCounting) dense = vision_cloud_dense(m);
    o.boolean(dense);
  }
  static bool get(In& in, Horus& m) {
    msg::PointCloudDescriptor d{};
    std::string_view frame;
    std::uint32_t height = 0, width = 0, point_step = 0, row_step = 0;
    std::size_t k = 0, n = 0;
    bool big_endian = false, dense = false;
    if (!in.header(d.timestamp_ns, frame) ||
        !in.text(d.frame_id, frame, "header.frame_id", "horus::msg::PointCloud.frame_id") ||
        !in.num(height, "height") || !in.num(width, "width") || !vision_read_fields(in, k, d.dtype) ||
        !in.boolean(big_endian, "is_bigendian") || !in.num(point_step, "point_step") || !in.num(row_step, "row_step"))
      return false;
    const std::uint64_t packed = std::uint64_t{k} * msg::element_size(d.dtype);
    if (big_endian && msg::element_size(d.dtype) > 1)
      return in.over("is_bigendian", "big-endian values; horus point clouds are little-endian");
    if (point_step != packed)
      return in.over("point_step", std::to_string(point_step) + ", expected " + std::to_string(packed) +
                                       " (packed fields); horus::msg::PointCloud holds no padding");
    if (row_step != std::uint64_t{width} * point_step)
      return in.over("row_step", std::to_string(row_step) + ", expected width * point_step = " +
                                     std::to_string(std::uint64_t{width} * point_step) + "; horus holds no padding");
    if (!in.count(n, 1, "data")) return false;
    if (n != std::uint64_t{height} * row_step)
      return in.malformed("data", std::to_string(n) + " bytes, expected height * row_step = " +
                                      std::to_string(std::uint64_t{height} * row_step));
    if (n > msg::kMaxLargeDataBytes)
      return in.over("data", std::to_string(n) + " bytes; horus::msg::PointCloud holds at most 2 GiB");
    ByteBuffer bytes;
    if (!vision_take_bytes(in, n, bytes, "data") || !in.boolean(dense, "is_dense")) return false;
    d.point_count = std::uint64_t{height} * width;
    d.fields_per_point = static_cast<std::uint32_t>(k);
    d.data_size = n;
    auto cloud = msg::PointCloud::adopt(d, std::move(bytes));
    if (!cloud) return in.malformed("data", "not a point cloud horus can hold");
    m = std::move(*cloud);
    return true;
  }
};

constexpr Conversion kVision[] = {
    make_conversion<ImageImage>(),
    make_conversion<CompressedImageCompressedImage>(),
    make_conversion<CameraInfoCameraInfo>(),
    make_conversion<PointCloudPointCloud2>(),
};

}  // namespace

std::span<const Conversion> vision_conversions() noexcept { return kVision; }

}  // namespace horus::ros2::detail
