// The rules of the road for one car on a Track: the speed it may drive now, and why. Pure logic
// (no I/O, no clock of its own): the program feeds the car's progress, speed and time, what the
// V2I advisory says, and the cars ahead on its track from V2V.
// - Lights: a light is GREEN only when a fresh advisory names that very light as GREEN (or
//   YELLOW, see below); with a stale advisory, or one about another light, every light is RED.
//   On RED the car stops with its front stop_margin_m before the stop line; on YELLOW it stops
//   when it can at comfort_decel_m_s2, else it goes on (decided once per light and pass). A RED
//   (or a stale advisory) that comes when even a hard stop would leave the car standing over
//   the line (a yellow the car went on, an advisory lost near the line) lets it go on (decided
//   once per light and pass): standing in the junction helps no one.
// - Stop signs: a full stop (speed below stopped_m_s) for at least stop_sign_hold_s, then on.
// - Speed limits (signs, and the advisory's when fresh), curve signs (curve_speed_m_s), and a
//   gap of at least min_gap_m behind any car ahead on the track.
// - An obstacle on the path (from the LIDAR): stop with the front obstacle_margin_m before it,
//   and go on once the path has been clear for obstacle_clear_s. No fresh scan (the LIDAR is
//   gone): the path counts as blocked right ahead.
#pragma once

#include <autodrive_vehicle.h>

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include <autodrive/behaviour/city_map.hpp>

namespace autodrive::behaviour {

struct RulesConfig {
  double cruise_m_s = 0.2;          // desired speed on a free road [m/s]
  double curve_speed_m_s = 0.14;    // after a curve sign, through the curve [m/s]
  double comfort_decel_m_s2 = 0.3;  // planned braking [m/s^2]
  // A hard stop (throttle to 0 at once): the Nano slews the throttle down at
  // ACTUATION_THROTTLE_SLEW_PER_S (from cruise to 0 in ~0.19 s, so ~0.1 s at full speed on
  // average), then the motor brakes. Stopping distance v * hard_lag_s + v^2 / (2 hard_decel_m_s2).
  double hard_lag_s = 0.1;       // [s]
  double hard_decel_m_s2 = 1.0;  // [m/s^2]
  // base_link (rear axle) to the front and to the rear bumper [m], from the car's chassis box
  double front_m = AUTODRIVE_VEHICLE_CHASSIS_OFFSET_M_X + 0.5 * AUTODRIVE_VEHICLE_CHASSIS_SIZE_M_X;
  double rear_m = 0.5 * AUTODRIVE_VEHICLE_CHASSIS_SIZE_M_X - AUTODRIVE_VEHICLE_CHASSIS_OFFSET_M_X;
  double stop_margin_m = 0.04;    // the front stops this far before the stop line [m]
  double stop_zone_m = 0.12;      // a stop counts within this of its target [m]
  double stopped_m_s = 0.01;      // below this the car is standing [m/s]
  double stop_sign_hold_s = 1.2;  // standstill at a stop sign (>= 1 s) [s]
  double min_gap_m = 0.15;        // bumper to bumper behind a car ahead [m]
  double peer_corridor_m = 0.17;  // a peer this close to the track's centre line is on it [m]
  double peer_horizon_m = 1.2;    // how far ahead peers are looked for [m]
  // the front stops this far before an obstacle [m]: more than the LIDAR's blind zone ahead of
  // the front (range_min_m 0.15 m from the LIDAR, 0.105 m from the front), so that a car
  // standing before a box still sees it go
  double obstacle_margin_m = 0.15;
  double obstacle_clear_s = 1.0;  // the path clear this long before going on after one [s]
};

enum class LightState : int8_t { off = 0, red = 1, yellow = 2, green = 3 };

struct Advisory {
  bool fresh = false;
  int light_id = -1;
  LightState light = LightState::red;
  double speed_limit_m_s = -1;  // < 0: none
};

struct RulesInput {
  double s_m = 0;  // progress along the track, unwrapped over laps [m] (base_link)
  double speed_m_s = 0;
  int64_t t_us = 0;  // the car's clock [us]
  Advisory advisory;
  std::vector<double> peers_ahead_m;  // along the track from base_link to each peer's base_link
  // LIDAR: whether a fresh scan was judged (false: the path counts as blocked), and along the
  // track from base_link to the nearest obstacle on the path (< 0: clear)
  bool scan_fresh = true;
  double obstacle_ahead_m = -1;
};

struct RulesOutput {
  double speed_m_s = 0;  // allowed speed now [m/s]
  std::string reason;    // what limits it ("cruise", "red light 3 at x_stop_s", ...)
  double stop_s_m = -1;  // the stop line the car is stopping for (unwrapped) [m], < 0 none
  // the entry of RulesInput::peers_ahead_m whose gap limits the speed ("car ahead"), -1: none
  // (what the driver charges a peer's held time to)
  int peer_index = -1;
};

class CityRules {
 public:
  CityRules(const Track &track, const RulesConfig &cfg) : track_(track), cfg_(cfg) {}
  RulesOutput step(const RulesInput &in);
  uint64_t stop_signs_served() const { return stop_signs_served_; }

 private:
  // The allowed speed to stop with the front stop_margin_m before s_line_m [m/s].
  double stop_profile(double s_line_m, double front_s_m) const;
  const Track &track_;
  RulesConfig cfg_;
  // Per stop and pass (stop index + lap * stops): yellow decided to go; red decided to go
  // (below); stop sign served;
  // standstill at the stop sign since [us].
  std::map<long, bool> yellow_go_;
  std::map<long, bool> red_go_;  // RED (or stale) came too late to stop before the line: go on
  std::map<long, int64_t> still_since_us_;
  std::map<long, bool> served_;
  uint64_t stop_signs_served_ = 0;
  int64_t obstacle_seen_us_ = -1;  // the last step an obstacle held the car [us]
};

}  // namespace autodrive::behaviour
