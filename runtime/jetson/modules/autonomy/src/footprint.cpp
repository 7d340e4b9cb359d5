#include <autodrive/autonomy/footprint.hpp>

#include <algorithm>
#include <cmath>

namespace autodrive::autonomy {

CollisionChecker::CollisionChecker(const GridMap &map, const Footprint &fp,
                                   bool unknown_is_obstacle)
    : map_(map), fp_(fp), field_m_(grid_distance_field_m(map, unknown_is_obstacle)) {
  const double seg_m = fp.length_m / fp.discs;
  disc_radius_m_ = std::hypot(0.5 * seg_m, 0.5 * fp.width_m);
  for (int i = 0; i < fp.discs; ++i)
    disc_offsets_m_.push_back(fp.center_ahead_m - 0.5 * fp.length_m + (i + 0.5) * seg_m);
}

double CollisionChecker::clearance_m(const Pose2 &base) const {
  double best = 1e9;
  const double c = std::cos(base.yaw_rad), s = std::sin(base.yaw_rad);
  for (double off : disc_offsets_m_) {
    int cx, cy;
    if (!map_.world_to_cell(base.x_m + c * off, base.y_m + s * off, cx, cy)) return -1.0;
    // The distance field is to cell centres: subtract half a cell diagonal to stay safe.
    const double d = field_m_[map_.index(cx, cy)] - 0.7072 * map_.resolution_m;
    best = std::min(best, d - disc_radius_m_);
  }
  return best;
}

bool CollisionChecker::path_free(const Path &path) const {
  return std::all_of(path.begin(), path.end(),
                     [&](const PathPoint &p) { return pose_free(p.pose); });
}

}  // namespace autodrive::autonomy
