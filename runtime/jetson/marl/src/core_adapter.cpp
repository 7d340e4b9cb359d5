// INTERIM implementation of the MARL core's observation and shield (see core_adapter.hpp).
#include "marl/core_adapter.hpp"

#include <autodrive_vehicle.h>

#include <algorithm>
#include <cmath>

namespace marl {

const char *obs_layout_name() {
  return "interim-0";
}

double top_speed_m_s() {
  return AUTODRIVE_VEHICLE_MOTOR_NOLOAD_SPEED_RAD_S * AUTODRIVE_VEHICLE_WHEEL_RADIUS_M;
}

namespace {
// v (map frame) in the frame of a car at yaw [rad]
void to_own_frame(const CarState &own, double x_m, double y_m, double *fx, double *fy) {
  const double dx = x_m - own.x_m, dy = y_m - own.y_m;
  const double c = std::cos(own.yaw_rad), s = std::sin(own.yaw_rad);
  *fx = c * dx + s * dy;
  *fy = -s * dx + c * dy;
}
}  // namespace

std::vector<float> build_observation(const CarState &own, const Goal &goal,
                                     const std::vector<CarState> &peers) {
  std::vector<float> o(kObsDim, 0.0f);
  double gx, gy;
  to_own_frame(own, goal.x_m, goal.y_m, &gx, &gy);
  o[0] = static_cast<float>(gx / kGoalScaleM);
  o[1] = static_cast<float>(gy / kGoalScaleM);
  o[2] = static_cast<float>(own.speed_m_s / top_speed_m_s());
  std::vector<CarState> sorted = peers;
  std::sort(sorted.begin(), sorted.end(), [&](const CarState &a, const CarState &b) {
    return std::hypot(a.x_m - own.x_m, a.y_m - own.y_m) <
           std::hypot(b.x_m - own.x_m, b.y_m - own.y_m);
  });
  for (int k = 0; k < kPeerSlots && k < static_cast<int>(sorted.size()); ++k) {
    const CarState &q = sorted[static_cast<size_t>(k)];
    double px, py;
    to_own_frame(own, q.x_m, q.y_m, &px, &py);
    float *slot = o.data() + 3 + 6 * k;
    slot[0] = static_cast<float>(px / kPeerScaleM);
    slot[1] = static_cast<float>(py / kPeerScaleM);
    slot[2] = static_cast<float>(std::sin(q.yaw_rad - own.yaw_rad));
    slot[3] = static_cast<float>(std::cos(q.yaw_rad - own.yaw_rad));
    slot[4] = static_cast<float>(q.speed_m_s / top_speed_m_s());
    slot[5] = 1.0f;
  }
  return o;
}

ShieldResult shield(const CarState &own, double throttle, double steering,
                    const std::vector<CarState> &peers, const ShieldParams &p) {
  ShieldResult r;
  r.throttle = throttle;
  r.steering = steering;
  const double v_own = std::max(0.0, throttle) * top_speed_m_s();
  const double yaw_rate =
      v_own * std::tan(steering * AUTODRIVE_VEHICLE_STEER_LIMIT_RAD) / AUTODRIVE_VEHICLE_WHEELBASE_M;
  // Chassis centres (the poses are of base_link, the rear-axle centre).
  const double off = AUTODRIVE_VEHICLE_CHASSIS_OFFSET_M_X;
  double x = own.x_m, y = own.y_m, yaw = own.yaw_rad;
  for (double t = 0.0; t <= p.horizon_s && r.ttc_s > 1e8; t += p.step_s) {
    const double cx = x + off * std::cos(yaw), cy = y + off * std::sin(yaw);
    for (const CarState &q : peers) {
      const double qx = q.x_m + (q.speed_m_s * t + off) * std::cos(q.yaw_rad);
      const double qy = q.y_m + (q.speed_m_s * t + off) * std::sin(q.yaw_rad);
      if (std::hypot(qx - cx, qy - cy) < p.contact_m) {
        r.ttc_s = t;
        break;
      }
    }
    x += v_own * std::cos(yaw) * p.step_s;
    y += v_own * std::sin(yaw) * p.step_s;
    yaw += yaw_rate * p.step_s;
  }
  // Brake when moving on would meet a peer within min_ttc_s and standing still does not meet
  // it sooner (a contact from behind is the other car's to avoid).
  if (r.ttc_s <= p.min_ttc_s && v_own > 0.0) {
    const ShieldResult still = shield(own, 0.0, steering, peers, p);
    if (still.ttc_s >= r.ttc_s) {
      r.throttle = 0.0;
      r.intervened = true;
    }
  }
  return r;
}

}  // namespace marl
