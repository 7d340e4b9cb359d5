// Path tracking on the rear axle, forward and reverse, by the one pure pursuit
// (<autodrive/pure_pursuit.h>: the goal sample, the steering law), with a speed profile
// (accelerate, cruise, slow for curvature, brake to a stop at every cusp and at the goal) and
// a short standstill at each cusp before the direction changes.
// Output is the vehicle_command_t convention: throttle and steering in [-1, 1].
// Throttle-to-speed map (assumed, linear, no deadband): throttle 1.0 -> top_speed_m_s
// (0.267 m/s, Nigel's top speed), so throttle = speed / top_speed_m_s, sign = direction.
#pragma once

#include <autodrive_vehicle.h>
#include <cmath>

#include <autodrive/autonomy/path.hpp>

namespace autodrive::autonomy {

struct TrackerConfig {
  double wheelbase_m = AUTODRIVE_VEHICLE_WHEELBASE_M;
  double max_steer_rad = AUTODRIVE_VEHICLE_STEER_LIMIT_RAD;  // steering 1.0 = this angle
  double top_speed_m_s = 0.267;                              // speed at throttle 1.0
  double cruise_speed_m_s = 0.2;
  double min_speed_m_s = 0.025;  // creep speed just before a stop
  double accel_m_s2 = 0.4, decel_m_s2 = 0.3;
  double lateral_accel_m_s2 = 0.25;  // slows in tight arcs
  double lookahead_min_m = 0.07, lookahead_time_s = 0.4;
  double stop_tolerance_m = 0.004;  // a segment ends when less than this remains
  double cusp_pause_s = 0.4;        // standstill between direction changes
  double steer_rate_rad_s = AUTODRIVE_VEHICLE_STEER_RATE_RAD_S;  // slow before curvature changes
  double steer_preview_m = 0.25;
  // Stall recovery: the throttle map is open loop, and at creep speed with the wheels on full
  // lock the drivetrain's friction can hold the car. Moving slower than stall_fraction of the
  // target for stall_s, the throttle gets a boost growing at boost_rate_per_s up to boost_max
  // (throttle units); it goes once the car moves at boost_release_fraction of the target.
  double stall_fraction = 0.3, stall_s = 0.5;
  double boost_rate_per_s = 0.3, boost_max = 0.4, boost_release_fraction = 0.8;
};

struct TrackerCommand {
  double throttle = 0.0;   // [-1, 1]
  double steering = 0.0;   // [-1, 1], + left
  double speed_m_s = 0.0;  // signed target speed
  double steer_rad = 0.0;
  bool done = false;  // the last segment has been completed: hold still
};

class PurePursuit {
 public:
  explicit PurePursuit(const TrackerConfig &cfg = TrackerConfig{}) : cfg_(cfg) {}
  void set_path(const Path &path);
  // One control step at the current base pose; dt_s since the last step. measured_speed_m_s:
  // the car's signed speed from odometry, for stall recovery (NaN: open loop only).
  TrackerCommand step(const Pose2 &pose, double dt_s, double measured_speed_m_s = std::nan(""));
  double boost() const { return boost_; }  // current stall boost [throttle units]
  bool done() const { return done_; }
  bool has_path() const { return !segments_.empty(); }
  // Index in the full path of the sample nearest to the car (for the obstacle check).
  size_t progress_index() const { return seg_offset_ + nearest_; }
  const Path &path() const { return path_; }

 private:
  void update_stall_boost(double along_m_s, double target_m_s, double dt_s);
  TrackerConfig cfg_;
  Path path_;
  std::vector<Path> segments_;                    // split at cusps
  std::vector<std::vector<double>> segments_xy_;  // their samples, x0 y0 x1 y1 ... [m]
  std::vector<size_t> offsets_;
  size_t seg_ = 0, seg_offset_ = 0, nearest_ = 0;
  double speed_m_s_ = 0.0;  // magnitude of the last commanded speed
  double last_steer_rad_ = 0.0;
  double pause_left_s_ = 0.0;
  double stalled_s_ = 0.0, boost_ = 0.0;
  bool done_ = true;
};

}  // namespace autodrive::autonomy
