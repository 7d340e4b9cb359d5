// lo_: laser odometry. Each scan is registered by ICP (icp_) on a keyframe scan; the wheel/EKF
// odometry's motion is the initial guess, and the fallback when ICP fails or disagrees with it
// by more than a wheel could slip. Keyframes (not the previous scan) keep standstill noise from
// adding up: the reference only moves on after real motion.
#pragma once

#include <autodrive_vehicle.h>
#include <vector>

#include <autodrive/autonomy/icp.hpp>

namespace autodrive::autonomy {

struct LaserOdomConfig {
  IcpConfig icp;
  Pose2 lidar_in_base{AUTODRIVE_VEHICLE_LIDAR_POS_M_X, AUTODRIVE_VEHICLE_LIDAR_POS_M_Y, 0.0};
  double max_rms_m = 0.03;           // a registration worse than this is not trusted [m]
  int min_inliers = 60;              // of the ~360 returns of an A1 revolution
  double max_disagree_m = 0.05;      // ICP vs odometry motion since the keyframe [m]
  double max_disagree_rad = 0.1;     // [rad]
  double keyframe_dist_m = 0.10;     // a new keyframe after this much motion [m]
  double keyframe_angle_rad = 0.15;  // [rad]
};

struct LaserOdomStep {
  Pose2 motion;           // base motion since the previous scan, in the previous base frame
  bool from_icp = false;  // false: the odometry guess was used (first scan or ICP rejected)
  double rms_m = 0;
  int inliers = 0;
};

class LaserOdometry {
 public:
  explicit LaserOdometry(const LaserOdomConfig &cfg) : cfg_(cfg) {}
  // odom_motion: the wheel/EKF odometry's base motion since the previous scan (the guess).
  LaserOdomStep update(const Scan &scan, const Pose2 &odom_motion);
  // Accumulated pose in the laser-odometry frame (= the base pose at the first scan).
  Pose2 pose() const { return pose_; }
  int scans() const { return scans_; }
  int rejected() const { return rejected_; }  // scans where the odometry guess was used

 private:
  LaserOdomConfig cfg_;
  std::vector<Eigen::Vector2d> key_points_;  // keyframe scan, its base frame [m]
  Pose2 key_pose_;                           // keyframe base pose, laser-odometry frame
  Pose2 pose_;
  int scans_ = 0, rejected_ = 0;
};

}  // namespace autodrive::autonomy
