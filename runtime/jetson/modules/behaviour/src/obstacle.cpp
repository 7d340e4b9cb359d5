#include <autodrive/behaviour/obstacle.hpp>

#include <algorithm>
#include <cmath>

namespace autodrive::behaviour {

double obstacle_ahead_m(const Track &track, const CarPose &car, const Scan &scan,
                        const ObstacleConfig &cfg, double front_m) {
  const double c = std::cos(car.yaw_rad), s = std::sin(car.yaw_rad);
  std::vector<double> ahead;
  for (size_t i = 0; i < scan.ranges_m.size(); ++i) {
    const double r = scan.ranges_m[i];
    if (!std::isfinite(r) || r < scan.range_min_m || r > scan.range_max_m) continue;
    if (r > cfg.horizon_m + front_m) continue;  // beyond the horizon however the track bends
    const double a = scan.angle_min_rad + static_cast<double>(i) * scan.angle_increment_rad;
    const double bx = cfg.lidar_x_m + r * std::cos(a), by = cfg.lidar_y_m + r * std::sin(a);
    if (bx < front_m) continue;  // beside or behind the front: not in the way ahead
    const double x = car.x_m + c * bx - s * by, y = car.y_m + s * bx + c * by;
    const auto p = project(track, x, y, car.s_m, 0.0, cfg.horizon_m + front_m);
    if (p.dist_m > cfg.corridor_half_m) continue;
    double d = p.s_m - car.s_m;
    if (track.loop && d < 0) d += track.length_m;
    if (d >= front_m && d <= front_m + cfg.horizon_m) ahead.push_back(d);
  }
  if (static_cast<int>(ahead.size()) < cfg.min_returns) return -1.0;
  // the min_returns-th nearest: a lone stray return does not stop the car
  std::nth_element(ahead.begin(), ahead.begin() + (cfg.min_returns - 1), ahead.end());
  return ahead[static_cast<size_t>(cfg.min_returns - 1)];
}

void ObstacleTracker::on_scan(const Track &track, const CarPose &car, const Scan &scan,
                              const ObstacleConfig &cfg, double front_m) {
  const double d = obstacle_ahead_m(track, car, scan, cfg, front_m);
  if (d >= 0) {
    have_ = true;
    s_m_ = car.s_m + d;
    if (track.loop && s_m_ >= track.length_m) s_m_ -= track.length_m;
    return;
  }
  const double kept = ahead_m(track, car.s_m);
  // out of sight: nearer the LIDAR than its range_min (with 2 cm to spare)
  if (kept >= 0 && kept - cfg.lidar_x_m < scan.range_min_m + 0.02) return;
  have_ = false;
}

double ObstacleTracker::ahead_m(const Track &track, double s_m) const {
  if (!have_) return -1.0;
  double d = s_m_ - s_m;
  if (track.loop) d = std::remainder(d, track.length_m);
  return d < 0 ? 0.0 : d;  // the car stands at or over it: in the way
}

}  // namespace autodrive::behaviour
