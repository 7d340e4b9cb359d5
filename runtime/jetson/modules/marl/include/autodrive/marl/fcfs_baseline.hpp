// The rule-based baseline: first come, first served on the intersection's conflict zone with
// the peers' V2V states. A car drives its route by pure pursuit. It requests the zone when its
// base_link comes within request_m [m] of the zone's edge, outside it and heading towards its
// centre; every car judges itself and its peers by that same rule, with the request time from
// the sender's V2V stamp (its own clock for itself: SIM_CLOCK in HIL, the same for all). The
// order is (request time in bins of bin_s [s], vehicle name): a total order that a later-seen
// peer can only move back, so two cars never both wait for each other. A car is granted the
// zone when nobody is in it and no peer ahead in that order still requests it; until then it
// holds short of the zone. The grant is re-judged until the car is in the zone (a peer that got
// in first withdraws it); in the zone the car is committed.
#pragma once

#include <autodrive/v2v_state_t.hpp>
#include <autodrive/autonomy/pure_pursuit.hpp>

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include <autodrive/marl/route_map.hpp>

namespace autodrive::marl {

struct FcfsParams {
  double request_m = 0.60;  // base_link this far from the zone's edge requests it [m]
  // While not granted, stop with base_link this far from the zone's edge [m]: with the
  // default zone (the 4-way's roads + 0.1 m) the front bumper stays behind the stop line.
  double hold_m = 0.45;
  double bin_s = 0.25;  // request times in the same bin are ordered by name [s]
};

struct DriveCommand {
  double throttle = 0, steering = 0;  // [-1, 1]
  bool done = false;                  // at the end of the route
};

class FcfsBaseline {
 public:
  FcfsBaseline(std::string self, Route route, ConflictZone zone, FcfsParams p = FcfsParams{});
  DriveCommand step(const autodrive::autonomy::Pose2 &pose, double speed_m_s,
                    const std::vector<autodrive::v2v_state_t> &peers, int64_t now_us, double dt_s);
  bool granted() const { return granted_; }
  const char *phase() const;

 private:
  // Distance of base_link from the zone's edge [m] (<= 0 inside), and whether a car there,
  // heading yaw_rad, requests the zone.
  double edge_distance_m(double x_m, double y_m) const;
  bool requests(double x_m, double y_m, double yaw_rad) const;
  // base_link or the front bumper of a car there is in the zone
  bool occupies(double x_m, double y_m, double yaw_rad) const;

  std::string self_;
  Route route_;
  ConflictZone zone_;
  FcfsParams p_;
  autodrive::autonomy::PurePursuit tracker_;
  bool crosses_zone_ = false;
  int64_t my_request_us_ = -1;
  bool granted_ = false, committed_ = false, left_zone_ = false;
  std::map<std::string, int64_t> peer_request_us_;
};

}  // namespace autodrive::marl
