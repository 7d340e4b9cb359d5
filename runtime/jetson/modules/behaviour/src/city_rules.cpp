#include <autodrive/behaviour/city_rules.hpp>

#include <algorithm>
#include <cmath>

namespace autodrive::behaviour {

double CityRules::stop_profile(double s_line_m, double front_s_m) const {
  const double room_m = s_line_m - cfg_.stop_margin_m - front_s_m;
  if (room_m <= 0.003) return 0.0;
  return std::sqrt(2.0 * cfg_.comfort_decel_m_s2 * room_m);
}

RulesOutput CityRules::step(const RulesInput &in) {
  RulesOutput out{cfg_.cruise_m_s, "cruise", -1};
  // true when v is the new limit (any later limit takes the blame off a peer)
  auto limit = [&](double v, const std::string &why) {
    if (v >= out.speed_m_s) return false;
    out.speed_m_s = std::max(0.0, v), out.reason = why, out.peer_index = -1;
    return true;
  };
  const double L = track_.length_m;
  const double front = in.s_m + cfg_.front_m;
  const long lap = track_.loop ? static_cast<long>(std::floor(in.s_m / L)) : 0;
  const long nstops = static_cast<long>(track_.stops.size());
  // Stops ahead on this lap and the next (a loop), nearest first.
  for (long k = 0; k < (track_.loop ? 2 : 1) * nstops; ++k) {
    const Stop &st = track_.stops[static_cast<size_t>(k % nstops)];
    const long pass = lap + k / nstops;
    const double s_line = st.s_m + (track_.loop ? pass * L : 0.0);
    const long key = static_cast<long>(k % nstops) + pass * nstops;
    if (s_line - front < -cfg_.stop_margin_m) continue;  // the front is past it: behind us
    if (s_line - front > 3.0) break;                     // far ahead: later
    if (st.kind == Stop::Kind::light) {
      LightState ls = LightState::red;  // stale, or about another light: red
      if (in.advisory.fresh && in.advisory.light_id == st.light_id) ls = in.advisory.light;
      const std::string what = "light " + std::to_string(st.light_id) + " at " + st.name;
      if (ls == LightState::green) {
        yellow_go_.erase(key);
        red_go_.erase(key);
        continue;
      }
      if (ls == LightState::yellow) {
        red_go_.erase(key);
        auto it = yellow_go_.find(key);
        if (it == yellow_go_.end()) {
          // Go on only when stopping before the line would need more than comfort braking.
          const double need_m = in.speed_m_s * in.speed_m_s / (2.0 * cfg_.comfort_decel_m_s2);
          it = yellow_go_.emplace(key, need_m > s_line - cfg_.stop_margin_m - front).first;
        }
        if (it->second) continue;
        limit(stop_profile(s_line, front), "yellow " + what);
      } else {
        yellow_go_.erase(key);
        auto it = red_go_.find(key);
        if (it == red_go_.end()) {
          // Go on only when even a hard stop would leave the front over the line.
          const double v = std::max(0.0, in.speed_m_s);
          const double hard_m = v * cfg_.hard_lag_s + v * v / (2.0 * cfg_.hard_decel_m_s2);
          it = red_go_.emplace(key, hard_m > s_line - front).first;
        }
        if (it->second) continue;
        limit(stop_profile(s_line, front),
              (in.advisory.fresh ? "red " : "stale advisory: red ") + what);
      }
      if (out.stop_s_m < 0) out.stop_s_m = s_line;
      break;  // the nearest stop that holds the car decides
    }
    // Stop sign.
    if (served_[key]) continue;
    const bool at_line = s_line - cfg_.stop_margin_m - front < cfg_.stop_zone_m;
    if (at_line && in.speed_m_s < cfg_.stopped_m_s) {
      auto it = still_since_us_.emplace(key, in.t_us).first;
      if ((in.t_us - it->second) * 1e-6 >= cfg_.stop_sign_hold_s) {
        served_[key] = true;
        ++stop_signs_served_;
        continue;
      }
    } else {
      still_since_us_.erase(key);
    }
    limit(stop_profile(s_line, front), "stop sign at " + st.name);
    out.stop_s_m = s_line;
    break;
  }
  // Speed zones (speed-limit and curve signs) the car is in or about to enter.
  for (const SpeedZone &z : track_.zones) {
    const double v_zone = z.limit_m_s < 0 ? cfg_.curve_speed_m_s : z.limit_m_s;
    for (long pass = lap - 1; pass <= lap + 1; ++pass) {
      const double off = track_.loop ? pass * L : 0.0;
      const double s0 = z.s0_m + off, s1 = z.s1_m + off;
      if (front > s1 || in.s_m > s1) continue;
      const double to_zone_m = std::max(0.0, s0 - front);
      if (to_zone_m > 1.0) continue;
      // Brake into the zone so the front enters it at the zone's speed.
      limit(std::sqrt(v_zone * v_zone + 2.0 * cfg_.comfort_decel_m_s2 * to_zone_m), z.why);
    }
  }
  if (in.advisory.fresh && in.advisory.speed_limit_m_s > 0)
    limit(in.advisory.speed_limit_m_s, "advisory speed limit");
  // Cars ahead on the track: keep min_gap_m bumper to bumper, braking comfortably.
  for (size_t k = 0; k < in.peers_ahead_m.size(); ++k) {
    const double gap_m = in.peers_ahead_m[k] - cfg_.rear_m - cfg_.front_m;
    const double room_m = gap_m - cfg_.min_gap_m;
    if (limit(room_m <= 0.003 ? 0.0 : std::sqrt(2.0 * cfg_.comfort_decel_m_s2 * room_m),
              "car ahead"))
      out.peer_index = static_cast<int>(k);
  }
  // An obstacle on the path (LIDAR): brake to stand obstacle_margin_m before it; once it held
  // the car, the path must stay clear for obstacle_clear_s before the car goes on.
  if (!in.scan_fresh) {
    limit(0.0, "no fresh LIDAR scan");
  } else if (in.obstacle_ahead_m >= 0) {
    const double room_m = in.obstacle_ahead_m - cfg_.front_m - cfg_.obstacle_margin_m;
    const double v = room_m <= 0.003 ? 0.0 : std::sqrt(2.0 * cfg_.comfort_decel_m_s2 * room_m);
    if (v == 0.0) obstacle_seen_us_ = in.t_us;
    limit(v, "obstacle ahead (LIDAR)");
  } else if (obstacle_seen_us_ >= 0 &&
             (in.t_us - obstacle_seen_us_) * 1e-6 < cfg_.obstacle_clear_s) {
    limit(0.0, "obstacle gone, waiting");
  }
  return out;
}

}  // namespace autodrive::behaviour
