#include <autodrive/marl/core_adapter.hpp>

#include <autodrive/marl_core.h>
#include <autodrive_vehicle.h>

#include <cctype>
#include <cmath>
#include <stdexcept>

namespace autodrive::marl {

namespace {
adm_car_t to_core(const CarState &c) {
  return adm_car_t{c.id, c.x_m, c.y_m, c.yaw_rad, c.speed_m_s};
}
std::vector<adm_car_t> to_core(const std::vector<CarState> &cs) {
  std::vector<adm_car_t> out;
  for (const auto &c : cs) out.push_back(to_core(c));
  return out;
}
}  // namespace

int vehicle_id(const std::string &vehicle) {
  size_t i = vehicle.size();
  while (i > 0 && std::isdigit(static_cast<unsigned char>(vehicle[i - 1]))) --i;
  return i < vehicle.size() ? std::stoi(vehicle.substr(i)) : 0;
}

int obs_version() {
  return ADM_OBS_VERSION;
}
int obs_dim() {
  return ADM_OBS_DIM;
}

Core::Core(const Route &route, double lookahead_m)
    : half_width_m_(route.half_width_m), lookahead_m_(lookahead_m) {
  for (const auto &p : route.points) {
    route_xy_m_.push_back(p.x_m);
    route_xy_m_.push_back(p.y_m);
  }
  goal_xy_m_[0] = route.points.back().x_m;
  goal_xy_m_[1] = route.points.back().y_m;
}

std::vector<float> Core::observation(const CarState &own, const std::vector<CarState> &peers,
                                     double last_steering) {
  char err[256] = "";
  double waypoint[2];
  if (adm_route_waypoint(route_xy_m_.data(), static_cast<int>(route_xy_m_.size() / 2), own.x_m,
                         own.y_m, lookahead_m_, &hint_, waypoint, &remaining_m_, err,
                         sizeof err) != 0)
    throw std::runtime_error(std::string("marl core: route waypoint: ") + err);
  std::vector<float> obs(ADM_OBS_DIM);
  const adm_car_t self = to_core(own);
  const std::vector<adm_car_t> ps = to_core(peers);
  if (adm_observation(&self, goal_xy_m_, waypoint, last_steering, ps.data(),
                      static_cast<int>(ps.size()), obs.data(), ADM_OBS_DIM, err, sizeof err) != 0)
    throw std::runtime_error(std::string("marl core: observation: ") + err);
  return obs;
}

ShieldResult Core::shield(const CarState &own, double throttle, double steering,
                          const std::vector<CarState> &peers, bool emergency_only,
                          double steering_now) const {
  adm_shield_config_t cfg;
  adm_shield_defaults(&cfg);
  if (emergency_only) cfg.horizon_s = cfg.emergency_s;
  cfg.chassis_length_m = AUTODRIVE_VEHICLE_CHASSIS_SIZE_M_X;
  cfg.chassis_width_m = AUTODRIVE_VEHICLE_CHASSIS_SIZE_M_Y;
  cfg.chassis_offset_m = AUTODRIVE_VEHICLE_CHASSIS_OFFSET_M_X;
  cfg.wheelbase_m = AUTODRIVE_VEHICLE_WHEELBASE_M;
  cfg.steer_limit_rad = AUTODRIVE_VEHICLE_STEER_LIMIT_RAD;
  cfg.top_speed_m_s = AUTODRIVE_VEHICLE_MOTOR_NOLOAD_SPEED_RAD_S * AUTODRIVE_VEHICLE_WHEEL_RADIUS_M;
  cfg.steer_rate_rad_s = AUTODRIVE_VEHICLE_STEER_RATE_RAD_S;
  cfg.pose_error_m = pose_error_m_;
  const adm_lane_t lane{route_xy_m_.data(), static_cast<int>(route_xy_m_.size() / 2), hint_,
                        half_width_m_, steering_now};
  const bool with_lane = std::isfinite(steering_now) && half_width_m_ > 0.0;
  const adm_car_t self = to_core(own);
  const std::vector<adm_car_t> ps = to_core(peers);
  const adm_command_t intended{throttle, steering};
  adm_shield_result_t r{};
  char err[256] = "";
  if (adm_shield(&cfg, &self, &intended, ps.data(), static_cast<int>(ps.size()),
                 with_lane ? &lane : nullptr, &r, err, sizeof err) != 0)
    throw std::runtime_error(std::string("marl core: shield: ") + err);
  return ShieldResult{r.command.throttle, r.command.steering, r.intervened != 0, r.peer_id, r.ttc_s,
                      r.steered != 0};
}

}  // namespace autodrive::marl
