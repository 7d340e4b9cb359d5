/* One 1 ms step of the world (sim.h: sim_step): lights and late boxes, then per car its host
 * link, firmware, actuation, lamps and tyres, MuJoCo's step, contacts, and the LIDAR. */
#include <stdio.h>

#include "sim_internal.h"

/* Will anyone read the accelerometer after this step? The emulated Nano samples its IMU at
 * 100 Hz (its own schedule, imu_next_us, read in the next step's nano_core_step) and the learning
 * API asks before the last step of a control period (sim_want_accel). */
static int sim_accel_due(const sim_t *s) {
  if (s->accel_wanted) return 1;
  const uint32_t next_step_us = (uint32_t)(s->time_us + SIM_STEP_US);
  for (int i = 0; i < s->ncars; i++)
    if ((int32_t)(next_step_us - s->car[i].nano.imu_next_us) >= 0) return 1;
  return 0;
}

/* MuJoCo 2.2's mj_step2 (actuation, acceleration, constraint, acceleration sensors, checks,
 * integration), except that the acceleration-stage sensors are computed only in the steps
 * whose values are read: the accelerometer's mj_rnePostConstraint is ~6 % of a step, and the
 * Nano reads it every 10th step. The values read are the ones mj_step2 would give. */
static void sim_step2(sim_t *s) {
  const mjModel *m = s->m;
  mjData *d = s->d;
  if (m->opt.integrator == mjINT_IMPLICIT) { /* its integrator is not in 2.2's public API */
    mj_step2(m, d);
    s->accel_wanted = 0;
    return;
  }
  mj_fwdActuation(m, d);
  mj_fwdAcceleration(m, d);
  mj_fwdConstraint(m, d);
  if (sim_accel_due(s)) mj_sensorAcc(m, d);
  s->accel_wanted = 0;
  mj_checkAcc(m, d);
  if (mjENABLED(mjENBL_FWDINV)) mj_compareFwdInv(m, d);
  mj_Euler(m, d); /* mj_step2 integrates RK4 models with Euler too */
}

void sim_want_accel(sim_t *s) {
  s->accel_wanted = 1;
}

int sim_step(sim_t *s, char *err, size_t err_sz) {
  if (s->tl.n > 0) { /* lights: program or command, lamps lit in the model for the cameras */
    tl_update(&s->tl, s->time_us);
    tl_draw(&s->tl, s->mv ? s->mv : s->m);
  }
  sim_place_late_boxes(s); /* before mj_step1: its kinematics, contacts and rays see them */
  mj_step1(s->m, s->d);
  const int io_due = sim_host_io_due(s);
  for (int i = 0; i < s->ncars; i++) {
    sim_car_t *c = &s->car[i];
    sim_host_turn_t turn;
    sim_host_receive(s, c, io_due, &turn);
    sim_script_feed(s, c);
    sim_nano_step(s, c);
    sim_host_send(s, c, &turn);
    sim_actuate(s, c);
    sim_draw_lamps(s, c);
    if (s->tyre_paper) sim_tyres(s, c);
  }
  sim_step2(s);
  sim_record_contacts(s);
  s->time_us += SIM_STEP_US;
  for (int i = 0; i < s->ncars; i++) {
    sim_car_t *c = &s->car[i];
    c->lidar_new = 0;
    if (!c->lidar || s->lidar_on_request) continue;
    /* mj_step2 leaves kinematics at the start of the step: fine for 1 ms ray timing */
    if (sim_lidar_update(s->m, s->d, c->lidar, s->time_us)) c->lidar_new = 1;
    if (c->rplidar) { /* stream the rays just measured, as the real device does */
      int from, to, num_rays;
      const float *ranges_m, *quality;
      sim_lidar_last_cast(c->lidar, &from, &to, &num_rays, &ranges_m, &quality);
      sim_rplidar_push_rays(c->rplidar, ranges_m, quality, from, to, num_rays);
    }
    /* free lockstep: an RPLIDAR pty nobody scans on is served at the idle period, too */
    const int lidar_io_due = c->rplidar && io_due &&
                             (s->host_io_period_steps == 1 || sim_rplidar_scanning(c->rplidar) ||
                              (s->time_us / SIM_STEP_US) % SIM_HOST_IDLE_PERIOD_MS == 0);
    if (c->rplidar && lidar_io_due && sim_rplidar_poll(c->rplidar, s->time_us, err, err_sz) != 0)
      return -1;
  }
  if (s->d->warning[mjWARN_BADQACC].number > 0) {
    snprintf(err, err_sz, "physics diverged (bad qacc) at t = %.3f s", s->time_us * 1e-6);
    return -1;
  }
  return 0;
}
