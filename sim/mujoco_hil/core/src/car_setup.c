/* A car's power-on (sim_internal.h): its firmware, HAL, UARTs, noise, scripted driver and
 * LIDAR at boot (sim_create and sim_reset), and the ptys it opens once (sim_create). */
#include <stdio.h>
#include <string.h>

#include "sim_internal.h"

/* A car at power-on: actuators idle, UARTs empty, the firmware freshly booted, its noise and
 * biases drawn from (seed, car), its scripted driver at its first frame, its LIDAR head (with
 * its own noise seed) at the start of a revolution. sim_create and sim_reset share it. */
int sim_car_boot(sim_t *s, sim_car_t *c, char *err, size_t err_sz) {
  memset(c->fz_n, 0, sizeof c->fz_n);
  memset(c->mu, 0, sizeof c->mu);
  memset(c->normal, 0, sizeof c->normal);
  memset(c->contact_pos, 0, sizeof c->contact_pos);
  c->in_collision = 0;
  c->duty = c->reverse = c->lamps = 0;
  c->brake = 1;
  c->servo_us = 1500;
  c->steer_rad = 0.0;
  c->lamps_shown = 0xFF; /* draw on the first step */
  c->tx_pending_n = 0;
  c->host_idle = 0;
  c->lidar_new = 0;
  uart_init(&c->rx, PROTOCOL_BAUD);
  uart_init(&c->tx, PROTOCOL_BAUD);
  /* every car draws its own biases and noise from (seed, car) */
  rng_seed(&c->rng, s->seed * 1000003ull + (uint64_t)c->index);
  for (int k = 0; k < 3; k++) {
    c->accel_bias[k] = (2.0 * rng_uniform(&c->rng) - 1.0) * s->p.accel_bias_m_s2;
    c->gyro_bias[k] = (2.0 * rng_uniform(&c->rng) - 1.0) * s->p.gyro_bias_rad_s;
  }
  if (s->script_spec[0]) {
    if (script_parse(&c->script, s->script_spec, err, err_sz) != 0) return -1;
    c->has_script = 1;
  }
  if (s->lidar) {
    sim_lidar_config_t lc;
    sim_lidar_config_default(&lc);
    mju_copy3(lc.mount_pos_m, s->p.lidar_pos_m);
    lc.seed = s->seed * 7919ull + (uint64_t)c->index;
    if (s->lidar_rays > 0) lc.num_rays = s->lidar_rays;
    char body[32];
    snprintf(body, sizeof body, "nigel%d/base_link", c->index);
    sim_lidar_destroy(c->lidar);
    c->lidar = sim_lidar_create(s->m, body, &lc, err, err_sz);
    if (!c->lidar) return -1;
  }
  nano_core_init(&c->nano, &c->hal, 0, 0, SIM_BUILD_ID);
  return 0;
}

int sim_setup_car(sim_t *s, const sim_config_t *cfg, sim_car_t *c, char *err, size_t err_sz) {
  c->sim = s;
  sim_hal_bind(c);
  if (cfg->open_ptys) {
    char link[512];
    snprintf(link, sizeof link, "%s/nigel%d-nano", cfg->run_dir, c->index);
    if (ptylink_open(&c->pty, link, err, err_sz) != 0) return -1;
    c->has_pty = 1;
    c->host_rx_us = -1;
    protocol_parser_init(&c->host_parser);
  }
  if (sim_car_boot(s, c, err, err_sz) != 0) return -1;
  if (cfg->lidar && cfg->open_ptys) {
    snprintf(c->lidar_link, sizeof c->lidar_link, "%s/nigel%d-lidar", cfg->run_dir, c->index);
    c->rplidar = sim_rplidar_create(c->lidar_link, SIM_RPLIDAR_BAUD, err, err_sz);
    if (!c->rplidar) return -1;
  }
  return 0;
}
