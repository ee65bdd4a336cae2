#include "schemas.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstring>
#include <limits>
#include <span>

#include "horus/msg/all.hpp"
#include "horus/topic.hpp"
#include "horus/waitset.hpp"

namespace horus::tools::fox {
namespace {

// ---- the schemas (OMG IDL, as @foxglove/schemas defines them) --------------------------------
constexpr std::string_view kTime = R"IDL(  struct Time {
    uint32 sec;
    uint32 nsec;
  };
)IDL";
constexpr std::string_view kPose = R"IDL(  struct Vector3 {
    double x;
    double y;
    double z;
  };
  struct Quaternion {
    double x;
    double y;
    double z;
    @default(1.0) double w;
  };
  struct Pose {
    Vector3 position;
    Quaternion orientation;
  };
)IDL";

// `module foxglove { <parts> };`
std::string module(std::initializer_list<std::string_view> parts) {
  std::string s = "module foxglove {\n";
  for (auto p : parts) s += p;
  return s + "};\n";
}

const std::string& idl_raw_image() {
  static const std::string s = module({kTime, R"IDL(  struct RawImage {
    Time timestamp;
    string frame_id;
    uint32 width;
    uint32 height;
    string encoding;
    uint32 step;
    sequence<uint8> data;
  };
)IDL"});
  return s;
}
const std::string& idl_compressed_image() {
  static const std::string s = module({kTime, R"IDL(  struct CompressedImage {
    Time timestamp;
    string frame_id;
    sequence<uint8> data;
    string format;
  };
)IDL"});
  return s;
}
const std::string& idl_point_cloud() {
  static const std::string s = module({kTime, kPose, R"IDL(  enum NumericType {
    UNKNOWN,
    UINT8,
    INT8,
    UINT16,
    INT16,
    UINT32,
    INT32,
    FLOAT32,
    FLOAT64
  };
  struct PackedElementField {
    string name;
    uint32 offset;
    NumericType type;
  };
  struct PointCloud {
    Time timestamp;
    string frame_id;
    Pose pose;
    uint32 point_stride;
    sequence<PackedElementField> fields;
    sequence<uint8> data;
  };
)IDL"});
  return s;
}
const std::string& idl_laser_scan() {
  static const std::string s = module({kTime, kPose, R"IDL(  struct LaserScan {
    Time timestamp;
    string frame_id;
    Pose pose;
    double start_angle;
    double end_angle;
    sequence<double> ranges;
    sequence<double> intensities;
  };
)IDL"});
  return s;
}
const std::string& idl_pose_in_frame() {
  static const std::string s = module({kTime, kPose, R"IDL(  struct PoseInFrame {
    Time timestamp;
    string frame_id;
    Pose pose;
  };
)IDL"});
  return s;
}
const std::string& idl_frame_transform() {
  static const std::string s = module({kTime, kPose, R"IDL(  struct FrameTransform {
    Time timestamp;
    string parent_frame_id;
    string child_frame_id;
    Vector3 translation;
    Quaternion rotation;
  };
)IDL"});
  return s;
}

