/* The firmware's outputs on the car (sim_internal.h): the servo pulse through a rate-limited
 * shaft and Ackermann linkage to the knuckles' position loop, the motor driver's duty to the
 * rear gearmotors' torque, and the brake's holding friction. */
#include "sim_internal.h"

void sim_actuate(sim_t *s, sim_car_t *c) {
  const vehicle_params_t *p = &s->p;
  mjData *d = s->d;
  mjModel *m = s->m;
  const double dt = m->opt.timestep;
  /* servo: pulse -> commanded angle -> rate-limited shaft -> Ackermann knuckle targets */
  const double target =
      steer_command_rad(c->servo_us, p->servo_center_us, p->servo_us_per_full, p->steer_limit_rad);
  c->steer_rad = steer_rate_limit(c->steer_rad, target, p->steer_rate_rad_s, dt);
  double ang[2];
  steer_ackermann(c->steer_rad, p->wheelbase_m, p->track_m, &ang[0], &ang[1]);
  for (int w = 0; w < 2; w++) {
    const double e = ang[w] - d->qpos[c->steer_qpos[w]];
    d->qfrc_applied[c->steer_dof[w]] =
        p->steer_kp_nm_rad * e - p->steer_kv_nms_rad * d->qvel[c->steer_dof[w]];
  }
  /* rear gearmotors (one driver channel) and the brake's holding friction */
  for (int w = W_RL; w <= W_RR; w++) {
    const int dof = c->wheel_dof[w];
    d->qfrc_applied[dof] =
        motor_torque_nm(&s->motor, c->duty, c->reverse, c->brake, p->battery_v, d->qvel[dof]);
    m->dof_frictionloss[dof] = p->gearbox_friction_nm + (c->brake ? p->brake_hold_torque_nm : 0.0);
  }
}
