#include <autodrive/autonomy/slam.hpp>

#include <algorithm>
#include <cmath>

#include <Eigen/Dense>

namespace autodrive::autonomy {
namespace {

// Bilinear occupancy probability and its gradient [1/m] at a world point.
double map_sample(const GridMap &m, double x_m, double y_m, Eigen::Vector2d &grad_per_m) {
  const Eigen::Vector2d c = m.world_to_cellf(x_m, y_m);
  const double u = c.x() - 0.5, v = c.y() - 0.5;  // relative to cell centres
  const int i0 = static_cast<int>(std::floor(u)), j0 = static_cast<int>(std::floor(v));
  const double fu = u - i0, fv = v - j0;
  const double m00 = m.probability(i0, j0), m10 = m.probability(i0 + 1, j0);
  const double m01 = m.probability(i0, j0 + 1), m11 = m.probability(i0 + 1, j0 + 1);
  grad_per_m.x() = ((1 - fv) * (m10 - m00) + fv * (m11 - m01)) / m.resolution_m;
  grad_per_m.y() = ((1 - fu) * (m01 - m00) + fu * (m11 - m10)) / m.resolution_m;
  return (1 - fv) * ((1 - fu) * m00 + fu * m10) + fv * ((1 - fu) * m01 + fu * m11);
}

}  // namespace

Pose2 scan_match_level(const GridMap &map, const std::vector<Eigen::Vector2d> &points_base,
                       const Pose2 &guess, int iterations) {
  Pose2 p = guess;
  for (int it = 0; it < iterations; ++it) {
    Eigen::Matrix3d H = Eigen::Matrix3d::Zero();
    Eigen::Vector3d b = Eigen::Vector3d::Zero();
    const double c = std::cos(p.yaw_rad), s = std::sin(p.yaw_rad);
    for (const auto &q : points_base) {
      const Eigen::Vector2d w = pose_apply(p, q);
      Eigen::Vector2d g;
      const double mv = map_sample(map, w.x(), w.y(), g);
      // d(world point)/d(yaw)
      const double dx_dth = -s * q.x() - c * q.y(), dy_dth = c * q.x() - s * q.y();
      const Eigen::Vector3d J(g.x(), g.y(), g.x() * dx_dth + g.y() * dy_dth);
      H += J * J.transpose();
      b += J * (1.0 - mv);
    }
    if (H.determinant() < 1e-12) break;
    const Eigen::Vector3d d = H.ldlt().solve(b);
    if (!d.allFinite()) break;
    // Cap a step to one cell / a few degrees: GN on a discretised map can overshoot.
    const double max_step_m = map.resolution_m, max_step_rad = 0.1;
    const double scale = std::min(1.0, std::min(max_step_m / std::max(1e-12, d.head<2>().norm()),
                                                max_step_rad / std::max(1e-12, std::abs(d.z()))));
    p.x_m += scale * d.x();
    p.y_m += scale * d.y();
    p.yaw_rad = angle_wrap_rad(p.yaw_rad + scale * d.z());
    if (d.head<2>().norm() < 1e-4 * map.resolution_m && std::abs(d.z()) < 1e-5) break;
  }
  return p;
}

Pose2 scan_match(const std::vector<GridMap> &levels,
                 const std::vector<Eigen::Vector2d> &points_base, const Pose2 &guess,
                 int iterations_per_level) {
  Pose2 p = guess;
  for (int k = static_cast<int>(levels.size()) - 1; k >= 0; --k)
    p = scan_match_level(levels[k], points_base, p, iterations_per_level);
  return p;
}

HectorSlam::HectorSlam(const SlamConfig &cfg, const Pose2 &start_pose)
    : cfg_(cfg), pose_(start_pose), last_update_pose_(start_pose) {
  for (int k = 0; k < cfg.levels; ++k) {
    const double res = cfg.resolution_m * std::pow(2.0, k);
    levels_.emplace_back(static_cast<int>(std::ceil(cfg.width_m / res)),
                         static_cast<int>(std::ceil(cfg.height_m / res)), res, cfg.origin_x_m,
                         cfg.origin_y_m);
  }
}

void HectorSlam::integrate(const std::vector<Eigen::Vector2d> &, const Pose2 &pose,
                           const Scan &scan) {
  const Eigen::Vector2d sensor = pose_apply(pose, {cfg_.lidar_in_base.x_m, cfg_.lidar_in_base.y_m});
  const Pose2 lidar_pose = pose_compose(pose, cfg_.lidar_in_base);
  std::vector<Eigen::Vector2d> ends;
  std::vector<uint8_t> hit;
  for (size_t i = 0; i < scan.ranges_m.size(); ++i) {
    double r_m = scan.ranges_m[i];
    bool h = true;
    if (!std::isfinite(r_m) || r_m > scan.range_max_m) {
      r_m = scan.range_max_m;  // free space up to max range, no endpoint
      h = false;
    } else if (r_m < scan.range_min_m) {
      continue;
    }
    const double a_rad = scan.angle_min_rad + static_cast<double>(i) * scan.angle_increment_rad;
    ends.push_back(pose_apply(lidar_pose, {r_m * std::cos(a_rad), r_m * std::sin(a_rad)}));
    hit.push_back(h);
  }
  for (auto &m : levels_) {
    // Free updates first, then endpoints, and an endpoint cell is never cleared by another
    // ray of the same scan: on coarse levels grazing rays would otherwise erase thin walls.
    std::vector<float> before;
    std::vector<int> end_cells;
    for (size_t i = 0; i < ends.size(); ++i) {
      int cx, cy;
      if (hit[i] && m.world_to_cell(ends[i].x(), ends[i].y(), cx, cy))
        end_cells.push_back(m.index(cx, cy));
    }
    for (int c : end_cells) before.push_back(m.log_odds[c]);
    // Hit rays clear space only up to 1.5 cells short of the hit, so rays grazing a wall do
    // not erase the wall cells next to their own endpoint.
    for (size_t i = 0; i < ends.size(); ++i) {
      Eigen::Vector2d e = ends[i];
      if (hit[i]) {
        const Eigen::Vector2d d = ends[i] - sensor;
        const double r = d.norm();
        e = sensor + d * (std::max(0.0, r - 1.5 * m.resolution_m) / std::max(r, 1e-9));
      }
      m.update_ray(sensor.x(), sensor.y(), e.x(), e.y(), false, cfg_.l_free, 0.0f, cfg_.l_min,
                   cfg_.l_max);
    }
    for (size_t k = 0; k < end_cells.size(); ++k) m.log_odds[end_cells[k]] = before[k];
    std::sort(end_cells.begin(), end_cells.end());
    end_cells.erase(std::unique(end_cells.begin(), end_cells.end()), end_cells.end());
    for (int c : end_cells)
      m.log_odds[c] = std::clamp(m.log_odds[c] + cfg_.l_occ, cfg_.l_min, cfg_.l_max);
  }
  ++scans_integrated_;
}

Pose2 HectorSlam::update(const Scan &scan, const Pose2 &motion_guess, bool match) {
  ++scans_processed_;
  const auto pts = scan_points_base(scan, cfg_.lidar_in_base);
  if (scans_integrated_ == 0) {
    integrate(pts, pose_, scan);
    last_update_pose_ = pose_;
    return pose_;
  }
  pose_ = pose_compose(pose_, motion_guess);
  if (match) pose_ = scan_match(levels_, pts, pose_, cfg_.iterations_per_level);
  const Pose2 d = pose_between(last_update_pose_, pose_);
  if (std::hypot(d.x_m, d.y_m) >= cfg_.update_min_dist_m ||
      std::abs(d.yaw_rad) >= cfg_.update_min_angle_rad ||
      scans_integrated_ < cfg_.initial_integrations) {
    integrate(pts, pose_, scan);
    last_update_pose_ = pose_;
  }
  return pose_;
}

}  // namespace autodrive::autonomy