// ---- XCDR1 little-endian, with its encapsulation header --------------------------------------
class Cdr {
 public:
  explicit Cdr(std::vector<std::byte>& out) : out_(out) {
    out_.clear();
    out_.insert(out_.end(), {std::byte{0}, std::byte{1}, std::byte{0}, std::byte{0}});  // CDR_LE
  }
  void u32(std::uint32_t v) { put(v); }
  void f64(double v) { put(v); }
  void time(std::uint64_t ns) {
    u32(static_cast<std::uint32_t>(ns / 1'000'000'000ULL));
    u32(static_cast<std::uint32_t>(ns % 1'000'000'000ULL));
  }
  void str(std::string_view s) {
    u32(static_cast<std::uint32_t>(s.size() + 1));
    const auto* p = reinterpret_cast<const std::byte*>(s.data());
    out_.insert(out_.end(), p, p + s.size());
    out_.push_back(std::byte{0});
  }
  void bytes(std::span<const std::uint8_t> b) {
    u32(static_cast<std::uint32_t>(b.size()));
    const auto* p = reinterpret_cast<const std::byte*>(b.data());
    out_.insert(out_.end(), p, p + b.size());
  }
  // A byte sequence of n bytes written by `fill` in place (no intermediate copy).
  std::span<std::uint8_t> bytes_in_place(std::size_t n) {
    u32(static_cast<std::uint32_t>(n));
    const std::size_t at = out_.size();
    out_.resize(at + n);
    return {reinterpret_cast<std::uint8_t*>(out_.data() + at), n};
  }
  void pose(const std::array<double, 3>& p, const std::array<double, 4>& q) {
    for (double v : p) f64(v);
    for (double v : q) f64(v);
  }

 private:
  template <class V>
  void put(V v) {
    while ((out_.size() - 4) % sizeof(V) != 0) out_.push_back(std::byte{0});
    std::array<std::byte, sizeof(V)> b;
    std::memcpy(b.data(), &v, sizeof(V));  // x86-64 and aarch64: little-endian already
    out_.insert(out_.end(), b.begin(), b.end());
  }
  std::vector<std::byte>& out_;
};

std::uint64_t stamp_or_now(std::uint64_t ns) {
  if (ns != 0) return ns;
  return static_cast<std::uint64_t>(
      std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::system_clock::now().time_since_epoch())
          .count());
}

std::array<double, 4> yaw_quaternion(double theta) { return {0.0, 0.0, std::sin(theta / 2), std::cos(theta / 2)}; }

// ---- the conversions ----------------------------------------------------------------------
std::string_view raw_encoding(msg::ImageEncoding e) {
  using E = msg::ImageEncoding;
  switch (e) {
    case E::Mono8:
      return "mono8";
    case E::Mono16:
      return "mono16";
    case E::Rgb8:
      return "rgb8";
    case E::Bgr8:
      return "bgr8";
    case E::Rgba8:
      return "rgba8";
    case E::Bgra8:
      return "bgra8";
    case E::Yuv422:
      return "yuv422";
    case E::Mono32F:
      return "32FC1";
    case E::Rgb32F:
      return "rgb8";  // converted
    case E::BayerRggb8:
      return "bayer_rggb8";
    case E::Depth16:
      return "16UC1";
  }
  return "";
}

void convert(const msg::Image& m, const std::string&, const std::string&, std::vector<std::byte>& out) {
  Cdr c(out);
  c.time(stamp_or_now(m.timestamp_ns()));
  c.str(m.frame_id());
  c.u32(m.width());
  c.u32(m.height());
  c.str(raw_encoding(m.encoding()));
  if (m.encoding() == msg::ImageEncoding::Rgb32F) {  // Foxglove draws no float RGB: 8 bits a channel
    c.u32(m.width() * 3);
    auto dst = c.bytes_in_place(std::size_t{m.width()} * 3 * m.height());
    const auto src = m.data();
    for (std::uint32_t y = 0; y < m.height(); ++y)
      for (std::uint32_t i = 0; i < m.width() * 3; ++i) {
        float f = 0;
        std::memcpy(&f, src.data() + std::size_t{y} * m.step() + std::size_t{i} * 4, 4);
        const float v = std::isfinite(f) ? std::clamp(f, 0.0f, 1.0f) : 0.0f;
        dst[std::size_t{y} * m.width() * 3 + i] = static_cast<std::uint8_t>(std::lround(v * 255.0f));
      }
    return;
  }
  c.u32(m.step());
  c.bytes(m.data());
}

void convert(const msg::DepthImage& m, const std::string&, const std::string&, std::vector<std::byte>& out) {
  Cdr c(out);
  c.time(stamp_or_now(m.timestamp_ns()));
  c.str(m.frame_id());
  c.u32(m.width());
  c.u32(m.height());
  c.str(m.is_meters() ? "32FC1" : "16UC1");
  c.u32(m.width() * (m.is_meters() ? 4 : 2));
  c.bytes(m.data());
}

void convert(const msg::CompressedImage& m, const std::string&, const std::string&, std::vector<std::byte>& out) {
  Cdr c(out);
  c.time(stamp_or_now(m.timestamp_ns));
  c.str(horus::fixed_str_view(m.frame_id));
  c.bytes(m.data);
  c.str(horus::fixed_str_view(m.format));
}

std::uint32_t numeric_type(msg::TensorDtype d) {
  using D = msg::TensorDtype;
  switch (d) {
    case D::U8:
      return 1;
    case D::I8:
      return 2;
    case D::U16:
      return 3;
    case D::I16:
      return 4;
    case D::U32:
      return 5;
    case D::I32:
      return 6;
    case D::F32:
      return 7;
    case D::F64:
      return 8;
    default:
      return 0;  // UNKNOWN: F16, BF16, 64-bit integers, Bool have no Foxglove type
  }
}

void convert(const msg::PointCloud& m, const std::string&, const std::string& frame, std::vector<std::byte>& out) {
  Cdr c(out);
  c.time(stamp_or_now(m.timestamp_ns()));
  c.str(m.frame_id().empty() ? std::string_view(frame) : m.frame_id());
  c.pose({0, 0, 0}, {0, 0, 0, 1});
  c.u32(static_cast<std::uint32_t>(m.point_size()));
  std::vector<std::string_view> names{"x", "y", "z"};
  const std::uint32_t n = m.fields_per_point();
  if (n == 4 || n == 5) names.push_back("intensity");
  if (n >= 6) names.insert(names.end(), {"red", "green", "blue"});
  if (n >= 7) names.push_back("alpha");
  names.resize(std::min<std::size_t>(names.size(), n));
  c.u32(static_cast<std::uint32_t>(names.size()));
  const auto size = static_cast<std::uint32_t>(msg::element_size(m.dtype()));
  for (std::size_t i = 0; i < names.size(); ++i) {
    c.str(names[i]);
    c.u32(static_cast<std::uint32_t>(i) * size);
    c.u32(numeric_type(m.dtype()));
  }
  c.bytes(m.data());
}

void convert(const msg::LaserScan& m, const std::string&, const std::string& frame, std::vector<std::byte>& out) {
  Cdr c(out);
  c.time(stamp_or_now(m.timestamp_ns));
  c.str(frame);
  c.pose({0, 0, 0}, {0, 0, 0, 1});
  const std::size_t n = m.ranges.size();
  c.f64(m.angle_min);
  c.f64(static_cast<double>(m.angle_min) + static_cast<double>(m.angle_increment) * static_cast<double>(n - 1));
  c.u32(static_cast<std::uint32_t>(n));
  for (std::size_t i = 0; i < n; ++i)
    c.f64(m.is_range_valid(i) ? static_cast<double>(m.ranges[i]) : std::numeric_limits<double>::quiet_NaN());
  c.u32(0);  // no intensities
}

void pose_in_frame(Cdr& c, std::uint64_t stamp, std::string_view frame, const std::array<double, 3>& p,
                   const std::array<double, 4>& q) {
  c.time(stamp_or_now(stamp));
  c.str(frame);
  c.pose(p, q);
}

void convert(const msg::Pose2D& m, const std::string&, const std::string& frame, std::vector<std::byte>& out) {
  Cdr c(out);
  pose_in_frame(c, m.timestamp_ns, frame, {m.x, m.y, 0}, yaw_quaternion(m.theta));
}

void convert(const msg::Pose3D& m, const std::string&, const std::string& frame, std::vector<std::byte>& out) {
  Cdr c(out);
  pose_in_frame(c, m.timestamp_ns, frame, {m.position.x, m.position.y, m.position.z},
                {m.orientation.x, m.orientation.y, m.orientation.z, m.orientation.w});
}

void convert(const msg::Odometry& m, const std::string&, const std::string& frame, std::vector<std::byte>& out) {
  Cdr c(out);
  const auto own = m.frame_id_str();
  pose_in_frame(c, m.timestamp_ns, own.empty() ? std::string_view(frame) : own, {m.pose.x, m.pose.y, 0},
                yaw_quaternion(m.pose.theta));
}

void convert(const msg::TransformStamped& m, const std::string& topic, const std::string& frame,
             std::vector<std::byte>& out) {
  Cdr c(out);
  c.time(stamp_or_now(m.timestamp_ns));
  c.str(frame);
  c.str(topic);
  for (double v : m.translation) c.f64(v);
  for (double v : m.rotation) c.f64(v);
}

// ---- the source ---------------------------------------------------------------------------
template <class T>
class ConvertedSource final : public RecordSource {
 public:
  ConvertedSource(Topic<T> topic, const FoxgloveSchema& schema, std::string frame)
      : topic_(std::move(topic)),
        base_(topic_.name()),
        name_(base_ + std::string(kConvertedSuffix)),
        frame_(std::move(frame)) {
    type_.name = std::string(schema.name);
    type_.schema = std::string(schema.idl);
  }
  const std::string& topic() const override { return name_; }
  const RecordedType& type() const override { return type_; }
  std::string scope() const override { return std::string(horus::to_string(topic_.scope())); }
  std::optional<std::string> unsupported(RecordFormat format) const override {
    if (format == RecordFormat::Lcm) return std::string("Foxglove's schemas are recorded into MCAP only");
    return std::nullopt;
  }
  std::optional<std::uint64_t> next(RecordFormat, std::vector<std::byte>& out) override {
    auto m = topic_.recv();
    if (!m) return std::nullopt;
    const T& msg = *m;
    convert(msg, base_, frame_, out);
    return record_detail::own_stamp(msg);
  }
  bool attach(WaitSet& ws) override {
    try {
      ws.attach(topic_);
      return true;
    } catch (const Exception&) {
      return false;
    }
  }
  std::uint64_t dropped() const override { return topic_.dropped_count(); }

 private:
  Topic<T> topic_;
  std::string base_;  // the horus topic
  std::string name_;  // base_/foxglove
  std::string frame_;
  RecordedType type_;
};

struct Conversion {
  std::string_view horus;  // unqualified
  FoxgloveSchema schema;
  std::unique_ptr<RecordSource> (*open)(const std::string&, const TopicOptions&, const FoxgloveSchema&,
                                        const std::string&, std::string&);
};

template <class T>
std::unique_ptr<RecordSource> open_as(const std::string& name, const TopicOptions& o, const FoxgloveSchema& schema,
                                      const std::string& frame, std::string& error) {
  auto t = Topic<T>::open(name, o);
  if (!t) {
    error = t.error().message();
    return nullptr;
  }
  return std::make_unique<ConvertedSource<T>>(std::move(*t), schema, frame);
}

const std::array<Conversion, 9>& conversions() {
  static const std::array<Conversion, 9> table = {{
      {"Image", {"foxglove::RawImage", idl_raw_image()}, &open_as<msg::Image>},
      {"DepthImage", {"foxglove::RawImage", idl_raw_image()}, &open_as<msg::DepthImage>},
      {"CompressedImage", {"foxglove::CompressedImage", idl_compressed_image()}, &open_as<msg::CompressedImage>},
      {"PointCloud", {"foxglove::PointCloud", idl_point_cloud()}, &open_as<msg::PointCloud>},
      {"LaserScan", {"foxglove::LaserScan", idl_laser_scan()}, &open_as<msg::LaserScan>},
      {"Pose2D", {"foxglove::PoseInFrame", idl_pose_in_frame()}, &open_as<msg::Pose2D>},
      {"Pose3D", {"foxglove::PoseInFrame", idl_pose_in_frame()}, &open_as<msg::Pose3D>},
      {"Odometry", {"foxglove::PoseInFrame", idl_pose_in_frame()}, &open_as<msg::Odometry>},
      {"TransformStamped", {"foxglove::FrameTransform", idl_frame_transform()}, &open_as<msg::TransformStamped>},
  }};
  return table;
}

const Conversion* find(std::string_view type) {
  if (type.starts_with("horus::msg::")) type.remove_prefix(12);
  for (const auto& c : conversions())
    if (c.horus == type) return &c;
  return nullptr;
}

}  // namespace

const FoxgloveSchema* foxglove_schema_of(std::string_view horus_type) {
  const auto* c = find(horus_type);
  return c ? &c->schema : nullptr;
}

std::unique_ptr<RecordSource> open_foxglove_source(std::string_view horus_type, const std::string& name,
                                                   const TopicOptions& options, const std::string& frame,
                                                   std::string& error) {
  const auto* c = find(horus_type);
  if (c == nullptr) {
    error = std::string(horus_type) + " has no conversion to a Foxglove schema";
    return nullptr;
  }
  return c->open(name, options, c->schema, frame, error);
}

}  // namespace horus::tools::fox
