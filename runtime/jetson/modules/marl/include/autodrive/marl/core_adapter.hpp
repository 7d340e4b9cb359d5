// The one place autodrive-marl calls the MARL core (autodrive_marl_core, <autodrive/marl_core.h>,
// common/marl_core/): the observation builder and the time-to-collision shield, so the
// C++ program and Python's training and batch evaluation share them. This wrapper only turns
// C++ types into the core's and fills the shield's car figures from vehicle/nigel.params.
#pragma once

#include <limits>
#include <string>
#include <vector>

#include <autodrive/marl/route_map.hpp>

namespace autodrive::marl {

struct CarState {
  int id = 0;                            // vehicle number (NIGEL<id>): the core's tie-break
  double x_m = 0, y_m = 0, yaw_rad = 0;  // base_link in the map frame [m, m, rad]
  double speed_m_s = 0;                  // [m/s], + forward
};

// "NIGEL3" -> 3 (the trailing number; 0 when there is none).
int vehicle_id(const std::string &vehicle);

int obs_version();  // ADM_OBS_VERSION
int obs_dim();      // ADM_OBS_DIM

struct ShieldResult {
  double throttle = 0, steering = 0;  // the command to send
  bool intervened = false;            // the shield braked instead of the intended command
  int peer_id = -1;                   // the peer it braked for
  double ttc_s = 0;                   // predicted time to collision with it [s]
  bool steered = false;               // the lane term replaced the steering
};

class Core {
 public:
  // route: the car's route (its end is the goal until set_goal); lookahead_m [m]: the route
  // waypoint's distance ahead, as in training.
  Core(const Route &route, double lookahead_m);
  void set_goal(double x_m, double y_m) {
    goal_xy_m_[0] = x_m;
    goal_xy_m_[1] = y_m;
  }
  // The observation of own (heading to the route's end) with these peers; throws
  // std::runtime_error with the core's message.
  std::vector<float> observation(const CarState &own, const std::vector<CarState> &peers,
                                 double last_steering);
  double remaining_m() const { return remaining_m_; }  // along the route, after observation()
  // How far each car's pose may be off [m] (the shield grows every footprint by it; 0: exact).
  void set_pose_error_m(double e) { pose_error_m_ = e; }
  // emergency_only: predict only the core's emergency horizon, so the shield brakes for an
  // imminent contact but does not arbitrate right of way (the baseline has its own rule).
  // steering_now: the wheels' steering now (normalised; the last command where the angle is not
  // measured): with it, the core's lane term keeps the chassis on the route's lane (the route
  // point nearest as found by the last observation()); NaN: no lane term.
  ShieldResult shield(const CarState &own, double throttle, double steering,
                      const std::vector<CarState> &peers, bool emergency_only = false,
                      double steering_now = std::numeric_limits<double>::quiet_NaN()) const;

 private:
  std::vector<double> route_xy_m_;
  double half_width_m_ = 0;
  double pose_error_m_ = 0;
  double goal_xy_m_[2] = {0, 0};
  double lookahead_m_;
  int hint_ = -1;
  double remaining_m_ = 0;
};

}  // namespace autodrive::marl
