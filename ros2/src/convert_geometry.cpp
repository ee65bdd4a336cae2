// The geometry conversions (convert.hpp): velocities, poses, transforms, wrenches.
#include "cdr_io.hpp"
#include "horus/msg/force.hpp"
#include "horus/msg/geometry.hpp"

namespace horus::ros2::detail {
namespace {

// geometry_msgs/msg/Twist's six numbers from a horus velocity, and back.
template <class S>
void put_twist(Out<S>& o, const std::array<double, 3>& linear, const std::array<double, 3>& angular) {
  o.vector3(linear[0], linear[1], linear[2]);
  o.vector3(angular[0], angular[1], angular[2]);
}
bool get_twist(In& in, std::array<double, 3>& linear, std::array<double, 3>& angular, std::string_view field) {
  return in.run(linear.data(), 3, field) && in.run(angular.data(), 3, field);
}
std::array<double, 3> cmd_linear(const msg::CmdVel& m) { return {static_cast<double>(m.linear), 0.0, 0.0}; }
std::array<double, 3> cmd_angular(const msg::CmdVel& m) { return {0.0, 0.0, static_cast<double>(m.angular)}; }
void set_cmd(msg::CmdVel& m, const std::array<double, 3>& linear, const std::array<double, 3>& angular) {
  m.linear = static_cast<float>(linear[0]);
  m.angular = static_cast<float>(angular[2]);
}

struct CmdVelTwist {
  using Horus = msg::CmdVel;
  static constexpr std::string_view kRos = "geometry_msgs/msg/Twist";
  static constexpr bool kPreferred = true;
  static constexpr std::string_view kLoses =
      "to ROS 2: stamp_nanos (Twist has no stamp); from ROS 2: linear.y, linear.z, angular.x, angular.y "
      "(a CmdVel is planar), stamp_nanos is the time of receipt";
  template <class S>
  static void put(Out<S>& o, const Horus& m, const Context&) {
    put_twist(o, cmd_linear(m), cmd_angular(m));
  }
  static bool get(In& in, Horus& m) {
    std::array<double, 3> linear{}, angular{};
    if (!get_twist(in, linear, angular, "linear")) return false;
    set_cmd(m, linear, angular);
    m.stamp_nanos = now_ns();
    return true;
  }
};

struct CmdVelTwistStamped {
  using Horus = msg::CmdVel;
  static constexpr std::string_view kRos = "geometry_msgs/msg/TwistStamped";
  static constexpr bool kPreferred = false;
  static constexpr std::string_view kLoses =
      "to ROS 2: header.frame_id is the rule's frame_id; from ROS 2: header.frame_id, linear.y, linear.z, "
      "angular.x, angular.y";
  template <class S>
  static void put(Out<S>& o, const Horus& m, const Context& ctx) {
    o.header(m.stamp_nanos, ctx.frame_id);
    put_twist(o, cmd_linear(m), cmd_angular(m));
  }
  static bool get(In& in, Horus& m) {
    std::string_view frame;
    std::array<double, 3> linear{}, angular{};
    if (!in.header(m.stamp_nanos, frame) || !get_twist(in, linear, angular, "twist")) return false;
    set_cmd(m, linear, angular);
    return true;
  }
};

struct TwistTwist {
  using Horus = msg::Twist;
  static constexpr std::string_view kRos = "geometry_msgs/msg/Twist";
  static constexpr bool kPreferred = true;
  static constexpr std::string_view kLoses = "to ROS 2: timestamp_ns; from ROS 2: timestamp_ns is the time of receipt";
  template <class S>
  static void put(Out<S>& o, const Horus& m, const Context&) {
    put_twist(o, m.linear, m.angular);
  }
  static bool get(In& in, Horus& m) {
    if (!get_twist(in, m.linear, m.angular, "linear")) return false;
    m.timestamp_ns = now_ns();
    return true;
  }
};

struct TwistTwistStamped {
  using Horus = msg::Twist;
  static constexpr std::string_view kRos = "geometry_msgs/msg/TwistStamped";
  static constexpr bool kPreferred = false;
  static constexpr std::string_view kLoses = "to ROS 2: header.frame_id is the rule's frame_id; from ROS 2: header.frame_id";
  template <class S>
  static void put(Out<S>& o, const Horus& m, const Context& ctx) {
    o.header(m.timestamp_ns, ctx.frame_id);
    put_twist(o, m.linear, m.angular);
  }
  static bool get(In& in, Horus& m) {
    std::string_view frame;
    return in.header(m.timestamp_ns, frame) && get_twist(in, m.linear, m.angular, "twist");
  }
};

struct Pose2DPose2D {
  using Horus = msg::Pose2D;
  static constexpr std::string_view kRos = "geometry_msgs/msg/Pose2D";
  static constexpr bool kPreferred = true;
  static constexpr std::string_view kLoses = "to ROS 2: timestamp_ns; from ROS 2: timestamp_ns is the time of receipt";
  template <class S>
  static void put(Out<S>& o, const Horus& m, const Context&) {
    o.vector3(m.x, m.y, m.theta);
  }
  static bool get(In& in, Horus& m) {
    if (!in.vector3(m.x, m.y, m.theta, "x")) return false;
    m.timestamp_ns = now_ns();
    return true;
  }
};

struct Pose3DPoseStamped {
  using Horus = msg::Pose3D;
  static constexpr std::string_view kRos = "geometry_msgs/msg/PoseStamped";
  static constexpr bool kPreferred = true;
  static constexpr std::string_view kLoses = "to ROS 2: header.frame_id is the rule's frame_id; from ROS 2: header.frame_id";
  template <class S>
  static void put(Out<S>& o, const Horus& m, const Context& ctx) {
    o.header(m.timestamp_ns, ctx.frame_id);
    o.vector3(m.position.x, m.position.y, m.position.z);
    o.num(m.orientation.x);
    o.vector3(m.orientation.y, m.orientation.z, m.orientation.w);
  }
  static bool get(In& in, Horus& m) {
    std::string_view frame;
    return in.header(m.timestamp_ns, frame) && in.vector3(m.position.x, m.position.y, m.position.z, "pose.position") &&
           in.num(m.orientation.x, "pose.orientation") &&
           in.vector3(m.orientation.y, m.orientation.z, m.orientation.w, "pose.orientation");
  }
};

// geometry_msgs/msg/TransformStamped: header, child_frame_id, translation, rotation (x, y, z, w).
template <class S>
void put_transform(Out<S>& o, const msg::TransformStamped& m, const Context& ctx) {
  o.header(m.timestamp_ns, ctx.frame_id);
  o.string(ctx.child_frame_id);
  o.run(std::span<const double>(m.translation));
  o.run(std::span<const double>(m.rotation));
}
bool get_transform(In& in, msg::TransformStamped& m, std::string_view field) {
  std::string_view frame, child;
  return in.header(m.timestamp_ns, frame) && in.string_view(child, field) &&
         in.run(m.translation.data(), 3, field) && in.run(m.rotation.data(), 4, field);
}

struct TransformTransformStamped {
  using Horus = msg::TransformStamped;
  static constexpr std::string_view kRos = "geometry_msgs/msg/TransformStamped";
  static constexpr bool kPreferred = true;
  static constexpr std::string_view kLoses =
      "to ROS 2: header.frame_id and child_frame_id are the rule's frame_id and child_frame_id; from ROS 2: both "
      "frame ids";
  template <class S>
  static void put(Out<S>& o, const Horus& m, const Context& ctx) {
    put_transform(o, m, ctx);
  }
  static bool get(In& in, Horus& m) { return get_transform(in, m, "transform"); }
};

struct TransformTFMessage {
  using Horus = msg::TransformStamped;
  static constexpr std::string_view kRos = "tf2_msgs/msg/TFMessage";
  static constexpr bool kPreferred = false;
  static constexpr std::string_view kLoses =
      "to ROS 2: one transform per message, its frame ids the rule's; from ROS 2: a message of exactly one transform "
      "(more are refused and counted), its frame ids";
  template <class S>
  static void put(Out<S>& o, const Horus& m, const Context& ctx) {
    o.count(1);
    put_transform(o, m, ctx);
  }
  static bool get(In& in, Horus& m) {
    std::size_t n = 0;
    if (!in.count(n, 4, "transforms")) return false;
    if (n != 1)
      return in.over("transforms", std::to_string(n) + " transforms; horus::msg::TransformStamped holds exactly 1");
    return get_transform(in, m, "transforms[0]");
  }
};

struct WrenchWrenchStamped {
  using Horus = msg::WrenchStamped;
  static constexpr std::string_view kRos = "geometry_msgs/msg/WrenchStamped";
  static constexpr bool kPreferred = true;
  static constexpr std::string_view kLoses =
      "to ROS 2: point_of_application (ROS 2 gives the wrench at the frame's origin); from ROS 2: "
      "point_of_application is the origin";
  template <class S>
  static void put(Out<S>& o, const Horus& m, const Context& ctx) {
    o.header(m.timestamp_ns, frame_or(fixed_str_view(m.frame_id), ctx.frame_id));
    o.vector3(m.force.x, m.force.y, m.force.z);
    o.vector3(m.torque.x, m.torque.y, m.torque.z);
  }
  static bool get(In& in, Horus& m) {
    std::string_view frame;
    return in.header(m.timestamp_ns, frame) &&
           in.text(m.frame_id, frame, "header.frame_id", "horus::msg::WrenchStamped.frame_id") &&
           in.vector3(m.force.x, m.force.y, m.force.z, "wrench.force") &&
           in.vector3(m.torque.x, m.torque.y, m.torque.z, "wrench.torque");
  }
};

constexpr Conversion kGeometry[] = {
    make_conversion<CmdVelTwist>(),        make_conversion<CmdVelTwistStamped>(),
    make_conversion<TwistTwist>(),         make_conversion<TwistTwistStamped>(),
    make_conversion<Pose2DPose2D>(),       make_conversion<Pose3DPoseStamped>(),
    make_conversion<TransformTransformStamped>(), make_conversion<TransformTFMessage>(),
    make_conversion<WrenchWrenchStamped>(),
};

}  // namespace

std::span<const Conversion> geometry_conversions() noexcept { return kGeometry; }

}  // namespace horus::ros2::detail
