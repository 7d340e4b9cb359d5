// slam_: occupancy-grid SLAM in the manner of Hector SLAM (Kohlbrecher et al. 2011): no
// odometry needed; each scan is matched against the map so far by Gauss-Newton on the
// bilinearly interpolated occupancy probability, coarse to fine over 2-3 map resolutions,
// then written into every resolution level.
#pragma once

#include <autodrive_vehicle.h>
#include <vector>

#include <autodrive/autonomy/grid_map.hpp>

namespace autodrive::autonomy {

struct SlamConfig {
  double resolution_m = 0.02;  // finest level; level k has resolution_m * 2^k
  int levels = 3;
  double width_m = 12.0, height_m = 12.0;
  double origin_x_m = -6.0, origin_y_m = -6.0;
  float l_free = -0.4f, l_occ = 0.9f, l_min = -6.0f, l_max = 6.0f;  // log-odds update/clamp
  int iterations_per_level = 12;
  double update_min_dist_m = 0.03;  // map is rewritten only after this much motion [m]
  double update_min_angle_rad = 0.05;
  int initial_integrations = 5;  // scans written regardless of motion, to seed the map
  Pose2 lidar_in_base{AUTODRIVE_VEHICLE_LIDAR_POS_M_X, AUTODRIVE_VEHICLE_LIDAR_POS_M_Y, 0.0};
};

// scan_match_: one Gauss-Newton refinement of a pose guess on one map level.
// points_base: scan endpoints in the vehicle base frame [m]. Returns the refined base pose.
Pose2 scan_match_level(const GridMap &map, const std::vector<Eigen::Vector2d> &points_base,
                       const Pose2 &guess, int iterations);

// Coarse-to-fine over levels (levels[0] finest).
Pose2 scan_match(const std::vector<GridMap> &levels,
                 const std::vector<Eigen::Vector2d> &points_base, const Pose2 &guess,
                 int iterations_per_level);

class HectorSlam {
 public:
  HectorSlam(const SlamConfig &cfg, const Pose2 &start_pose);
  // Matches the scan (starting from the last pose, moved by the optional motion guess in the
  // base frame), updates the map, returns the new pose estimate in the map frame.
  // match = false trusts the motion guess (odometry says the car stood still: matching a scan
  // against a map of one or two scans can slide into a wrong basin by centimetres).
  Pose2 update(const Scan &scan, const Pose2 &motion_guess = Pose2{}, bool match = true);
  const GridMap &map() const { return levels_.front(); }
  const std::vector<GridMap> &levels() const { return levels_; }
  Pose2 pose() const { return pose_; }
  int scans_integrated() const { return scans_integrated_; }
  int scans_processed() const { return scans_processed_; }

 private:
  void integrate(const std::vector<Eigen::Vector2d> &points_base, const Pose2 &pose,
                 const Scan &scan);
  SlamConfig cfg_;
  std::vector<GridMap> levels_;
  Pose2 pose_;
  Pose2 last_update_pose_;
  int scans_integrated_ = 0;
  int scans_processed_ = 0;
};

}  // namespace autodrive::autonomy
