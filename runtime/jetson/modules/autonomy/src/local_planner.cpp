#include <autodrive/autonomy/local_planner.hpp>

#include <cmath>

namespace autodrive::autonomy {

LocalCheck lp_check_path(const Path &path, size_t from_index, double horizon_m,
                         const std::vector<Eigen::Vector2d> &points_map, const Footprint &fp) {
  LocalCheck out;
  const double half_l = 0.5 * fp.length_m + fp.margin_m, half_w = 0.5 * fp.width_m + fp.margin_m;
  double s = 0.0;
  for (size_t i = from_index; i < path.size(); ++i) {
    if (i > from_index)
      s += std::hypot(path[i].pose.x_m - path[i - 1].pose.x_m,
                      path[i].pose.y_m - path[i - 1].pose.y_m);
    if (s > horizon_m) break;
    const Pose2 &p = path[i].pose;
    const double c = std::cos(p.yaw_rad), sn = std::sin(p.yaw_rad);
    for (const auto &q : points_map) {
      const double dx = q.x() - p.x_m, dy = q.y() - p.y_m;
      const double lx = c * dx + sn * dy - fp.center_ahead_m, ly = -sn * dx + c * dy;
      if (std::abs(lx) <= half_l && std::abs(ly) <= half_w) {
        out.blocked = true;
        out.distance_ahead_m = s;
        out.obstacle_m = q;
        return out;
      }
    }
  }
  return out;
}

std::vector<Eigen::Vector2d> lp_unmapped_points(const GridMap &map,
                                                const std::vector<float> &field_m,
                                                const std::vector<Eigen::Vector2d> &points_map,
                                                double min_dist_m) {
  std::vector<Eigen::Vector2d> out;
  for (const auto &q : points_map) {
    int cx, cy;
    if (!map.world_to_cell(q.x(), q.y(), cx, cy)) continue;
    // field_m is to occupied-or-unknown cells; an unknown cell next to a wall is still "mapped".
    if (field_m[map.index(cx, cy)] >= min_dist_m) out.push_back(q);
  }
  return out;
}

}  // namespace autodrive::autonomy
