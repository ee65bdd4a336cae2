// The list of every standard message, by domain: what the catalogue tool prints, and what
// the tests iterate over (every type through the Topic, JSON, the codec).
//
//   horus::msg::for_each_message([]<class T>(std::string_view domain) { ... });
//
// A new standard message goes into its domain's list here; the catalogue test then fails
// until messages/README.md is regenerated (horus-msg-catalogue --update messages/README.md).
#pragma once

#include <cstddef>
#include <string_view>

#include "horus/messages.hpp"

#include "horus/export.hpp"

HORUS_API_BEGIN

namespace horus::msg {

template <class... T>
struct TypeList {
  static constexpr std::size_t size = sizeof...(T);
};

namespace detail {
template <class... L>
struct Concat;
template <class... A>
struct Concat<TypeList<A...>> {
  using type = TypeList<A...>;
};
template <class... A, class... B, class... Rest>
struct Concat<TypeList<A...>, TypeList<B...>, Rest...> {
  using type = typename Concat<TypeList<A..., B...>, Rest...>::type;
};
}  // namespace detail

using GeometryMessages = TypeList<CmdVel, Twist, Pose2D, Pose3D, Point3, Vector3, Quaternion, TransformStamped,
                                  Accel, AccelStamped, PoseWithCovariance, TwistWithCovariance>;
using SensorMessages = TypeList<LaserScan, Imu, Odometry, Range, BatteryState, NavSatFix, JointState>;
using ControlMessages =
    TypeList<MotorCommand, DifferentialDriveCommand, ServoCommand, JointCommand, PidConfig, TrajectoryPoint>;
using VisionMessages = TypeList<Image, ImageDescriptor, CompressedImage, CameraInfo, StereoInfo, RegionOfInterest>;
using DetectionMessages = TypeList<BoundingBox2D, BoundingBox3D, Detection, Detection3D>;
using PerceptionMessages = TypeList<PointCloud, PointXYZ, PointXYZRGB, PointXYZI, DepthImage, Tensor, Device,
                                    PointCloudDescriptor, DepthImageDescriptor, TensorDescriptor>;
using NavigationMessages = TypeList<Goal, GoalResult, Waypoint, Path, NavPath, PathPlan, OccupancyGrid, CostMap,
                                    VelocityObstacle, VelocityObstacles>;
using DiagnosticsMessages = TypeList<Heartbeat, NodeHeartbeat, Status, DiagnosticStatus, EmergencyStop, SafetyStatus,
                                     ResourceUsage, DiagnosticValue, DiagnosticReport>;
using ForceMessages = TypeList<WrenchStamped, ImpedanceParameters, ForceCommand, ContactInfo, HapticFeedback>;
using InputMessages = TypeList<JoystickInput, KeyboardInput>;
using TrackingMessages =
    TypeList<SegmentationMask, Landmark, Landmark3D, LandmarkArray, TrackedObject, TrackingHeader>;
using TimeMessages = TypeList<Clock, TimeReference>;
using AudioMessages = TypeList<AudioFrame>;
using GenericMessages = TypeList<GenericMessage>;

/// Every standard message type.
using AllMessages =
    detail::Concat<GeometryMessages, SensorMessages, ControlMessages, VisionMessages, DetectionMessages,
                   PerceptionMessages, NavigationMessages, DiagnosticsMessages, ForceMessages, InputMessages,
                   TrackingMessages, TimeMessages, AudioMessages, GenericMessages>::type;

namespace detail {
template <class F, class... T>
void visit(std::string_view domain, TypeList<T...>, F& f) {
  (f.template operator()<T>(domain), ...);
}
}  // namespace detail

/// Calls f.template operator()<T>(domain) for every standard message, in catalogue order.
template <class F>
void for_each_message(F&& f) {
  detail::visit("geometry", GeometryMessages{}, f);
  detail::visit("sensor", SensorMessages{}, f);
  detail::visit("control", ControlMessages{}, f);
  detail::visit("vision", VisionMessages{}, f);
  detail::visit("detection", DetectionMessages{}, f);
  detail::visit("perception", PerceptionMessages{}, f);
  detail::visit("navigation", NavigationMessages{}, f);
  detail::visit("diagnostics", DiagnosticsMessages{}, f);
  detail::visit("force", ForceMessages{}, f);
  detail::visit("input", InputMessages{}, f);
  detail::visit("tracking", TrackingMessages{}, f);
  detail::visit("time", TimeMessages{}, f);
  detail::visit("audio", AudioMessages{}, f);
  detail::visit("generic", GenericMessages{}, f);
}

}  // namespace horus::msg

HORUS_API_END
