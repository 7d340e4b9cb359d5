// Throttle of autodrive-pilot: hold a set speed, slower for large steering. The network only
// steers; this rule turns the steering and the measured speed into a throttle.
#pragma once

namespace autodrive::pilot {

struct SpeedRuleConfig {
  double set_speed_m_s = 0.2;        // on a straight
  double min_speed_m_s = 0.1;        // at full steering
  double feedforward_per_m_s = 3.5;  // throttle per m/s of target speed
  double kp_per_m_s = 3.0;           // throttle per m/s of speed error
  double ki_per_m = 2.0;             // throttle per m of integrated speed error
  double max_throttle = 1.0;         // never more
};

class SpeedRule {
 public:
  explicit SpeedRule(const SpeedRuleConfig &c) : c_(c) {}
  // The target speed [m/s] at normalised steering s in [-1, 1]: set speed at 0, min speed at
  // |s| = 1, linear between.
  double target_m_s(double steering) const;
  // The throttle in [0, max_throttle] for this steering and measured speed; dt_s is the time
  // since the previous call (0: no integration).
  double throttle(double steering, double speed_m_s, double dt_s);
  void reset() { integral_m_ = 0.0; }

 private:
  SpeedRuleConfig c_;
  double integral_m_ = 0.0;
};

}  // namespace autodrive::pilot
