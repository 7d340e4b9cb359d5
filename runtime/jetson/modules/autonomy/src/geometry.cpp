#include <autodrive/autonomy/geometry.hpp>

namespace autodrive::autonomy {

std::vector<Eigen::Vector2d> scan_points_base(const Scan &scan, const Pose2 &lidar_in_base) {
  std::vector<Eigen::Vector2d> pts;
  pts.reserve(scan.ranges_m.size());
  for (size_t i = 0; i < scan.ranges_m.size(); ++i) {
    const double r_m = scan.ranges_m[i];
    if (!std::isfinite(r_m) || r_m < scan.range_min_m || r_m > scan.range_max_m) continue;
    const double a_rad = scan.angle_min_rad + static_cast<double>(i) * scan.angle_increment_rad;
    pts.push_back(pose_apply(lidar_in_base, {r_m * std::cos(a_rad), r_m * std::sin(a_rad)}));
  }
  return pts;
}

}  // namespace autodrive::autonomy
