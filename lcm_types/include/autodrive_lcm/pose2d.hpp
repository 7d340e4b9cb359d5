// A planar pose message in the map frame, filled in one place for every producer (the Eye,
// AMCL): units in the type (lcm_types/autodrive/pose2d_t.lcm).
#pragma once

#include <autodrive/pose2d_t.hpp>

#include <array>
#include <cstdint>
#include <string>

namespace autodrive_lcm {

// cov: x, y, yaw row-major [m^2, m rad, rad^2]; source: pose2d_t::SOURCE_*.
inline autodrive::pose2d_t map_pose2d(int64_t utime_us, const std::string &vehicle, int8_t source,
                                      double x_m, double y_m, double yaw_rad,
                                      const std::array<double, 9> &cov) {
  autodrive::pose2d_t m{};
  m.utime = utime_us;
  m.vehicle = vehicle;
  m.frame_id = "map";
  m.source = source;
  m.x_m = x_m;
  m.y_m = y_m;
  m.yaw_rad = yaw_rad;
  for (size_t i = 0; i < cov.size(); ++i) m.covariance[i] = cov[i];
  return m;
}

}  // namespace autodrive_lcm
