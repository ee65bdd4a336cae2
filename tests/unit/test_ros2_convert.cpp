// horus messages <-> ROS 2 common interfaces (ros2/include/horus/ros2/convert.hpp), checked
// against the dynamic codec (dynamic.hpp): every conversion's bytes read back BY FIELD NAME as
// ROS 2 lays the type out, re-encode to the same bytes, and decode to the horus message again;
// ROS 2 samples built from JSON (not by the converter) decode or are refused naming the field.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <map>
#include <optional>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "horus/messages.hpp"
#include "horus/ros2/convert.hpp"
#include "horus/ros2/dynamic.hpp"
#include "horus/ros2/interface.hpp"

namespace {

namespace msg = horus::msg;
namespace ros2 = horus::ros2;
using horus::ros2::Context;
using horus::ros2::Conversion;
using horus::ros2::Interfaces;
using horus::ros2::Refusal;
using nlohmann::json;

constexpr std::uint64_t kStamp = 1'700'000'123'456'789'012;  // 2023-11-14, sec 1700000123, nanosec 456789012
constexpr Context kCtx{"rule_frame", "rule_child"};

const Interfaces& ros_types() { return Interfaces::standard(); }

/// The value at "a.b.3.c" (names and indices), or null with a failure.
json at(const json& j, std::string_view path) {
  const json* p = &j;
  for (std::size_t dot = 0; !path.empty(); path = dot == path.npos ? std::string_view{} : path.substr(dot + 1)) {
    dot = path.find('.');
    const std::string part(path.substr(0, dot));
    const bool index = p->is_array() && std::all_of(part.begin(), part.end(), ::isdigit) && !part.empty();
    if (index && std::stoul(part) < p->size()) {
      p = &(*p)[std::stoul(part)];
    } else if (!index && p->is_object() && p->contains(part)) {
      p = &(*p)[part];
    } else {
      ADD_FAILURE() << "no '" << part << "' in " << p->dump().substr(0, 200);
      return json{};
    }
  }
  return *p;
}
double num(const json& j, std::string_view path) {
  const json v = at(j, path);
  return v.is_number() ? v.get<double>() : std::numeric_limits<double>::quiet_NaN();
}
std::string text(const json& j, std::string_view path) {
  const json v = at(j, path);
  return v.is_string() ? v.get<std::string>() : "<" + v.dump() + ">";
}
void expect_stamp(const json& j, std::string_view path, std::uint64_t ns) {
  EXPECT_EQ(num(j, std::string(path) + ".sec"), static_cast<double>(ns / 1'000'000'000)) << path;
  EXPECT_EQ(num(j, std::string(path) + ".nanosec"), static_cast<double>(ns % 1'000'000'000)) << path;
}
void expect_header(const json& j, std::uint64_t ns, std::string_view frame, std::string_view path = "header") {
  expect_stamp(j, std::string(path) + ".stamp", ns);
  EXPECT_EQ(text(j, std::string(path) + ".frame_id"), frame);
}
template <class R>
void expect_numbers(const json& j, std::string_view path, const R& values) {
  const json a = at(j, path);
  ASSERT_EQ(a.size(), std::size(values)) << path;
  std::size_t i = 0;
  for (const auto& v : values) EXPECT_EQ(a[i++].get<double>(), static_cast<double>(v)) << path << "[" << i - 1 << "]";
}

/// Numbers by path: {{"linear.x", 1.5}, {"header.stamp.sec", 3}}.
void expect_fields(const json& j, std::initializer_list<std::pair<std::string, double>> fields) {
  for (const auto& [path, value] : fields) EXPECT_EQ(num(j, path), value) << path;
}

std::vector<std::byte> sample(std::string_view ros_type, const json& value) {
  auto body = ros2::encode_json(ros_types(), ros_type, value);
  EXPECT_TRUE(body) << (body ? "" : body.error().message());
  return body ? *body : std::vector<std::byte>{};
}
template <class T>
T decode_as(const Conversion& c, std::span<const std::byte> body, bool little_endian = true,
            const horus::ByteSink* sink = nullptr) {
  T out{};
  auto ok = c.decode(body, little_endian, &out, sink);
  EXPECT_TRUE(ok) << c.ros_type << ": " << (ok ? "" : ok.error().what);
  return out;
}
/// The preferred conversion of T (each horus type here has one ROS 2 type).
template <class T>
const Conversion& pref() {
  const Conversion* c = ros2::find_conversion(horus::type_hash<T>, "");
  if (c == nullptr) throw std::runtime_error("no conversion of " + std::string(horus::type_name<T>()));
  return *c;
}
/// A ROS 2 sample of T's preferred type, built from JSON, decoded.
template <class T>
T from_ros(const json& value, const horus::ByteSink* sink = nullptr) {
  return decode_as<T>(pref<T>(), sample(pref<T>().ros_type, value), true, sink);
}
/// Why such a sample is refused.
template <class T>
Refusal refused(const json& value, const horus::ByteSink* sink = nullptr) {
  const auto body = sample(pref<T>().ros_type, value);
  T out{};
  auto r = pref<T>().decode(body, true, &out, sink);
  EXPECT_FALSE(r) << pref<T>().ros_type << " took " << value.dump().substr(0, 200);
  return r ? Refusal{} : r.error();
}
void expect_over(const Refusal& r, std::initializer_list<std::string_view> words) {
  EXPECT_FALSE(r.malformed) << r.what;
  for (auto w : words) EXPECT_NE(r.what.find(w), std::string::npos) << "'" << w << "' not in: " << r.what;
}

/// A message's bytes (the conversion's), their JSON (decode_json's: it re-encodes to the very same
/// bytes) and the message decoded back (the conversion's). With `frame`, the header is checked
/// too: stamped kStamp, that frame id.
template <class T>
struct Trip {
  std::vector<std::byte> body;
  json ros;
  T back{};
};
template <class T>
Trip<T> trip(const Conversion& c, const T& m, std::optional<std::string_view> frame = std::nullopt) {
  Trip<T> t;
  t.body.resize(c.encoded_size(&m, kCtx));
  c.encode(&m, kCtx, t.body);
  auto j = ros2::decode_json(ros_types(), c.ros_type, t.body);
  EXPECT_TRUE(j) << c.ros_type << ": " << (j ? "" : j.error().message());
  if (!j) return t;
  t.ros = *j;
  EXPECT_EQ(sample(c.ros_type, t.ros), t.body) << "the dynamic codec re-encodes " << c.ros_type << " otherwise";
  t.back = decode_as<T>(c, t.body);
  if (frame) expect_header(t.ros, kStamp, *frame);
  return t;
}

// -- one check per conversion: the fields by name and unit, then the round trip ------------------
void check_cmdvel(const Conversion& c) {
  const auto t = trip(c, msg::CmdVel{kStamp, 1.5f, -0.25f});
  const std::string p = c.ros_type == "geometry_msgs/msg/Twist" ? "" : "twist.";
  expect_fields(t.ros, {{p + "linear.x", 1.5}, {p + "linear.y", 0.0}, {p + "angular.z", -0.25}});
  EXPECT_TRUE(t.back.linear == 1.5f && t.back.angular == -0.25f);
  if (!p.empty()) expect_header(t.ros, kStamp, kCtx.frame_id);
  EXPECT_TRUE(p.empty() ? t.back.stamp_nanos > kStamp : t.back.stamp_nanos == kStamp) << "receipt time or the stamp";
}
void check_twist(const Conversion& c) {
  const msg::Twist m{{1.0, 2.0, 3.0}, {-4.0, -5.0, -6.0}, kStamp};
  const auto t = trip(c, m);
  const std::string p = c.ros_type == "geometry_msgs/msg/Twist" ? "" : "twist.";
  expect_fields(t.ros, {{p + "linear.y", 2.0}, {p + "angular.x", -4.0}, {p + "angular.z", -6.0}});
  EXPECT_TRUE(t.back.linear == m.linear && t.back.angular == m.angular);
  if (!p.empty()) expect_header(t.ros, kStamp, kCtx.frame_id);
  EXPECT_TRUE(p.empty() || t.back.timestamp_ns == kStamp);
}
void check_pose2d(const Conversion& c) {
  const auto t = trip(c, msg::Pose2D{1.5, -2.5, 0.75, kStamp});
  expect_fields(t.ros, {{"x", 1.5}, {"y", -2.5}, {"theta", 0.75}});
  EXPECT_TRUE(t.back.x == 1.5 && t.back.y == -2.5 && t.back.theta == 0.75);
}
void check_pose3d(const Conversion& c) {
  const msg::Pose3D m{{1.0, 2.0, 3.0}, {0.1, 0.2, 0.3, 0.9}, kStamp};
  const auto t = trip(c, m, kCtx.frame_id);
  expect_fields(t.ros, {{"pose.position.z", 3.0}, {"pose.orientation.x", 0.1}, {"pose.orientation.w", 0.9}});
  EXPECT_EQ(t.back, m);
}
void check_transform(const Conversion& c) {
  const msg::TransformStamped m{{1.0, 2.0, 3.0}, {0.1, 0.2, 0.3, 0.9}, kStamp};
  const auto t = trip(c, m);
  const std::string p = c.ros_type == "tf2_msgs/msg/TFMessage" ? "transforms.0." : "";
  EXPECT_TRUE(p.empty() || at(t.ros, "transforms").size() == 1u) << "one transform";
  expect_header(t.ros, kStamp, kCtx.frame_id, p + "header");
  EXPECT_EQ(text(t.ros, p + "child_frame_id"), kCtx.child_frame_id);
  expect_fields(t.ros, {{p + "transform.translation.y", 2.0}, {p + "transform.rotation.x", 0.1},
                        {p + "transform.rotation.w", 0.9}});
  EXPECT_EQ(t.back, m);
}
void check_wrench(const Conversion& c) {
  msg::WrenchStamped m{{1.0, 2.0, 3.0}, {-1.0, -2.0, -3.0}, {0.5, 0.5, 0.5}, {}, kStamp};
  ASSERT_TRUE(horus::set_fixed_str(m.frame_id, "ft_sensor"));
  const auto t = trip(c, m, "ft_sensor");
  expect_fields(t.ros, {{"wrench.force.z", 3.0}, {"wrench.torque.x", -1.0}});
  m.point_of_application = {};  // lost: ROS 2 gives the wrench at the frame's origin
  EXPECT_EQ(t.back, m);
}
void check_imu(const Conversion& c) {
  msg::Imu m{{0.1, 0.2, 0.3, 0.9}, {}, {0.4, 0.5, 0.6}, {}, {0.7, 0.8, 9.81}, {}, kStamp};
  for (std::size_t i = 0; i < 9; ++i) {
    m.orientation_covariance[i] = 0.01 * static_cast<double>(i + 1);
    m.angular_velocity_covariance[i] = 0.02 * static_cast<double>(i + 1);
    m.linear_acceleration_covariance[i] = 0.03 * static_cast<double>(i + 1);
  }
  const auto t = trip(c, m, kCtx.frame_id);
  expect_fields(t.ros, {{"orientation.x", 0.1}, {"orientation.w", 0.9}, {"angular_velocity.y", 0.5},
                        {"linear_acceleration.z", 9.81}});
  expect_numbers(t.ros, "orientation_covariance", m.orientation_covariance);
  expect_numbers(t.ros, "angular_velocity_covariance", m.angular_velocity_covariance);
  expect_numbers(t.ros, "linear_acceleration_covariance", m.linear_acceleration_covariance);
  EXPECT_EQ(t.back, m);
}
void check_laser_scan(const Conversion& c) {
  msg::LaserScan m = msg::LaserScan::make();
  for (std::size_t i = 0; i < m.ranges.size(); ++i) m.ranges[i] = 0.5f + 0.01f * static_cast<float>(i);
  m.ranges[7] = 0.0f;
  m.time_increment = 0.0001f;
  m.timestamp_ns = kStamp;
  const auto t = trip(c, m, kCtx.frame_id);
  EXPECT_EQ(at(t.ros, "ranges").size(), 360u) << "a full turn of 1-degree steps is 360 beams, not 361";
  EXPECT_EQ(num(t.ros, "ranges.7"), std::numeric_limits<double>::infinity()) << "0 (no return) is +inf, REP 117";
  EXPECT_EQ(at(t.ros, "intensities").size(), 0u);
  expect_fields(t.ros, {{"ranges.0", m.ranges[0]}, {"angle_min", m.angle_min}, {"angle_max", m.angle_max},
                        {"angle_increment", m.angle_increment}, {"time_increment", m.time_increment},
                        {"scan_time", 0.1f}, {"range_min", 0.1f}, {"range_max", 30.0}});
  EXPECT_EQ(t.back, m);
  msg::LaserScan part = m;  // 201 beams from -1 to 1 rad
  part.angle_min = -1.0f;
  part.angle_max = 1.0f;
  part.angle_increment = 0.01f;
  EXPECT_EQ(at(trip(c, part).ros, "ranges").size(), 201u);
}
void check_range(const Conversion& c) {
  const msg::Range m{msg::Range::INFRARED, 0.1f, 0.02f, 4.0f, 1.25f, kStamp};
  const auto t = trip(c, m, kCtx.frame_id);
  expect_fields(t.ros, {{"radiation_type", 1.0}, {"field_of_view", 0.1f}, {"min_range", 0.02f}, {"max_range", 4.0},
                        {"range", 1.25}, {"variance", 0.0}});
  EXPECT_EQ(t.back, m);
}
void check_battery(const Conversion& c) {
  const msg::BatteryState m{12.5f, -2.5f, 3.25f, 5.0f, 50.0f, msg::BatteryState::STATUS_FULL, 28.5f,
                            {4.125f, 4.25f, 4.0f}, 3, kStamp};
  const auto t = trip(c, m, kCtx.frame_id);
  expect_fields(t.ros, {{"voltage", 12.5}, {"current", -2.5}, {"charge", 3.25}, {"capacity", 5.0},
                        {"temperature", 28.5}, {"percentage", 0.5}, {"power_supply_status", 4.0}});
  EXPECT_TRUE(std::isnan(num(t.ros, "design_capacity")));
  EXPECT_EQ(at(t.ros, "present"), true);
  expect_numbers(t.ros, "cell_voltage", std::vector<float>{4.125f, 4.25f, 4.0f});
  EXPECT_EQ(text(t.ros, "serial_number"), "");
  EXPECT_EQ(t.back, m);
}
void check_nav_sat_fix(const Conversion& c) {
  msg::NavSatFix m = msg::NavSatFix::from_coordinates(47.397742, 8.545594, 488.0);
  m.status = msg::NavSatFix::STATUS_SBAS_FIX;
  for (std::size_t i = 0; i < 9; ++i) m.position_covariance[i] = static_cast<double>(i + 1);
  m.timestamp_ns = kStamp;
  const auto t = trip(c, m, kCtx.frame_id);
  expect_fields(t.ros, {{"status.status", 1.0}, {"status.service", 1.0}, {"latitude", 47.397742},
                        {"longitude", 8.545594}, {"altitude", 488.0}, {"position_covariance_type", 1.0}});
  expect_numbers(t.ros, "position_covariance", m.position_covariance);
  EXPECT_EQ(t.back, m) << "hdop and vdop come back 99.9, as from_coordinates() makes them";
}
void check_joint_state(const Conversion& c) {
  msg::JointState m{};
  ASSERT_TRUE(m.add_joint("shoulder", 0.5, 0.1, 2.0));
  ASSERT_TRUE(m.add_joint("elbow", -1.25, 0.2, 3.0));
  ASSERT_TRUE(m.add_joint("wrist_roll_joint_of_the_leftarm", 0.0, 0.3, 4.0));  // 31 characters
  m.timestamp_ns = kStamp;
  const auto t = trip(c, m, kCtx.frame_id);
  EXPECT_EQ(at(t.ros, "name"), json({"shoulder", "elbow", "wrist_roll_joint_of_the_leftarm"}));
  expect_numbers(t.ros, "position", std::vector<double>{0.5, -1.25, 0.0});
  expect_numbers(t.ros, "velocity", std::vector<double>{0.1, 0.2, 0.3});
  expect_numbers(t.ros, "effort", std::vector<double>{2.0, 3.0, 4.0});
  EXPECT_EQ(t.back, m);
}
void check_image(const Conversion& c) {
  msg::Image m(4, 6, msg::ImageEncoding::Rgb8);
  for (std::size_t i = 0; i < m.data().size(); ++i) m.data_mut()[i] = static_cast<std::uint8_t>(i * 7);
  ASSERT_TRUE(m.set_frame_id("camera_optical"));
  m.set_timestamp_ns(kStamp);
  const auto t = trip(c, m, "camera_optical");
  EXPECT_EQ(text(t.ros, "encoding"), "rgb8");
  expect_fields(t.ros, {{"height", 4.0}, {"width", 6.0}, {"is_bigendian", 0.0}, {"step", 18.0}, {"data.5", 35.0}});
  EXPECT_EQ(at(t.ros, "data").size(), 72u);
  EXPECT_EQ(t.back, m);
  EXPECT_EQ(text(trip(c, msg::Image(2, 2, msg::ImageEncoding::Depth16)).ros, "encoding"), "16UC1");
  EXPECT_EQ(text(trip(c, msg::Image(1, 1, msg::ImageEncoding::Mono32F)).ros, "encoding"), "32FC1");
}
void check_compressed_image(const Conversion& c) {
  msg::CompressedImage m = msg::CompressedImage::make("jpeg", {0xFF, 0xD8, 1, 2, 3}, 640, 480);
  ASSERT_TRUE(m.set_frame_id("camera"));
  m.timestamp_ns = kStamp;
  const auto t = trip(c, m, "camera");
  EXPECT_EQ(text(t.ros, "format"), "jpeg");
  expect_numbers(t.ros, "data", m.data);
  m.width = m.height = 0;  // ROS 2 carries no decoded size
  EXPECT_EQ(t.back, m);
}
void check_camera_info(const Conversion& c) {
  msg::CameraInfo m = msg::CameraInfo::make(640, 480, 525.0, 526.0, 320.5, 240.5);
  ASSERT_TRUE(m.set_distortion_model("plumb_bob"));
  m.distortion_coefficients = {0.1, -0.2, 0.001, 0.002, 0.05, 0.0, 0.0, 0.0};
  ASSERT_TRUE(m.set_frame_id("camera_optical"));
  m.timestamp_ns = kStamp;
  const auto t = trip(c, m, "camera_optical");
  expect_fields(t.ros, {{"width", 640.0}, {"height", 480.0}, {"binning_x", 0.0}, {"roi.width", 0.0}});
  EXPECT_EQ(text(t.ros, "distortion_model"), "plumb_bob");
  expect_numbers(t.ros, "d", std::vector<double>{0.1, -0.2, 0.001, 0.002, 0.05});
  expect_numbers(t.ros, "k", m.camera_matrix);
  expect_numbers(t.ros, "r", m.rectification_matrix);
  expect_numbers(t.ros, "p", m.projection_matrix);
  EXPECT_EQ(t.back, m);
  ASSERT_TRUE(m.set_distortion_model("rational_poly"));
  EXPECT_EQ(at(trip(c, m).ros, "d").size(), 8u);
}
void check_point_cloud(const Conversion& c) {
  const std::vector<std::array<float, 4>> points{{1.0f, 2.0f, 3.0f, 0.5f}, {4.0f, 5.0f, 6.0f, 0.25f}};
  msg::PointCloud m = msg::PointCloud::from_xyzi(points);
  ASSERT_TRUE(m.set_frame_id("lidar"));
  m.set_timestamp_ns(kStamp);
  const auto t = trip(c, m, "lidar");
  expect_fields(t.ros, {{"height", 1.0}, {"width", 2.0}, {"point_step", 16.0}, {"row_step", 32.0}});
  const char* names[] = {"x", "y", "z", "intensity"};
  ASSERT_EQ(at(t.ros, "fields").size(), 4u);
  for (std::size_t i = 0; i < 4; ++i) {
    const std::string f = "fields." + std::to_string(i);
    EXPECT_EQ(text(t.ros, f + ".name"), names[i]);
    expect_fields(t.ros, {{f + ".offset", 4.0 * static_cast<double>(i)}, {f + ".datatype", 7.0}, {f + ".count", 1.0}});
  }
  EXPECT_EQ(at(t.ros, "is_bigendian"), false);
  EXPECT_EQ(at(t.ros, "is_dense"), true);
  EXPECT_EQ(at(t.ros, "data").size(), 32u);
  EXPECT_EQ(t.back, m);
  const std::vector<std::array<float, 3>> hole{{1.0f, NAN, 0.0f}};
  EXPECT_EQ(at(trip(c, msg::PointCloud::from_xyz(hole)).ros, "is_dense"), false);
}
void check_odometry(const Conversion& c) {
  msg::Odometry m{};
  m.update(msg::Pose2D{1.0, 2.0, 0.5, kStamp}, msg::Twist{{0.5, 0.1, 0.0}, {0.0, 0.0, 0.2}, kStamp}, kStamp);
  for (std::size_t i = 0; i < 36; ++i) {
    m.pose_covariance[i] = 0.1 * static_cast<double>(i);
    m.twist_covariance[i] = 0.2 * static_cast<double>(i);
  }
  ASSERT_TRUE(m.set_frames("odom", "base_link"));
  const auto t = trip(c, m, "odom");
  EXPECT_EQ(text(t.ros, "child_frame_id"), "base_link");
  expect_fields(t.ros, {{"pose.pose.position.x", 1.0}, {"pose.pose.position.z", 0.0},
                        {"pose.pose.orientation.z", std::sin(0.25)}, {"pose.pose.orientation.w", std::cos(0.25)},
                        {"twist.twist.linear.y", 0.1}, {"twist.twist.angular.z", 0.2}});
  expect_numbers(t.ros, "pose.covariance", m.pose_covariance);
  expect_numbers(t.ros, "twist.covariance", m.twist_covariance);
  msg::Odometry back = t.back;
  EXPECT_NEAR(back.pose.theta, 0.5, 1e-12);
  back.pose.theta = m.pose.theta;
  EXPECT_EQ(back, m);
  m.frame_id = m.child_frame_id = {};
  const auto u = trip(c, m);
  EXPECT_EQ(text(u.ros, "header.frame_id"), kCtx.frame_id);
  EXPECT_EQ(text(u.ros, "child_frame_id"), kCtx.child_frame_id);
}
void check_occupancy_grid(const Conversion& c) {
  msg::OccupancyGrid m = msg::OccupancyGrid::make(3, 2, 0.05f, msg::Pose2D{-1.0, -2.0, 0.3, 0});
  m.data = {-1, 0, 100, 50, 20, -1};
  ASSERT_TRUE(m.set_frame_id("map"));
  ASSERT_TRUE(m.set_metadata("lost on the way"));
  m.timestamp_ns = kStamp;
  const auto t = trip(c, m, "map");
  expect_stamp(t.ros, "info.map_load_time", kStamp);
  expect_fields(t.ros, {{"info.resolution", 0.05f}, {"info.width", 3.0}, {"info.height", 2.0},
                        {"info.origin.position.y", -2.0}, {"info.origin.orientation.z", std::sin(0.15)}});
  expect_numbers(t.ros, "data", m.data);
  EXPECT_NEAR(t.back.origin.theta, 0.3, 1e-12);
  msg::OccupancyGrid back = t.back;
  back.origin.theta = m.origin.theta;
  m.metadata = {};
  EXPECT_EQ(back, m);
}
void check_nav_path(const Conversion& c) {
  msg::NavPath m{};
  for (int i = 0; i < 3; ++i)
    ASSERT_TRUE(m.add_waypoint(msg::Waypoint::make(msg::Pose2D{1.0 * i, 2.0 * i, 0.1 * i, 0})));
  ASSERT_TRUE(m.set_frame_id("map"));
  m.timestamp_ns = kStamp;
  const auto t = trip(c, m, "map");
  ASSERT_EQ(at(t.ros, "poses").size(), 3u);
  expect_header(t.ros, kStamp, "map", "poses.2.header");
  expect_fields(t.ros, {{"poses.2.pose.position.x", 2.0}, {"poses.2.pose.position.y", 4.0},
                        {"poses.2.pose.orientation.z", std::sin(0.1)}});
  msg::NavPath back = t.back;
  for (std::size_t i = 0; i < 3; ++i) {
    EXPECT_NEAR(back.waypoints[i].pose.theta, m.waypoints[i].pose.theta, 1e-12);
    back.waypoints[i].pose.theta = m.waypoints[i].pose.theta;
  }
  EXPECT_DOUBLE_EQ(back.total_length, m.total_length);
  back.total_length = m.total_length;
  EXPECT_EQ(back, m);
}
void check_joystick(const Conversion& c) {
  msg::JoystickInput axis = msg::JoystickInput::new_axis(0, 3, "LeftStickY", -0.5f);
  axis.timestamp_ms = kStamp / 1'000'000;
  const auto t = trip(c, axis);
  expect_header(t.ros, axis.timestamp_ms * 1'000'000, kCtx.frame_id);
  expect_numbers(t.ros, "axes", std::vector<float>{0.0f, 0.0f, 0.0f, -0.5f});
  EXPECT_EQ(at(t.ros, "buttons").size(), 0u);
  EXPECT_TRUE(t.back.is_axis() && t.back.element_id == 3 && t.back.value == -0.5f);
  EXPECT_EQ(t.back.timestamp_ms, axis.timestamp_ms);
  const auto b = trip(c, msg::JoystickInput::new_button(0, 2, "A", true));
  expect_numbers(b.ros, "buttons", std::vector<int>{0, 0, 1});
  EXPECT_TRUE(b.back.is_button() && b.back.element_id == 2 && b.back.is_pressed() && b.back.value == 1.0f);
}
void check_diagnostic_status(const Conversion& c) {
  msg::DiagnosticStatus m = msg::DiagnosticStatus::warn(42, "battery low").with_component("power");
  m.timestamp_ns = kStamp;
  const auto t = trip(c, m, kCtx.frame_id);
  EXPECT_EQ(at(t.ros, "status"), json::parse(R"([{"level": 1, "name": "power", "message": "battery low",
                                                   "hardware_id": "", "values": [{"key": "code", "value": "42"}]}])"));
  EXPECT_EQ(t.back, m);
  EXPECT_EQ(num(trip(c, msg::DiagnosticStatus::fatal(1, "dead")).ros, "status.0.level"), 2.0) << "FATAL is ERROR";
}
void check_diagnostic_report(const Conversion& c) {
  msg::DiagnosticReport m = msg::DiagnosticReport::make("motor_left");
  ASSERT_TRUE(m.add_string("mode", "cruise") && m.add_float("temp_c", 45.5) && m.add_int("rpm", 1200));
  m.set_level(msg::StatusLevel::Error);
  m.timestamp_ns = kStamp;
  const auto t = trip(c, m, kCtx.frame_id);
  EXPECT_EQ(at(t.ros, "status"), json::parse(R"([{"level": 2, "name": "motor_left", "message": "", "hardware_id": "",
      "values": [{"key": "mode", "value": "cruise"}, {"key": "temp_c", "value": "45.500"},
                 {"key": "rpm", "value": "1200"}]}])"));
  for (std::size_t i = 0; i < 3; ++i) m.values[i].value_type = msg::DiagnosticValue::TYPE_STRING;  // lost
  EXPECT_EQ(t.back, m);
}
void check_clock(const Conversion& c) {
  const auto t = trip(c, msg::Clock::sim_time(kStamp, 2.0, kStamp + 5));
  expect_stamp(t.ros, "clock", kStamp);
  EXPECT_EQ(t.back.clock_ns, kStamp);
  EXPECT_EQ(t.back.source, msg::Clock::SOURCE_SIM);
  EXPECT_GT(t.back.realtime_ns, kStamp) << "the time of receipt";
}

using Check = void (*)(const Conversion&);
template <class T>
std::pair<std::pair<std::uint64_t, std::string_view>, Check> entry(std::string_view ros_name, Check check) {
  return {{horus::type_hash<T>, ros_name}, check};
}

TEST(Ros2Convert, EveryConversionCarriesItsFieldsByNameAndBack) {
  const std::map<std::pair<std::uint64_t, std::string_view>, Check> checks{
      entry<msg::CmdVel>("Twist", check_cmdvel), entry<msg::CmdVel>("TwistStamped", check_cmdvel),
      entry<msg::Twist>("Twist", check_twist), entry<msg::Twist>("TwistStamped", check_twist),
      entry<msg::Pose2D>("Pose2D", check_pose2d), entry<msg::Pose3D>("PoseStamped", check_pose3d),
      entry<msg::TransformStamped>("TransformStamped", check_transform),
      entry<msg::TransformStamped>("TFMessage", check_transform),
      entry<msg::WrenchStamped>("WrenchStamped", check_wrench), entry<msg::Imu>("Imu", check_imu),
      entry<msg::LaserScan>("LaserScan", check_laser_scan), entry<msg::Range>("Range", check_range),
      entry<msg::BatteryState>("BatteryState", check_battery), entry<msg::NavSatFix>("NavSatFix", check_nav_sat_fix),
      entry<msg::JointState>("JointState", check_joint_state), entry<msg::Image>("Image", check_image),
      entry<msg::CompressedImage>("CompressedImage", check_compressed_image),
      entry<msg::CameraInfo>("CameraInfo", check_camera_info), entry<msg::PointCloud>("PointCloud2", check_point_cloud),
      entry<msg::Odometry>("Odometry", check_odometry),
      entry<msg::OccupancyGrid>("OccupancyGrid", check_occupancy_grid), entry<msg::NavPath>("Path", check_nav_path),
      entry<msg::JoystickInput>("Joy", check_joystick),
      entry<msg::DiagnosticStatus>("DiagnosticArray", check_diagnostic_status),
      entry<msg::DiagnosticReport>("DiagnosticArray", check_diagnostic_report), entry<msg::Clock>("Clock", check_clock),
  };
  EXPECT_EQ(ros2::conversions().size(), checks.size());
  for (const Conversion& c : ros2::conversions()) {
    SCOPED_TRACE(std::string(c.horus_type) + " -> " + std::string(c.ros_type));
    EXPECT_FALSE(c.loses.empty());
    const auto it = checks.find({c.horus_hash, c.ros_type.substr(c.ros_type.rfind('/') + 1)});
    ASSERT_NE(it, checks.end()) << "no check for this conversion";
    it->second(c);
  }
}

// -- ROS 2 samples built as JSON: decoded, or refused naming the field and the limit -------------

TEST(Ros2Convert, RefusesWhatTheHorusTypeCannotHoldNamingFieldAndLimit) {
  const std::string long_frame(40, 'f');
  json joints = json::array(), values = json::array();
  for (int i = 0; i < 17; ++i) joints.push_back("joint" + std::to_string(i));
  for (int i = 0; i < 17; ++i) values.push_back({{"key", "k" + std::to_string(i)}, {"value", "v"}});
  expect_over(refused<msg::LaserScan>({{"ranges", std::vector<float>(720, 1.0f)}}), {"ranges", "720", "360"});
  expect_over(refused<msg::JointState>({{"name", joints}}), {"name", "17", "16"});
  expect_over(refused<msg::JointState>({{"name", {"a", std::string(32, 'j')}}}), {"name[1]", "32", "31"});
  expect_over(refused<msg::WrenchStamped>({{"header", {{"frame_id", long_frame}}}}), {"header.frame_id", "40", "31"});
  expect_over(refused<msg::Odometry>({{"child_frame_id", long_frame}}), {"child_frame_id", "31"});
  expect_over(refused<msg::BatteryState>({{"cell_voltage", std::vector<float>(17, 3.7f)}}), {"cell_voltage", "17", "16"});
  expect_over(refused<msg::NavPath>({{"poses", std::vector<json>(257, json::object())}}), {"poses", "257", "256"});
  expect_over(refused<msg::CameraInfo>({{"d", std::vector<double>(9, 0.1)}}), {"d", "9", "8"});
  expect_over(refused<msg::CompressedImage>({{"format", "h264-annexb"}}), {"format", "7"});  // image_transport's is its compression:
  EXPECT_EQ(from_ros<msg::CompressedImage>({{"format", "rgb8; jpeg compressed bgr8"}}).format_str(), "jpeg");
  expect_over(refused<msg::NavSatFix>({{"status", {{"status", 5}}}}), {"status.status", "5"});
  expect_over(refused<msg::Range>({{"radiation_type", 2}}), {"radiation_type", "2"});
  expect_over(refused<msg::DiagnosticReport>({{"status", {json::object(), json::object()}}}), {"status", "2", "1"});
  expect_over(refused<msg::DiagnosticStatus>(json::object()), {"status", "0 statuses"});
  expect_over(refused<msg::DiagnosticReport>({{"status", {{{"values", values}}}}}), {"values", "17", "16"});
  expect_over(refused<msg::DiagnosticReport>({{"status", {{{"values", {{{"key", "k"}, {"value", std::string(64, 'v')}}}}}}}}),
              {"status[0].values[0].value", "64", "63"});
  expect_over(refused<msg::JoystickInput>({{"axes", {0.5f, 0.0f, 0.75f}}}), {"axes", "3 axes"});
  expect_over(refused<msg::JoystickInput>({{"axes", {0.0f}}, {"buttons", {1}}}), {"1 axes and 1 buttons"});
  const Refusal odd = refused<msg::JointState>({{"name", {"a", "b"}}, {"effort", {1.0}}});
  EXPECT_TRUE(odd.malformed && odd.what.find("effort") != std::string::npos) << odd.what;
}

TEST(Ros2Convert, ReadsRos2SamplesAsTheHorusTypesMeanThem) {
  const float inf = std::numeric_limits<float>::infinity();
  const auto s = from_ros<msg::LaserScan>({{"range_min", 0.1}, {"range_max", 30.0}, {"intensities", {9.0f, 9.0f}},
                                           {"ranges", {1.0f, nullptr, 0.05f, 50.0f, inf, 2.0f}},
                                           {"header", {{"stamp", {{"sec", 3}, {"nanosec", 7}}}}}});
  EXPECT_TRUE(s.ranges[0] == 1.0f && s.ranges[5] == 2.0f);
  for (std::size_t i : {1u, 2u, 3u, 4u, 6u, 359u}) EXPECT_EQ(s.ranges[i], 0.0f) << "beam " << i << ": no return";
  EXPECT_EQ(s.timestamp_ns, 3'000'000'007u);
  const auto b = from_ros<msg::BatteryState>({{"percentage", 0.25}, {"power_supply_status", 3}});
  EXPECT_TRUE(b.percentage == 25.0f && b.power_supply_status == msg::BatteryState::STATUS_UNKNOWN) << "NOT_CHARGING";
  EXPECT_EQ(from_ros<msg::BatteryState>({{"power_supply_status", 2}}).power_supply_status,
            msg::BatteryState::STATUS_DISCHARGING);
  EXPECT_EQ(from_ros<msg::NavSatFix>(json::object()).status, msg::NavSatFix::STATUS_NO_FIX) << "STATUS_UNKNOWN (-2)";
  EXPECT_EQ(from_ros<msg::NavSatFix>({{"status", {{"status", 2}}}}).status, msg::NavSatFix::STATUS_GBAS_FIX);
  const auto j = from_ros<msg::JointState>({{"name", {"a", "b"}}, {"position", {1.0, 2.0}}});
  EXPECT_TRUE(j.count() == 2 && j.positions[1] == 2.0 && j.velocities[1] == 0.0) << "an empty velocity is zeros";
  const auto a = from_ros<msg::JoystickInput>({{"axes", {0.0f, 0.0f, 0.75f}}});
  EXPECT_TRUE(a.is_axis() && a.element_id == 2 && a.value == 0.75f);
  const auto d = from_ros<msg::DiagnosticStatus>(
      {{"status", {{{"level", 3}, {"name", "n"}, {"values", {{{"key", "code"}, {"value", "7"}}}}}}}});
  EXPECT_EQ(d.level, msg::DiagnosticStatus::LEVEL_ERROR) << "STALE";
  EXPECT_EQ(d.code, 7u);
}

// A pool stand-in: lends one writable buffer of the size asked for, or none.
struct TestSlot {
  bool give = true;
  std::size_t asked = 0;
  std::vector<std::uint8_t> bytes;  // the slot
};
bool test_slot_place(void* context, std::size_t n, horus::ByteBuffer& out) {
  auto* slot = static_cast<TestSlot*>(context);
  slot->asked = n;
  if (!slot->give) return false;
  slot->bytes.assign(n, 0);
  out = horus::ByteBuffer::borrow(slot->bytes.data(), n, {}, true);
  return true;
}

TEST(Ros2Convert, ImagesAndCloudsGoIntoThePoolSlotOrAreRefusedNamingWhy) {
  const json rgb{{"height", 2}, {"width", 3}, {"encoding", "bgr8"}, {"step", 9}, {"data", std::vector<int>(18, 7)},
                 {"header", {{"frame_id", "cam"}}}};
  TestSlot slot;
  const horus::ByteSink sink{&slot, &test_slot_place};
  const auto img = from_ros<msg::Image>(rgb, &sink);
  EXPECT_EQ(slot.asked, 18u);
  EXPECT_EQ(img.data().data(), slot.bytes.data()) << "the pixels were copied once, into the slot";
  EXPECT_TRUE(img.encoding() == msg::ImageEncoding::Bgr8 && img.frame_id() == "cam" && img.data()[17] == 7);
  slot.give = false;
  expect_over(refused<msg::Image>(rgb, &sink), {"data", "no pool slot for 18 bytes"});
  slot.give = true;
  json odd = rgb;
  odd["encoding"] = "yuv420";
  expect_over(refused<msg::Image>(odd), {"encoding", "yuv420", "mono8", "bayer_rggb8"});
  odd = rgb;
  odd["data"] = std::vector<int>(17, 7);
  EXPECT_TRUE(refused<msg::Image>(odd).malformed) << "17 bytes are not 2 rows of 9";

  const auto field = [](const char* name, int offset, int datatype) {
    return json{{"name", name}, {"offset", offset}, {"datatype", datatype}, {"count", 1}};
  };
  json pc{{"height", 1}, {"width", 2}, {"point_step", 12}, {"row_step", 24}, {"data", std::vector<int>(24, 0)},
          {"fields", {field("x", 0, 7), field("y", 4, 7), field("z", 8, 7)}}};
  const auto xyz = from_ros<msg::PointCloud>(pc, &sink);
  EXPECT_TRUE(xyz.point_count() == 2 && xyz.fields_per_point() == 3 && xyz.dtype() == msg::TensorDtype::F32);
  EXPECT_EQ(xyz.data().data(), slot.bytes.data());
  json mixed = pc;
  mixed["fields"][2] = field("z", 8, 8);
  expect_over(refused<msg::PointCloud>(mixed), {"fields[2].datatype"});
  pc["point_step"] = 16;
  pc["row_step"] = 32;
  pc["data"] = std::vector<int>(32, 0);
  expect_over(refused<msg::PointCloud>(pc), {"point_step", "16", "12"});
  pc["fields"].push_back(field("rgb", 12, 7));
  expect_over(refused<msg::PointCloud>(pc), {"fields[3].name", "rgb", "intensity"});
}

TEST(Ros2Convert, TruncatedOrForeignBytesAreMalformed) {
  const Conversion& imu = pref<msg::Imu>();
  auto body = sample(imu.ros_type, {{"orientation", {{"w", 1.0}}}});
  for (std::size_t cut : {std::size_t{0}, std::size_t{3}, body.size() / 2, body.size() - 8, body.size() + 8}) {
    std::vector<std::byte> bytes = body;
    bytes.resize(cut);
    msg::Imu out{};
    const auto r = imu.decode(bytes, true, &out, nullptr);
    ASSERT_FALSE(r) << cut << " bytes";
    EXPECT_TRUE(r.error().malformed) << r.error().what;
    EXPECT_NE(r.error().what.find("sensor_msgs/msg/Imu."), std::string::npos) << r.error().what;
  }
}

TEST(Ros2Convert, BigEndianSamplesDecode) {
  auto body = sample("geometry_msgs/msg/Twist", {{"linear", {{"x", 1.5}}}, {"angular", {{"z", -0.5}}}});
  ASSERT_EQ(body.size(), 48u);
  for (auto it = body.begin(); it != body.end(); it += 8) std::reverse(it, it + 8);
  const auto cmd = decode_as<msg::CmdVel>(pref<msg::CmdVel>(), body, false);
  EXPECT_TRUE(cmd.linear == 1.5f && cmd.angular == -0.5f);
  const auto j = ros2::decode_json(ros_types(), "geometry_msgs/msg/Twist", body, false);
  ASSERT_TRUE(j) << j.error().message();
  EXPECT_EQ(num(*j, "linear.x"), 1.5);
  auto header = sample("std_msgs/msg/Header", {{"stamp", {{"sec", 5}, {"nanosec", 6}}}, {"frame_id", "ab"}});
  for (auto it = header.begin(); it != header.begin() + 12; it += 4) std::reverse(it, it + 4);
  const auto h = ros2::decode_json(ros_types(), "std_msgs/msg/Header", header, false);
  ASSERT_TRUE(h) << h.error().message();
  EXPECT_EQ(text(*h, "frame_id"), "ab") << "the string's count swapped too";
  EXPECT_EQ(num(*h, "stamp.nanosec"), 6.0);
}

TEST(Ros2Convert, EachHorusTypeHasExactlyOnePreferredRos2Type) {
  std::map<std::uint64_t, int> preferred;
  for (const Conversion& c : ros2::conversions()) preferred[c.horus_hash] += c.preferred ? 1 : 0;
  for (const auto& [hash, count] : preferred) {
    EXPECT_EQ(count, 1) << ros2::conversion_targets(hash);
    const Conversion* c = ros2::find_conversion(hash, "");
    ASSERT_TRUE(c != nullptr && c->preferred);
    EXPECT_EQ(ros2::find_conversion(hash, c->ros_type), c);
    EXPECT_EQ(ros2::find_conversion(hash, "nonexistent/msg/X"), nullptr);
    EXPECT_NE(ros2::conversion_targets(hash).find(c->ros_type), std::string::npos);
    EXPECT_TRUE(ros_types().find(c->ros_type) != nullptr) << c->ros_type << " is not in Interfaces::standard()";
  }
  EXPECT_EQ(ros2::find_conversion(horus::type_hash<msg::Pose2D>, "geometry_msgs/msg/PoseStamped"), nullptr);
  EXPECT_EQ(ros2::conversion_targets(horus::type_hash<msg::CmdVel>),
            "geometry_msgs/msg/Twist or geometry_msgs/msg/TwistStamped");
}

// -- the dynamic codec itself ----------------------------------------------------------------------

TEST(Ros2Dynamic, RoundTripsNestedTypesArraysBoundsAndDefaults) {
  const std::vector<std::pair<std::string_view, json>> samples{
      {"sensor_msgs/msg/NavSatFix", {{"status", {{"status", 1}, {"service", 8}}}, {"latitude", 1.5},
                                     {"position_covariance", std::vector<double>(9, 0.25)}}},
      {"diagnostic_msgs/msg/DiagnosticArray",
       {{"status", {{{"level", 2}, {"name", "n"}, {"values", {{{"key", "k"}, {"value", "v"}}}}}, json::object()}}}},
      {"rmw_dds_common/msg/ParticipantEntitiesInfo",
       {{"gid", {{"data", std::vector<int>(16, 200)}}},
        {"node_entities_info_seq", {{{"node_name", "talker"}, {"reader_gid_seq", {{{"data", std::vector<int>(16, 1)}}}}}}}}},
      {"std_msgs/msg/Empty", json::object()},
      {"sensor_msgs/msg/Joy", {{"axes", {0.5f, -1.0f}}, {"buttons", {1, 0, -3}}}},
  };
  for (const auto& [type, value] : samples) {
    const auto body = ros2::encode_json(ros_types(), type, value);
    ASSERT_TRUE(body) << type << ": " << body.error().message();
    const auto back = ros2::decode_json(ros_types(), type, *body);
    ASSERT_TRUE(back) << type << ": " << back.error().message();
    EXPECT_EQ(ros2::encode_json(ros_types(), type, *back).value_or(std::vector<std::byte>{}), *body) << type;
    for (const json& op : json::diff(value, *back)) EXPECT_EQ(op["op"], "add") << type << ": " << op.dump();
  }
  EXPECT_EQ(sample("std_msgs/msg/Empty", json::object()).size(), 1u) << "rosidl's placeholder byte";
  const auto q = ros2::decode_json(ros_types(), "geometry_msgs/msg/Quaternion",
                                          sample("geometry_msgs/msg/Quaternion", json::object()));
  ASSERT_TRUE(q);
  EXPECT_EQ(num(*q, "w"), 1.0) << "the .msg's default";
  // XCDR1 layout: alignment from the first byte, strings with their NUL, no padding after the
  // count of an empty sequence (JointState: 13 bytes of header, pad to 16, four counts).
  const auto h = sample("std_msgs/msg/Header", {{"stamp", {{"sec", 1}, {"nanosec", 2}}}, {"frame_id", "ab"}});
  const std::vector<std::uint8_t> expected{1, 0, 0, 0, 2, 0, 0, 0, 3, 0, 0, 0, 'a', 'b', 0};
  ASSERT_EQ(h.size(), expected.size());
  EXPECT_EQ(std::memcmp(h.data(), expected.data(), h.size()), 0);
  EXPECT_EQ(sample("sensor_msgs/msg/JointState", json::object()).size(), 32u);
  EXPECT_EQ(sample("sensor_msgs/msg/JointState", {{"position", {1.0}}}).size(), 32u + 8u) << "the double aligned to 8";
}

TEST(Ros2Dynamic, ErrorsNameThePath) {
  const auto expect_error = [](const auto& result, std::string_view words) {
    ASSERT_FALSE(result) << words;
    EXPECT_NE(result.error().message().find(words), std::string::npos) << result.error().message();
  };
  const Interfaces& t = ros_types();
  const std::vector<std::tuple<std::string_view, json, std::string_view>> bad{
      {"geometry_msgs/msg/Twist", {{"linear", {{"q", 1}}}}, "geometry_msgs/msg/Twist.linear: unknown field 'q'"},
      {"geometry_msgs/msg/Twist", {{"linear", {{"x", "fast"}}}}, "geometry_msgs/msg/Twist.linear.x: expected a number"},
      {"sensor_msgs/msg/Imu", {{"orientation_covariance", {1.0, 2.0}}}, "sensor_msgs/msg/Imu.orientation_covariance: 2 el"},
      {"sensor_msgs/msg/Image", {{"data", {1, 300}}}, "sensor_msgs/msg/Image.data[1]: 300 is out of range for uint8"},
      {"sensor_msgs/msg/Range", {{"radiation_type", -1}}, "sensor_msgs/msg/Range.radiation_type: -1 is out of range"},
      {"sensor_msgs/msg/BatteryState", {{"present", 1}}, "sensor_msgs/msg/BatteryState.present: expected a bool"},
      {"rmw_dds_common/msg/NodeEntitiesInfo", {{"node_name", std::string(257, 'n')}}, "node_name: 257 characters, over"},
      {"nonexistent/msg/X", json::object(), "no type 'nonexistent/msg/X'"},
  };
  for (const auto& [type, value, words] : bad) expect_error(ros2::encode_json(t, type, value), words);
  auto scan = sample("sensor_msgs/msg/LaserScan", {{"ranges", {1.0f, 2.0f}}});
  std::vector<std::byte> cut(scan.begin(), scan.begin() + static_cast<std::ptrdiff_t>(scan.size() - 8));
  expect_error(ros2::decode_json(t, "sensor_msgs/msg/LaserScan", cut), "sensor_msgs/msg/LaserScan.ranges");
  auto battery = sample("sensor_msgs/msg/BatteryState", json::object());
  battery[47] = std::byte{2};  // present: header 13, pad to 16, 7 floats, 3 bytes
  expect_error(ros2::decode_json(t, "sensor_msgs/msg/BatteryState", battery),
               "sensor_msgs/msg/BatteryState.present: bool byte 2");
  auto huge = sample("sensor_msgs/msg/JointState", json::object());
  huge[16] = std::byte{0xFF};  // the count of name: 255 strings in 12 bytes
  expect_error(ros2::decode_json(t, "sensor_msgs/msg/JointState", huge), "sensor_msgs/msg/JointState.name: count 255");
  auto longer = sample("geometry_msgs/msg/Twist", json::object());
  longer.resize(longer.size() + 4);
  expect_error(ros2::decode_json(t, "geometry_msgs/msg/Twist", longer), "4 bytes left over");
  longer.resize(longer.size() - 1);
  EXPECT_TRUE(ros2::decode_json(t, "geometry_msgs/msg/Twist", longer)) << "3 bytes of padding are allowed";
}

}  // namespace
