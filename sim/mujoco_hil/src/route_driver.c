/* Route driver (see route_driver.h). */
#include "route_driver.h"

#include <autodrive_vehicle.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

void route_driver_list(const mjModel *m, char *out, size_t out_sz) {
  size_t len = 0;
  out[0] = '\0';
  for (int i = 0; i < m->nnumeric; i++) {
    const char *name = m->names + m->name_numericadr[i];
    if (strncmp(name, "route_", 6) != 0 || strstr(name, ".part")) continue;
    const int w = snprintf(out + len, out_sz - len, "%s%s", len ? ", " : "", name + 6);
    if (w < 0 || (size_t)w >= out_sz - len) break;
    len += (size_t)w;
  }
  if (!len) snprintf(out, out_sz, "none");
}

int route_driver_init(route_driver_t *r, const mjModel *m, const char *name, double speed,
                      double lookahead_m, char *err, size_t err_sz) {
  memset(r, 0, sizeof *r);
  char key[96], routes[1024];
  snprintf(key, sizeof key, "route_%s", name);
  const int id = mj_name2id(m, mjOBJ_NUMERIC, key);
  if (id < 0) {
    route_driver_list(m, routes, sizeof routes);
    snprintf(err, err_sz, "--script route:%s: the map has no numeric '%s' (routes: %s)", name, key,
             routes);
    return -1;
  }
  const int sz = m->numeric_size[id];
  const mjtNum *v = m->numeric_data + m->numeric_adr[id];
  if (sz < 6 || sz % 2 != 0 || !(v[1] > 0) || (v[0] != 0 && v[0] != 1)) {
    snprintf(err, err_sz,
             "--script route:%s: numeric '%s' must be 'loop half_width_m x0 y0 x1 y1 ...' with "
             "loop 0/1, half width > 0 and >= 2 points (%d values)",
             name, key, sz);
    return -1;
  }
  snprintf(r->name, sizeof r->name, "%s", name);
  r->half_width_m = v[1];
  /* a long route continues in route_<r>.part1, .part2, ... (MuJoCo's 500-value limit) */
  int values = sz - 2, parts = 0;
  for (;; parts++) {
    char part[128];
    snprintf(part, sizeof part, "%s.part%d", key, parts + 1);
    const int pid = mj_name2id(m, mjOBJ_NUMERIC, part);
    if (pid < 0) break;
    if (m->numeric_size[pid] % 2 != 0) {
      snprintf(err, err_sz, "--script route:%s: numeric '%s' holds an odd number of values", name,
               part);
      return -1;
    }
    values += m->numeric_size[pid];
  }
  const int n = values / 2;
  r->xy_m = malloc(sizeof(double) * (size_t)values);
  if (!r->xy_m) {
    snprintf(err, err_sz, "out of memory");
    return -1;
  }
  int at = 0;
  for (int k = 2; k < sz; k++) r->xy_m[at++] = v[k];
  for (int p = 1; p <= parts; p++) {
    char part[128];
    snprintf(part, sizeof part, "%s.part%d", key, p);
    const int pid = mj_name2id(m, mjOBJ_NUMERIC, part);
    for (int k = 0; k < m->numeric_size[pid]; k++)
      r->xy_m[at++] = m->numeric_data[m->numeric_adr[pid] + k];
  }
  char perr[256];
  if (pp_path_init(&r->path, r->xy_m, n, v[0] != 0, perr, sizeof perr) != 0) {
    snprintf(err, err_sz, "--script route:%s: %s", name, perr);
    route_driver_free(r);
    return -1;
  }
  r->speed = speed;
  r->lookahead_m = lookahead_m;
  pp_reset(&r->st, &r->path, r->xy_m[0], r->xy_m[1]);
  return 0;
}

void route_driver_free(route_driver_t *r) {
  pp_path_free(&r->path);
  free(r->xy_m);
  r->xy_m = NULL;
}

void route_driver_start(const route_driver_t *r, double *x_m, double *y_m, double *yaw_rad) {
  *x_m = r->xy_m[0];
  *y_m = r->xy_m[1];
  *yaw_rad = atan2(r->xy_m[3] - r->xy_m[1], r->xy_m[2] - r->xy_m[0]);
}

void route_driver_update(route_driver_t *r, double x_m, double y_m, double yaw_rad,
                         double *throttle, double *steering) {
  pp_project(&r->st, &r->path, x_m, y_m);
  if (r->st.done) {
    *throttle = 0.0;
    *steering = 0.0;
    return;
  }
  const double e = fabs(r->st.cross_track_m);
  r->sum_sq_m2 += e * e;
  if (e > r->max_abs_m) r->max_abs_m = e;
  r->samples++;
  const double delta = pp_steer(&r->st, &r->path, x_m, y_m, yaw_rad, r->lookahead_m,
                                AUTODRIVE_VEHICLE_WHEELBASE_M, AUTODRIVE_VEHICLE_STEER_LIMIT_RAD);
  *throttle = r->speed;
  *steering = delta / AUTODRIVE_VEHICLE_STEER_LIMIT_RAD;
}

long route_driver_stats(const route_driver_t *r, double *rms_m, double *max_m) {
  *rms_m = r->samples ? sqrt(r->sum_sq_m2 / (double)r->samples) : 0.0;
  *max_m = r->max_abs_m;
  return r->samples;
}
