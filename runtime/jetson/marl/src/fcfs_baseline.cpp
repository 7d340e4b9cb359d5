#include "marl/fcfs_baseline.hpp"

#include <cmath>

namespace marl {

FcfsBaseline::FcfsBaseline(std::string self, Route route, ConflictZone zone, FcfsParams p)
    : self_(std::move(self)), route_(std::move(route)), zone_(zone), p_(p) {
  tracker_.set_path(route_.path());
  zone_entry_s_m_ = zone_exit_s_m_ = -1;
  for (size_t i = 0; i < route_.points.size(); ++i) {
    if (!zone_.contains(route_.points[i].x_m, route_.points[i].y_m)) continue;
    if (zone_entry_s_m_ < 0) zone_entry_s_m_ = route_.s_m[i];
    zone_exit_s_m_ = route_.s_m[i];
  }
}

const char *FcfsBaseline::phase() const {
  if (left_zone_) return "cleared";
  if (granted_) return "granted";
  return my_request_us_ >= 0 ? "waiting" : "approaching";
}

double FcfsBaseline::distance_to_zone_m(const autonomy::Pose2 &pose) const {
  if (zone_entry_s_m_ < 0) return 1e9;  // the route never crosses the zone
  // The chassis front reaches the zone first: measure from the front bumper.
  const double s = route_.s_m[route_.nearest(pose.x_m, pose.y_m)] + 0.19;
  return zone_entry_s_m_ - s;
}

bool FcfsBaseline::peer_waiting(const autodrive::v2v_state_t &q) const {
  if (zone_.contains(q.x_m, q.y_m)) return false;
  const double dx = zone_.cx_m - q.x_m, dy = zone_.cy_m - q.y_m;
  const double towards = dx * std::cos(q.yaw_rad) + dy * std::sin(q.yaw_rad);
  const double edge = std::max(std::abs(dx), std::abs(dy)) - zone_.half_m;
  return towards > 0.0 && edge < p_.request_m + 0.19;
}

DriveCommand FcfsBaseline::step(const autonomy::Pose2 &pose, double speed_m_s,
                                const std::vector<autodrive::v2v_state_t> &peers, int64_t now_us,
                                double dt_s) {
  DriveCommand out;
  const autonomy::TrackerCommand tc = tracker_.step(pose, dt_s, speed_m_s);
  out.throttle = tc.throttle;
  out.steering = tc.steering;
  out.done = tc.done;
  // Peers' requests, by this car's clock: the first time each is seen waiting.
  for (const auto &q : peers) {
    if (peer_waiting(q)) {
      peer_request_us_.emplace(q.vehicle, now_us);
    } else if (!zone_.contains(q.x_m, q.y_m)) {
      peer_request_us_.erase(q.vehicle);  // gone through, or not there yet
    }
  }
  const double d = distance_to_zone_m(pose);
  const bool inside = zone_.contains(pose.x_m, pose.y_m);
  if (granted_ && !inside && d < 0) left_zone_ = true;
  if (granted_ || left_zone_ || d > p_.request_m) return out;
  if (my_request_us_ < 0) my_request_us_ = now_us;
  bool free = true;
  for (const auto &q : peers) {
    if (zone_.contains(q.x_m, q.y_m)) free = false;
    auto it = peer_request_us_.find(q.vehicle);
    if (it == peer_request_us_.end()) continue;
    const double earlier_s = (my_request_us_ - it->second) * 1e-6;
    if (earlier_s > p_.tie_s || (std::abs(earlier_s) <= p_.tie_s && q.vehicle < self_))
      free = false;
  }
  if (free) {
    granted_ = true;
    return out;
  }
  if (d < p_.stop_m + 0.05) out.throttle = 0.0;  // hold short of the zone
  return out;
}

}  // namespace marl
