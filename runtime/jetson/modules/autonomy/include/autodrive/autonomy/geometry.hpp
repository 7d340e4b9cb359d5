// Small 2-D geometry helpers shared by every autonomy module (SI units, REP-103 frames).
#pragma once
#include <cmath>
#include <vector>

#include <Eigen/Core>
#include <autodrive/angles.hpp>

namespace autodrive::autonomy {

using autodrive::angle_wrap_rad;
using autodrive::kPi;

// Pose of a frame on the plane: position [m] and heading [rad], CCW from x.
struct Pose2 {
  double x_m = 0.0;
  double y_m = 0.0;
  double yaw_rad = 0.0;
};

// a (+) b: b expressed in a's frame, moved into a's parent frame.
inline Pose2 pose_compose(const Pose2 &a, const Pose2 &b) {
  const double c = std::cos(a.yaw_rad), s = std::sin(a.yaw_rad);
  return {a.x_m + c * b.x_m - s * b.y_m, a.y_m + s * b.x_m + c * b.y_m,
          angle_wrap_rad(a.yaw_rad + b.yaw_rad)};
}

// Inverse pose: (-)a.
inline Pose2 pose_inverse(const Pose2 &a) {
  const double c = std::cos(a.yaw_rad), s = std::sin(a.yaw_rad);
  return {-c * a.x_m - s * a.y_m, s * a.x_m - c * a.y_m, angle_wrap_rad(-a.yaw_rad)};
}

// b relative to a: (-)a (+) b.
inline Pose2 pose_between(const Pose2 &a, const Pose2 &b) {
  return pose_compose(pose_inverse(a), b);
}

inline Eigen::Vector2d pose_apply(const Pose2 &p, const Eigen::Vector2d &v) {
  const double c = std::cos(p.yaw_rad), s = std::sin(p.yaw_rad);
  return {p.x_m + c * v.x() - s * v.y(), p.y_m + s * v.x() + c * v.y()};
}

// A planar scan as ROS LaserScan: ray i at angle_min_rad + i * angle_increment_rad.
// Non-finite or out-of-[range_min_m, range_max_m] ranges mean "no return".
struct Scan {
  double angle_min_rad = 0.0;
  double angle_increment_rad = 0.0;
  double range_min_m = 0.15;
  double range_max_m = 12.0;
  double scan_time_s = 0.0;  // one revolution; the scan's stamp is its start
  std::vector<float> ranges_m;
};

// Endpoints of the valid rays, in the frame of the vehicle base: the LIDAR sits at
// lidar_in_base (on Nigel: lidar_pos_m of vehicle/nigel.params).
std::vector<Eigen::Vector2d> scan_points_base(const Scan &scan, const Pose2 &lidar_in_base);

}  // namespace autodrive::autonomy
