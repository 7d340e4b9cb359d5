/* Motor and steering models (see drive.h). */
#include "drive.h"

#include <math.h>

double motor_torque_nm(const motor_model_t *m, uint8_t duty, uint8_t reverse, uint8_t brake,
                       double battery_v, double wheel_speed_rad_s) {
  double u = 0.0;
  if (!brake) u = (reverse ? -1.0 : 1.0) * (duty / 255.0) * battery_v / m->nominal_v;
  return m->stall_torque_nm * (u - wheel_speed_rad_s / m->noload_speed_rad_s);
}

double steer_command_rad(double pulse_us, double center_us, double us_per_full, double limit_rad) {
  double a = (pulse_us - center_us) / us_per_full * limit_rad;
  if (a > limit_rad) a = limit_rad;
  if (a < -limit_rad) a = -limit_rad;
  return a;
}

double steer_rate_limit(double angle_rad, double target_rad, double rate_rad_s, double dt_s) {
  const double step = rate_rad_s * dt_s;
  const double d = target_rad - angle_rad;
  if (d > step) return angle_rad + step;
  if (d < -step) return angle_rad - step;
  return target_rad;
}

void steer_ackermann(double delta_rad, double wheelbase_m, double track_m, double *left_rad,
                     double *right_rad) {
  const double t = tan(delta_rad);
  *left_rad = atan2(2.0 * wheelbase_m * t, 2.0 * wheelbase_m - track_m * t);
  *right_rad = atan2(2.0 * wheelbase_m * t, 2.0 * wheelbase_m + track_m * t);
}
