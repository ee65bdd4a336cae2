// Conversions between horus geometry messages and Eigen types.
//
//   Eigen::Isometry3d T = horus::msg::to_eigen(pose3d);
//   auto pose = horus::msg::pose3d_from_eigen(T * offset, stamp_ns);
//
// Quaternions: horus stores (x, y, z, w), while Eigen's Quaterniond constructor
// takes (w, x, y, z) and coeffs() is (x, y, z, w); these functions take care of
// the order. A message rotation is normalised before it becomes an isometry
// (a zero quaternion becomes identity), so an Isometry is always a rigid
// transform; to_eigen(Quaternion) converts the four numbers as they are.
#pragma once

#include <cmath>
#include <cstdint>

#include <Eigen/Geometry>

#include "horus/msg/geometry.hpp"

#include "horus/export.hpp"

HORUS_API_BEGIN

namespace horus::msg {

inline Eigen::Vector3d to_eigen(const Point3& p) { return Eigen::Vector3d(p.x, p.y, p.z); }
inline Eigen::Vector3d to_eigen(const Vector3& v) { return Eigen::Vector3d(v.x, v.y, v.z); }
inline Eigen::Quaterniond to_eigen(const Quaternion& q) { return Eigen::Quaterniond(q.w, q.x, q.y, q.z); }

inline Eigen::Isometry3d to_eigen(const Pose3D& p) {
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  t.linear() = to_eigen(p.orientation.normalized()).toRotationMatrix();
  t.translation() = to_eigen(p.position);
  return t;
}

inline Eigen::Isometry3d to_eigen(const TransformStamped& tf) {
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  t.linear() = to_eigen(tf.rotation_quaternion().normalized()).toRotationMatrix();
  t.translation() = Eigen::Vector3d(tf.translation[0], tf.translation[1], tf.translation[2]);
  return t;
}

inline Eigen::Isometry2d to_eigen(const Pose2D& p) {
  Eigen::Isometry2d t = Eigen::Isometry2d::Identity();
  t.linear() = Eigen::Rotation2Dd(p.theta).toRotationMatrix();
  t.translation() = Eigen::Vector2d(p.x, p.y);
  return t;
}

inline Point3 point3_from_eigen(const Eigen::Vector3d& v) { return Point3{v.x(), v.y(), v.z()}; }
inline Vector3 vector3_from_eigen(const Eigen::Vector3d& v) { return Vector3{v.x(), v.y(), v.z()}; }
inline Quaternion quaternion_from_eigen(const Eigen::Quaterniond& q) { return Quaternion{q.x(), q.y(), q.z(), q.w()}; }

/// The pose of an isometry (its rotation as a unit quaternion).
inline Pose3D pose3d_from_eigen(const Eigen::Isometry3d& t, std::uint64_t timestamp_ns = 0) {
  const Eigen::Quaterniond q(t.linear());
  return Pose3D{point3_from_eigen(t.translation()), quaternion_from_eigen(q.normalized()), timestamp_ns};
}

inline TransformStamped transform_from_eigen(const Eigen::Isometry3d& t, std::uint64_t timestamp_ns = 0) {
  const Eigen::Quaterniond q = Eigen::Quaterniond(t.linear()).normalized();
  const Eigen::Vector3d p = t.translation();
  return TransformStamped{{p.x(), p.y(), p.z()}, {q.x(), q.y(), q.z(), q.w()}, timestamp_ns};
}

/// The planar pose of a 2D isometry; theta in [-pi, pi].
inline Pose2D pose2d_from_eigen(const Eigen::Isometry2d& t, std::uint64_t timestamp_ns = 0) {
  const Eigen::Matrix2d r = t.linear();
  return Pose2D{t.translation().x(), t.translation().y(), std::atan2(r(1, 0), r(0, 0)), timestamp_ns};
}

}  // namespace horus::msg

HORUS_API_END
