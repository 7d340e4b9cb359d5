// lp_: local obstacle check of the path ahead against the live LIDAR scan. A scan point that
// falls inside the car's footprint (plus margin) at any path pose within the horizon blocks
// the path; the mission then marks the point in the planning grid and replans.
#pragma once
#include <vector>

#include <autodrive/autonomy/footprint.hpp>

namespace autodrive::autonomy {

struct LocalCheck {
  bool blocked = false;         // false = the path ahead is clear
  double distance_ahead_m = 0;  // path length to the first blocked pose [m]
  Eigen::Vector2d obstacle_m{0, 0};
};

LocalCheck lp_check_path(const Path &path, size_t from_index, double horizon_m,
                         const std::vector<Eigen::Vector2d> &points_map, const Footprint &fp);

// Scan points (map frame) farther than min_dist_m from every mapped obstacle: unmapped things.
std::vector<Eigen::Vector2d> lp_unmapped_points(const GridMap &map,
                                                const std::vector<float> &field_m,
                                                const std::vector<Eigen::Vector2d> &points_map,
                                                double min_dist_m);

}  // namespace autodrive::autonomy
