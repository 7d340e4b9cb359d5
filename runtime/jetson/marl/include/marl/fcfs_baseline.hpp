// The rule-based baseline: first come, first served on the intersection's conflict zone with
// the peers' V2V states and intents. A car drives its route by pure pursuit; within
// request_m [m] of the zone it asks for it; it is granted when no peer is inside the zone and
// no peer that asked earlier (by this car's clock; ties within tie_s [s] go to the lower
// vehicle name) is still waiting; until then it stops short of the zone. Once inside it is
// committed. A peer counts as waiting while it is outside the zone, within request_m of it and
// heading towards it; a peer whose V2V intent is a route it has finished (heading away) never
// blocks.
#pragma once

#include <autodrive/v2v_state_t.hpp>
#include <autonomy/pure_pursuit.hpp>

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "marl/route_map.hpp"

namespace marl {

struct FcfsParams {
  double request_m = 0.45;  // ask for the zone this far before its edge [m]
  double stop_m = 0.08;     // stop this far before the edge while not granted [m]
  double tie_s = 0.2;       // requests closer in time than this are ties [s]
};

struct DriveCommand {
  double throttle = 0, steering = 0;  // [-1, 1]
  bool done = false;                  // at the end of the route
};

class FcfsBaseline {
 public:
  FcfsBaseline(std::string self, Route route, ConflictZone zone, FcfsParams p = FcfsParams{});
  DriveCommand step(const autonomy::Pose2 &pose, double speed_m_s,
                    const std::vector<autodrive::v2v_state_t> &peers, int64_t now_us, double dt_s);
  bool granted() const { return granted_; }
  const char *phase() const;

 private:
  double distance_to_zone_m(const autonomy::Pose2 &pose) const;  // along the route, 0 inside
  bool peer_waiting(const autodrive::v2v_state_t &q) const;

  std::string self_;
  Route route_;
  ConflictZone zone_;
  FcfsParams p_;
  autonomy::PurePursuit tracker_;
  double zone_entry_s_m_ = 0, zone_exit_s_m_ = 0;
  int64_t my_request_us_ = -1;
  bool granted_ = false, left_zone_ = false;
  std::map<std::string, int64_t> peer_request_us_;
};

}  // namespace marl
