#include <autodrive/marl/fcfs_baseline.hpp>

#include <autodrive_vehicle.h>

#include <cmath>

namespace autodrive::marl {

FcfsBaseline::FcfsBaseline(std::string self, Route route, ConflictZone zone, FcfsParams p)
    : self_(std::move(self)), route_(std::move(route)), zone_(zone), p_(p) {
  tracker_.set_path(route_.path());
  for (const auto &q : route_.points) crosses_zone_ |= zone_.contains(q.x_m, q.y_m);
}

const char *FcfsBaseline::phase() const {
  if (left_zone_) return "cleared";
  if (committed_) return "in zone";
  if (granted_) return "granted";
  return my_request_us_ >= 0 ? "waiting" : "approaching";
}

bool FcfsBaseline::occupies(double x_m, double y_m, double yaw_rad) const {
  // base_link or the front bumper (the chassis' front, ahead of base_link) inside the zone
  const double ahead =
      AUTODRIVE_VEHICLE_CHASSIS_OFFSET_M_X + AUTODRIVE_VEHICLE_CHASSIS_SIZE_M_X / 2;
  return zone_.contains(x_m, y_m) ||
         zone_.contains(x_m + ahead * std::cos(yaw_rad), y_m + ahead * std::sin(yaw_rad));
}

double FcfsBaseline::edge_distance_m(double x_m, double y_m) const {
  return std::max(std::abs(x_m - zone_.cx_m), std::abs(y_m - zone_.cy_m)) - zone_.half_m;
}

bool FcfsBaseline::requests(double x_m, double y_m, double yaw_rad) const {
  const double towards =
      (zone_.cx_m - x_m) * std::cos(yaw_rad) + (zone_.cy_m - y_m) * std::sin(yaw_rad);
  const double d = edge_distance_m(x_m, y_m);
  return d > 0.0 && d < p_.request_m && towards > 0.0;
}

DriveCommand FcfsBaseline::step(const autodrive::autonomy::Pose2 &pose, double speed_m_s,
                                const std::vector<autodrive::v2v_state_t> &peers, int64_t now_us,
                                double dt_s) {
  DriveCommand out;
  const autodrive::autonomy::TrackerCommand tc = tracker_.step(pose, dt_s, speed_m_s);
  out.throttle = tc.throttle;
  out.steering = tc.steering;
  out.done = tc.done;
  // Peers' requests, stamped by their own V2V time: kept from the first state that requests.
  for (const auto &q : peers) {
    if (requests(q.x_m, q.y_m, q.yaw_rad))
      peer_request_us_.emplace(q.vehicle, q.utime);
    else if (!occupies(q.x_m, q.y_m, q.yaw_rad))
      peer_request_us_.erase(q.vehicle);  // through the zone, or not there yet
  }
  if (!crosses_zone_ || left_zone_) return out;
  const bool inside = occupies(pose.x_m, pose.y_m, pose.yaw_rad);
  if (committed_) {
    if (!inside && !requests(pose.x_m, pose.y_m, pose.yaw_rad) &&
        edge_distance_m(pose.x_m, pose.y_m) > 0.0)
      left_zone_ = true;
    return out;
  }
  if (inside) {  // in the zone: committed, whatever happens now
    committed_ = granted_ = true;
    return out;
  }
  if (my_request_us_ < 0) {
    if (!requests(pose.x_m, pose.y_m, pose.yaw_rad)) return out;  // still far
    my_request_us_ = now_us;
  }
  // Re-judged every step until the car is in the zone: a grant is withdrawn when a peer got
  // into the zone first (two cars that both judged themselves first: one of them stops).
  const auto bin = [&](int64_t t_us) { return static_cast<int64_t>(t_us * 1e-6 / p_.bin_s); };
  bool free = true;
  for (const auto &q : peers) {
    if (occupies(q.x_m, q.y_m, q.yaw_rad)) free = false;
    const auto it = peer_request_us_.find(q.vehicle);
    if (it == peer_request_us_.end() || granted_) continue;  // order matters before the grant
    const int64_t b = bin(it->second), mine = bin(my_request_us_);
    if (b < mine || (b == mine && q.vehicle < self_)) free = false;
  }
  granted_ = free;
  if (!free && edge_distance_m(pose.x_m, pose.y_m) < p_.hold_m) out.throttle = 0.0;  // hold short
  return out;
}

}  // namespace autodrive::marl
