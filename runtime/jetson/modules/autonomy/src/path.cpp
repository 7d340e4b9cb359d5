#include <autodrive/autonomy/path.hpp>

#include <cmath>

namespace autodrive::autonomy {

double path_length_m(const Path &path) {
  double s = 0.0;
  for (size_t i = 1; i < path.size(); ++i)
    s += std::hypot(path[i].pose.x_m - path[i - 1].pose.x_m,
                    path[i].pose.y_m - path[i - 1].pose.y_m);
  return s;
}

int path_cusps(const Path &path) {
  int n = 0;
  for (size_t i = 1; i < path.size(); ++i) n += path[i].direction != path[i - 1].direction;
  return n;
}

Pose2 arc_step(const Pose2 &p, double ds_m, double k) {
  const double dth = k * ds_m;
  if (std::abs(dth) < 1e-9) {
    return {p.x_m + ds_m * std::cos(p.yaw_rad), p.y_m + ds_m * std::sin(p.yaw_rad), p.yaw_rad};
  }
  const double r = 1.0 / k;
  return {p.x_m + r * (std::sin(p.yaw_rad + dth) - std::sin(p.yaw_rad)),
          p.y_m - r * (std::cos(p.yaw_rad + dth) - std::cos(p.yaw_rad)),
          angle_wrap_rad(p.yaw_rad + dth)};
}

}  // namespace autodrive::autonomy
