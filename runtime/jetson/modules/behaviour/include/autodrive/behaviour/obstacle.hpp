// Obstacles on the car's own path, from its planar LIDAR scan (what a real car has; the map
// knows nothing of a box dropped on the road). Each return is placed on the map with the car's
// EKF pose and projected on the track: a return within corridor_half_m of the centre line and
// ahead of the front bumper is on the path. Pure geometry (no I/O): the program feeds the scan.
#pragma once

#include <autodrive_vehicle.h>

#include <vector>

#include <autodrive/behaviour/city_map.hpp>

namespace autodrive::behaviour {

struct ObstacleConfig {
  // half the swept width (wheels included) plus a margin: a return this close to the centre
  // line would touch the car [m]
  double corridor_half_m = 0.5 * AUTODRIVE_VEHICLE_ENVELOPE_WIDTH_M + 0.03;
  double horizon_m = 1.2;  // how far ahead along the track returns are looked at [m]
  int min_returns = 2;     // fewer returns on the path than this are noise, not an obstacle
  // the LIDAR in base_link [m] (nigel.params lidar_pos_m)
  double lidar_x_m = AUTODRIVE_VEHICLE_LIDAR_POS_M_X, lidar_y_m = AUTODRIVE_VEHICLE_LIDAR_POS_M_Y;
};

struct Scan {
  double angle_min_rad = 0, angle_increment_rad = 0;  // CCW from the LIDAR's x (forward)
  double range_min_m = 0, range_max_m = 0;
  std::vector<float> ranges_m;  // +inf or out of [min, max]: no return
};

struct CarPose {
  double x_m = 0, y_m = 0, yaw_rad = 0;  // base_link on the map
  double s_m = 0;                        // its progress along the track [m]
};

// Along the track from base_link's progress to the nearest obstacle on the path [m]; < 0 when
// the path is clear for horizon_m.
double obstacle_ahead_m(const Track &track, const CarPose &car, const Scan &scan,
                        const ObstacleConfig &cfg, double front_m);

// The nearest obstacle's place along the track, from scan to scan: the car moves on between
// scans (7 Hz), and the LIDAR sees nothing closer than range_min_m, so an obstacle that has
// come that close is kept (it has not gone; it is out of sight) until a scan that could see its
// place shows it clear.
class ObstacleTracker {
 public:
  void on_scan(const Track &track, const CarPose &car, const Scan &scan, const ObstacleConfig &cfg,
               double front_m);
  // Along the track from progress s_m to the obstacle [m]; < 0: none.
  double ahead_m(const Track &track, double s_m) const;

 private:
  bool have_ = false;
  double s_m_ = 0;  // the obstacle's progress along the track [m], in [0, length) on a loop
};

}  // namespace autodrive::behaviour
