/* The world's state for its users (sim.h): sim time, models and data, each car's ground
 * truth, firmware, outputs and sensors, and the learning API's command, scan and IMU. */
#include <math.h>
#include <string.h>

#include "sim_internal.h"

int sim_lidar_pty_scanning(const sim_t *s, int car) {
  const sim_car_t *c = &s->car[car - 1];
  return c->rplidar ? sim_rplidar_scanning(c->rplidar) : 0;
}
traffic_lights_t *sim_traffic_lights(sim_t *s) {
  return &s->tl;
}
const route_driver_t *sim_route(const sim_t *s) {
  return s->route;
}

int64_t sim_time_us(const sim_t *s) {
  return s->time_us;
}
int sim_cars(const sim_t *s) {
  return s->ncars;
}
const mjModel *sim_model(const sim_t *s) {
  return s->m;
}
mjData *sim_data(const sim_t *s) {
  return s->d;
}
mjModel *sim_render_model(const sim_t *s) {
  return s->mv ? s->mv : s->m;
}
void sim_render_snapshot(const sim_t *s, mjData *dst) {
  const mjModel *m = s->m;
  dst->time = s->d->time;
  mju_copy(dst->qpos, s->d->qpos, m->nq);
  mju_copy(dst->qvel, s->d->qvel, m->nv);
  mju_copy(dst->mocap_pos, s->d->mocap_pos, 3 * m->nmocap);
  mju_copy(dst->mocap_quat, s->d->mocap_quat, 4 * m->nmocap);
  mj_kinematics(sim_render_model(s), dst);
  mj_camlight(sim_render_model(s), dst);
}
mjData *sim_render_data(sim_t *s) {
  if (!s->mv) return s->d;
  sim_render_snapshot(s, s->dv);
  return s->dv;
}
const char *sim_lidar_link(const sim_t *s, int car) {
  return s->car[car - 1].lidar_link;
}
const nano_core_t *sim_nano(const sim_t *s, int car) {
  return &s->car[car - 1].nano;
}
void sim_motor_outputs(const sim_t *s, int car, uint8_t *duty, uint8_t *reverse, uint8_t *brake,
                       uint16_t *servo_us) {
  const sim_car_t *c = &s->car[car - 1];
  *duty = c->duty;
  *reverse = c->reverse;
  *brake = c->brake;
  *servo_us = c->servo_us;
}

const struct sim_lidar_scan *sim_lidar_new_scan(const sim_t *s, int car) {
  const sim_car_t *c = &s->car[car - 1];
  return (c->lidar && c->lidar_new) ? sim_lidar_last_scan(c->lidar) : NULL;
}

void sim_get_truth(const sim_t *s, int car, sim_truth_t *o) {
  const sim_car_t *c = &s->car[car - 1];
  const mjData *d = s->d;
  const mjtNum *qp = d->qpos + c->root_qpos, *qv = d->qvel + c->root_dof;
  memset(o, 0, sizeof *o);
  mju_copy3(o->pos_m, qp);
  mju_copy4(o->quat_wxyz, qp + 3);
  o->yaw_rad =
      atan2(2.0 * (qp[3] * qp[6] + qp[4] * qp[5]), 1.0 - 2.0 * (qp[5] * qp[5] + qp[6] * qp[6]));
  /* free joint: linear velocity of the body origin in the world, angular in the body frame */
  mjtNum R[9];
  mju_quat2Mat(R, qp + 3);
  mju_mulMatTVec(o->vel_body_m_s, R, qv, 3, 3);
  mju_copy3(o->gyro_body_rad_s, qv + 3);
  const double tl = tan(d->qpos[c->steer_qpos[0]]), tr = tan(d->qpos[c->steer_qpos[1]]);
  o->steering_rad = (fabs(tl + tr) > 1e-12) ? atan(2.0 * tl * tr / (tl + tr)) : 0.0;
  for (int w = 0; w < W_N; w++) o->wheel_speed_rad_s[w] = d->qvel[c->wheel_dof[w]];
  o->in_collision = c->in_collision;
  o->command_throttle = c->nano.cmd.throttle_milli / (double)PROTOCOL_MILLI;
  o->command_steering = c->nano.cmd.steering_milli / (double)PROTOCOL_MILLI;
  o->expert_steering = (car == 1 && s->route) ? s->route->expert_steering : NAN;
}
int sim_drive(sim_t *s, int car, double throttle, double steering) {
  if (car < 1 || car > s->ncars) return -1;
  sim_car_t *c = &s->car[car - 1];
  if (!c->has_script || !(fabs(throttle) <= 1.0) || !(fabs(steering) <= 1.0)) return -1;
  c->script.throttle = throttle;
  c->script.steering = steering;
  return 0;
}

const struct sim_lidar_scan *sim_lidar_scan_at_once(sim_t *s, int car) {
  sim_car_t *c = &s->car[car - 1];
  if (!c->lidar) return NULL;
  sim_lidar_scan_now(s->m, s->d, c->lidar, s->time_us);
  return sim_lidar_last_scan(c->lidar);
}

void sim_imu(const sim_t *s, int car, double accel_m_s2[3], double gyro_rad_s[3]) {
  const sim_car_t *c = &s->car[car - 1];
  const mjtNum *sd = s->d->sensordata;
  for (int k = 0; k < 3; k++) {
    accel_m_s2[k] = sd[c->accel_adr + k] + c->accel_bias[k];
    gyro_rad_s[k] = sd[c->gyro_adr + k] + c->gyro_bias[k];
  }
}
