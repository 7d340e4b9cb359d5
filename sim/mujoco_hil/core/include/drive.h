/* Drive train and steering models between the firmware's actuator outputs and MuJoCo. */
#ifndef SIM_DRIVE_H
#define SIM_DRIVE_H

#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/* DC gearmotor, figures at the wheel: tau = stall * (u - w / w_noload), u = +-duty/255 * Vbat
 * / Vnominal (back-EMF makes the torque fall linearly with speed). Braking shorts the motor:
 * u = 0, so the back-EMF alone brakes (tau = -stall * w / w_noload). */
typedef struct motor_model {
  double stall_torque_nm, noload_speed_rad_s, nominal_v;
} motor_model_t;

double motor_torque_nm(const motor_model_t *m, uint8_t duty, uint8_t reverse, uint8_t brake,
                       double battery_v, double wheel_speed_rad_s);

/* Servo: pulse [us] -> commanded centre angle [rad, + left], clamped to the limit. */
double steer_command_rad(double pulse_us, double center_us, double us_per_full, double limit_rad);
/* Moves angle towards target by at most rate * dt. */
double steer_rate_limit(double angle_rad, double target_rad, double rate_rad_s, double dt_s);
/* Ackermann per-wheel angles from the centre angle (paper): tan d_l,r = 2 L tan d /
 * (2 L -+ T tan d). */
void steer_ackermann(double delta_rad, double wheelbase_m, double track_m, double *left_rad,
                     double *right_rad);

#ifdef __cplusplus
}
#endif
#endif
