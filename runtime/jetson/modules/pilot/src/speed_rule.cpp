#include <autodrive/pilot/speed_rule.hpp>

#include <algorithm>
#include <cmath>

namespace autodrive::pilot {

double SpeedRule::target_m_s(double steering) const {
  const double s = std::min(1.0, std::fabs(steering));
  return c_.set_speed_m_s + (c_.min_speed_m_s - c_.set_speed_m_s) * s;
}

double SpeedRule::throttle(double steering, double speed_m_s, double dt_s) {
  const double target = target_m_s(steering);
  const double err = target - speed_m_s;
  const double ff = c_.feedforward_per_m_s * target;
  const double unclamped = ff + c_.kp_per_m_s * err + c_.ki_per_m * integral_m_;
  // Anti-windup: integrate only while the output is not saturated in the error's direction.
  const bool saturated = (unclamped >= c_.max_throttle && err > 0) || (unclamped <= 0 && err < 0);
  if (dt_s > 0 && !saturated) integral_m_ += err * dt_s;
  return std::clamp(ff + c_.kp_per_m_s * err + c_.ki_per_m * integral_m_, 0.0, c_.max_throttle);
}

}  // namespace autodrive::pilot
