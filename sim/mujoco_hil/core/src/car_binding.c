/* A car's parts in the generated model (sim_internal.h): the addresses of its bodies, joints,
 * geoms and IMU sensors, found by name ("nigel<i>/<part>", mjcf_gen.c writes them). */
#include <stdio.h>

#include "sim_internal.h"

static int sim_id(const mjModel *m, int type, int car, const char *part, char *err, size_t err_sz) {
  char name[64];
  snprintf(name, sizeof name, "nigel%d/%s", car, part);
  const int id = mj_name2id(m, type, name);
  if (id < 0) snprintf(err, err_sz, "generated model lacks '%s'", name);
  return id;
}

int sim_bind_car(sim_t *s, sim_car_t *c, char *err, size_t err_sz) {
  const mjModel *m = s->m;
  static const char *wn[W_N] = {"fl", "fr", "rl", "rr"};
  char part[32];
  if ((c->body = sim_id(m, mjOBJ_BODY, c->index, "base_link", err, err_sz)) < 0) return -1;
  int j = sim_id(m, mjOBJ_JOINT, c->index, "root", err, err_sz);
  if (j < 0) return -1;
  c->root_qpos = m->jnt_qposadr[j];
  c->root_dof = m->jnt_dofadr[j];
  if ((c->chassis_geom = sim_id(m, mjOBJ_GEOM, c->index, "chassis", err, err_sz)) < 0) return -1;
  for (int w = 0; w < W_N; w++) {
    snprintf(part, sizeof part, "wheel_%s", wn[w]);
    if ((c->wheel_body[w] = sim_id(m, mjOBJ_BODY, c->index, part, err, err_sz)) < 0) return -1;
    if ((j = sim_id(m, mjOBJ_JOINT, c->index, part, err, err_sz)) < 0) return -1;
    c->wheel_qpos[w] = m->jnt_qposadr[j];
    c->wheel_dof[w] = m->jnt_dofadr[j];
    snprintf(part, sizeof part, "tyre_%s", wn[w]);
    if ((c->tyre_geom[w] = sim_id(m, mjOBJ_GEOM, c->index, part, err, err_sz)) < 0) return -1;
    s->geom_tyre[c->tyre_geom[w]] = (c->index - 1) * W_N + w;
  }
  for (int w = 0; w < 2; w++) {
    snprintf(part, sizeof part, "steer_%s", wn[w]);
    if ((j = sim_id(m, mjOBJ_JOINT, c->index, part, err, err_sz)) < 0) return -1;
    c->steer_qpos[w] = m->jnt_qposadr[j];
    c->steer_dof[w] = m->jnt_dofadr[j];
  }
  sim_bind_lamps(s, c);
  static const char *sn[3] = {"accel", "gyro", "mag"};
  int *adr[3] = {&c->accel_adr, &c->gyro_adr, &c->mag_adr};
  for (int k = 0; k < 3; k++) {
    const int id = sim_id(m, mjOBJ_SENSOR, c->index, sn[k], err, err_sz);
    if (id < 0) return -1;
    *adr[k] = m->sensor_adr[id];
  }
  return 0;
}
