#include <autodrive/autonomy/laser_odometry.hpp>

#include <cmath>

namespace autodrive::autonomy {

LaserOdomStep LaserOdometry::update(const Scan &scan, const Pose2 &odom_motion) {
  LaserOdomStep step;
  std::vector<Eigen::Vector2d> pts = scan_points_base(scan, cfg_.lidar_in_base);
  ++scans_;
  if (key_points_.empty()) {  // the first scan is the first keyframe, at the origin
    key_points_ = std::move(pts);
    return step;
  }
  // The odometry's guess of this scan relative to the keyframe.
  const Pose2 odom_pose = pose_compose(pose_, odom_motion);
  const Pose2 guess = pose_between(key_pose_, odom_pose);
  const IcpResult r = icp_match(key_points_, pts, guess, cfg_.icp);
  const Pose2 d = pose_between(guess, r.motion);
  const bool ok = !r.failed && r.inliers >= cfg_.min_inliers && r.rms_m <= cfg_.max_rms_m &&
                  std::hypot(d.x_m, d.y_m) <= cfg_.max_disagree_m &&
                  std::abs(d.yaw_rad) <= cfg_.max_disagree_rad;
  const Pose2 new_pose = ok ? pose_compose(key_pose_, r.motion) : odom_pose;
  if (!ok) ++rejected_;
  step.motion = pose_between(pose_, new_pose);
  step.from_icp = ok;
  step.rms_m = r.rms_m;
  step.inliers = r.inliers;
  pose_ = new_pose;
  const Pose2 since_key = pose_between(key_pose_, pose_);
  const bool moved_on = std::hypot(since_key.x_m, since_key.y_m) >= cfg_.keyframe_dist_m ||
                        std::abs(since_key.yaw_rad) >= cfg_.keyframe_angle_rad;
  // A rejected scan is no keyframe (its pose is only as good as the odometry), unless the
  // keyframe is so far behind that registration on it can no longer work.
  const bool lost = std::hypot(since_key.x_m, since_key.y_m) >= 3 * cfg_.keyframe_dist_m ||
                    std::abs(since_key.yaw_rad) >= 3 * cfg_.keyframe_angle_rad;
  if ((ok && moved_on) || lost) {
    key_points_ = std::move(pts);
    key_pose_ = pose_;
  }
  return step;
}

}  // namespace autodrive::autonomy
