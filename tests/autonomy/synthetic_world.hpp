// Test helper: a small synthetic parking lot made of wall segments, a ray-casting LIDAR
// simulator on it, its rasterisation to a GridMap, and a kinematic bicycle model.
#pragma once
#include <cmath>
#include <random>
#include <vector>

#include <Eigen/Core>
#include <autodrive_vehicle.h>

#include <autodrive/autonomy/grid_map.hpp>
#include <autodrive/autonomy/path.hpp>

namespace autodrive::synthetic_world {

using autodrive::autonomy::Pose2;

struct Segment {
  Eigen::Vector2d a, b;
};

struct World {
  std::vector<Segment> walls;

  void add_box(double x0, double y0, double x1, double y1) {
    walls.push_back({{x0, y0}, {x1, y0}});
    walls.push_back({{x1, y0}, {x1, y1}});
    walls.push_back({{x1, y1}, {x0, y1}});
    walls.push_back({{x0, y1}, {x0, y0}});
  }

  // 4 x 3 m room; four parking slots 0.3 m wide, 0.35 m deep along the bottom wall between
  // x = 2.0 and 3.2 (thin dividers); one construction box in the middle of the lot.
  static World parking_lot() {
    World w;
    w.add_box(0.0, 0.0, 4.0, 3.0);
    for (double x = 2.0; x < 3.25; x += 0.3) w.add_box(x - 0.01, 0.0, x + 0.01, 0.35);
    w.add_box(1.0, 1.6, 1.3, 1.9);
    w.add_box(3.2, 2.0, 3.5, 2.4);
    return w;
  }

  // Range along a ray from o in direction d (unit), +inf if nothing within max_range_m.
  double cast(const Eigen::Vector2d &o, const Eigen::Vector2d &d, double max_range_m) const {
    double best = std::numeric_limits<double>::infinity();
    for (const auto &s : walls) {
      const Eigen::Vector2d e = s.b - s.a;
      const double den = d.x() * e.y() - d.y() * e.x();
      if (std::abs(den) < 1e-12) continue;
      const Eigen::Vector2d w = s.a - o;
      const double t = (w.x() * e.y() - w.y() * e.x()) / den;  // along the ray
      const double u = (w.x() * d.y() - w.y() * d.x()) / den;  // along the segment
      if (t > 1e-9 && u >= 0.0 && u <= 1.0 && t < best) best = t;
    }
    return best <= max_range_m ? best : std::numeric_limits<double>::infinity();
  }

  // A 360-ray, 1-degree scan like the RPLIDAR A1, from the LIDAR at lidar_in_base.
  autodrive::autonomy::Scan scan(const Pose2 &base, const Pose2 &lidar_in_base,
                                 double noise_m = 0.0, std::mt19937 *rng = nullptr) const {
    autodrive::autonomy::Scan s;
    s.angle_min_rad = -autodrive::autonomy::kPi;
    s.angle_increment_rad = 2.0 * autodrive::autonomy::kPi / 360.0;
    s.range_min_m = 0.15;
    s.range_max_m = 12.0;
    const Pose2 lidar = autodrive::autonomy::pose_compose(base, lidar_in_base);
    std::normal_distribution<double> n(0.0, 1.0);
    for (int i = 0; i < 360; ++i) {
      const double a = lidar.yaw_rad + s.angle_min_rad + i * s.angle_increment_rad;
      double r = cast({lidar.x_m, lidar.y_m}, {std::cos(a), std::sin(a)}, s.range_max_m);
      if (std::isfinite(r) && rng && noise_m > 0) r += noise_m * n(*rng);
      s.ranges_m.push_back(static_cast<float>(r));
    }
    return s;
  }

  // Occupied where a wall passes through the cell, free elsewhere inside [0,4]x[0,3],
  // unknown outside; the grid spans [-0.5, 4.5] x [-0.5, 3.5].
  autodrive::autonomy::GridMap rasterize(double res_m) const {
    autodrive::autonomy::GridMap g(static_cast<int>(std::round(5.0 / res_m)),
                                   static_cast<int>(std::round(4.0 / res_m)), res_m, -0.5, -0.5);
    for (int cy = 0; cy < g.height_cells; ++cy) {
      for (int cx = 0; cx < g.width_cells; ++cx) {
        const Eigen::Vector2d c = g.cell_center_m(cx, cy);
        double dmin = 1e9;
        for (const auto &s : walls) {
          const Eigen::Vector2d e = s.b - s.a;
          const double t = std::clamp((c - s.a).dot(e) / e.squaredNorm(), 0.0, 1.0);
          dmin = std::min(dmin, (s.a + t * e - c).norm());
        }
        const bool inside = c.x() > 0 && c.x() < 4 && c.y() > 0 && c.y() < 3;
        float &l = g.log_odds[g.index(cx, cy)];
        if (dmin <= 0.5 * res_m * 1.4143)
          l = 5.0f;
        else
          l = inside ? -5.0f : 0.0f;
      }
    }
    return g;
  }
};

// Kinematic bicycle on the rear axle with a first-order speed lag and Nigel's steering rate.
struct Bicycle {
  Pose2 pose;
  double speed_m_s = 0.0, steer_rad = 0.0;
  double wheelbase_m = AUTODRIVE_VEHICLE_WHEELBASE_M, speed_tau_s = 0.1,
         steer_rate_rad_s = AUTODRIVE_VEHICLE_STEER_RATE_RAD_S;
  void step(double cmd_speed_m_s, double cmd_steer_rad, double dt_s) {
    speed_m_s += (cmd_speed_m_s - speed_m_s) * std::min(1.0, dt_s / speed_tau_s);
    const double ds =
        std::clamp(cmd_steer_rad - steer_rad, -steer_rate_rad_s * dt_s, steer_rate_rad_s * dt_s);
    steer_rad += ds;
    pose = autodrive::autonomy::arc_step(pose, speed_m_s * dt_s, std::tan(steer_rad) / wheelbase_m);
  }
};

// Distance from a point to a sampled path (to its polyline) [m].
inline double distance_to_path_m(const autodrive::autonomy::Path &path, const Eigen::Vector2d &p) {
  double best = 1e9;
  for (size_t i = 1; i < path.size(); ++i) {
    const Eigen::Vector2d a(path[i - 1].pose.x_m, path[i - 1].pose.y_m),
        b(path[i].pose.x_m, path[i].pose.y_m);
    const Eigen::Vector2d e = b - a;
    const double t =
        e.squaredNorm() < 1e-12 ? 0.0 : std::clamp((p - a).dot(e) / e.squaredNorm(), 0.0, 1.0);
    best = std::min(best, (a + t * e - p).norm());
  }
  return best;
}

}  // namespace autodrive::synthetic_world
