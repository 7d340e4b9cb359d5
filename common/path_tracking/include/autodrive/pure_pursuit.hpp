// The C++ face of the one pure pursuit (<autodrive/pure_pursuit.h>): the steering law as
// functions, and PathTracker, which owns a polyline and its progress (RAII over pp_path_t and
// pp_state_t). Header-only; link autodrive_path_tracking.
#pragma once

#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "autodrive/pure_pursuit.h"

namespace autodrive {

using PursuitVehicle = pp_vehicle_t;  // wheelbase [m], steering limit [rad]

// Nigel's steering geometry (vehicle/nigel.params).
inline PursuitVehicle default_pursuit_vehicle() {
  return pp_vehicle_default();
}

// Lookahead [m] = min_m + time_s * |speed_m_s|.
inline double pursuit_lookahead_m(double min_m, double time_s, double speed_m_s) {
  return pp_lookahead_m(min_m, time_s, speed_m_s);
}

// Steering angle [rad, + left] from the rear axle at (x, y, yaw) towards the goal (gx, gy).
inline double pursuit_steer_rad(double x_m, double y_m, double yaw_rad, double gx_m, double gy_m,
                                const PursuitVehicle &v = default_pursuit_vehicle()) {
  return pp_steer_to(x_m, y_m, yaw_rad, gx_m, gy_m, &v);
}

// A polyline followed by arc length: the goal lies lookahead [m] along the path past the car's
// projection, which is searched forward from the last one (crossings never jump).
class PathTracker {
 public:
  // xy_m: x0 y0 x1 y1 ... (copied); loop: the last point joins the first. Throws
  // std::invalid_argument for fewer than 2 points or a zero-length path.
  PathTracker(std::vector<double> xy_m, bool loop,
              const PursuitVehicle &v = default_pursuit_vehicle())
      : xy_m_(std::move(xy_m)), vehicle_(v) {
    char err[128];
    if (pp_path_init(&path_, xy_m_.data(), static_cast<int>(xy_m_.size() / 2), loop ? 1 : 0, err,
                     sizeof err) != 0)
      throw std::invalid_argument(std::string("PathTracker: ") + err);
    pp_reset(&state_, &path_, xy_m_[0], xy_m_[1]);
  }
  PathTracker(const PathTracker &) = delete;
  PathTracker &operator=(const PathTracker &) = delete;
  ~PathTracker() { pp_path_free(&path_); }

  // Starts at the path point nearest (x, y) (whole-path search).
  void reset(double x_m, double y_m) { pp_reset(&state_, &path_, x_m, y_m); }
  // Updates the progress from the rear-axle position.
  void project(double x_m, double y_m) { pp_project(&state_, &path_, x_m, y_m); }
  // Steering angle [rad, + left] towards the point lookahead_m past the projection.
  double steer_rad(double x_m, double y_m, double yaw_rad, double lookahead_m) const {
    return pp_steer(&state_, &path_, x_m, y_m, yaw_rad, lookahead_m, &vehicle_);
  }
  // The path point at arc length s_m [m].
  std::pair<double, double> point_at(double s_m) const {
    double xy[2];
    pp_point_at(&path_, s_m, xy);
    return {xy[0], xy[1]};
  }
  double s_m() const { return state_.s_m; }  // progress, unwrapped over a loop's laps [m]
  double cross_track_m() const { return state_.cross_track_m; }  // + = car left of the path
  bool done() const { return state_.done != 0; }
  double length_m() const { return path_.length_m; }
  const pp_path_t &path() const { return path_; }
  const pp_state_t &state() const { return state_; }

 private:
  std::vector<double> xy_m_;
  PursuitVehicle vehicle_;
  pp_path_t path_{};
  pp_state_t state_{};
};

}  // namespace autodrive
