/* Route driver (see route_driver.h). */
#include "route_driver.h"

#include "route.h"

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

/* Moves every point of the polyline `d_m` [m] to the left of its direction of travel (the
 * tangent from the point before to the point after; one-sided at a repeated point or an open
 * end). On the map's concentric lane arcs this gives the neighbouring lane's arc exactly. */
static int route_shift_left(double *xy_m, int n, int loop, double d_m) {
  double *orig = malloc(sizeof(double) * 2 * (size_t)n);
  if (!orig) return -1;
  memcpy(orig, xy_m, sizeof(double) * 2 * (size_t)n);
  for (int i = 0; i < n; i++) {
    const int prev = i > 0 ? i - 1 : (loop ? n - 1 : 0);
    const int next = i < n - 1 ? i + 1 : (loop ? 0 : n - 1);
    double tx = orig[2 * next] - orig[2 * prev], ty = orig[2 * next + 1] - orig[2 * prev + 1];
    if (hypot(tx, ty) < 1e-9) { /* a closed loop's repeated end point: the segment after it */
      const int k = i < n - 1 ? i : i - 1;
      tx = orig[2 * (k + 1)] - orig[2 * k];
      ty = orig[2 * (k + 1) + 1] - orig[2 * k + 1];
    }
    const double len = hypot(tx, ty);
    if (len < 1e-9) continue;
    xy_m[2 * i] = orig[2 * i] - d_m * ty / len;
    xy_m[2 * i + 1] = orig[2 * i + 1] + d_m * tx / len;
  }
  free(orig);
  return 0;
}

int route_driver_init(route_driver_t *r, const mjModel *m, const char *name, double speed,
                      double lookahead_m, int lanes_left, char *err, size_t err_sz) {
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
  route_t line; /* the numeric and its .partK continuations, read by route.c */
  char rerr[256];
  if (route_from_numeric(&line, m, id, 1, rerr, sizeof rerr) != 0) {
    snprintf(err, err_sz, "--script route:%s: %s", name, rerr);
    return -1;
  }
  snprintf(r->name, sizeof r->name, "%s", name);
  r->half_width_m = line.half_width_m;
  const int n = line.n, loop = line.loop;
  r->xy_m = line.xy; /* the driver keeps the points; the arc lengths are pure pursuit's own */
  free(line.s_m);
  /* the map's lanes are adjacent: the neighbouring lane's centre is one lane width away */
  if (lanes_left && route_shift_left(r->xy_m, n, loop, lanes_left * 2.0 * line.half_width_m)) {
    snprintf(err, err_sz, "--script route:%s: out of memory", name);
    free(r->xy_m);
    r->xy_m = NULL;
    return -1;
  }
  char perr[256];
  if (pp_path_init(&r->path, r->xy_m, n, loop, perr, sizeof perr) != 0) {
    snprintf(err, err_sz, "--script route:%s: %s", name, perr);
    route_driver_free(r);
    return -1;
  }
  r->speed = speed;
  r->lookahead_m = lookahead_m;
  r->laps = 1;
  pp_reset(&r->st, &r->path, r->xy_m[0], r->xy_m[1]);
  return 0;
}

void route_driver_set_laps_perturb(route_driver_t *r, int laps, double amplitude, uint64_t seed) {
  r->laps = laps < 1 ? 1 : laps;
  r->perturb = amplitude;
  rng_seed(&r->rng, seed * 2654435761ull + 16u);
  r->updates = 0;
  r->perturb_next = ROUTE_PERTURB_FIRST_UPDATES;
  r->perturb_end = 0;
  r->perturb_offset = 0.0;
}

/* The perturbation to add at this update (starts and ends them on schedule). */
static double route_driver_perturbation(route_driver_t *r) {
  if (r->perturb <= 0.0) return 0.0;
  const long u = r->updates;
  if (u == r->perturb_next) {
    const long len =
        ROUTE_PERTURB_MIN_UPDATES +
        (long)(rng_uniform(&r->rng) * (ROUTE_PERTURB_MAX_UPDATES - ROUTE_PERTURB_MIN_UPDATES + 1));
    const long gap = ROUTE_PERTURB_GAP_MIN_UPDATES +
                     (long)(rng_uniform(&r->rng) *
                            (ROUTE_PERTURB_GAP_MAX_UPDATES - ROUTE_PERTURB_GAP_MIN_UPDATES + 1));
    const double mag = r->perturb * (0.5 + 0.5 * rng_uniform(&r->rng));
    r->perturb_offset = rng_uniform(&r->rng) < 0.5 ? -mag : mag;
    r->perturb_end = u + len;
    r->perturb_next = r->perturb_end + gap;
  }
  return u < r->perturb_end ? r->perturb_offset : 0.0;
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
  if (r->path.loop) r->st.done = r->st.s_m >= (double)r->laps * r->path.length_m;
  if (r->st.done) {
    r->expert_steering = 0.0;
    *throttle = 0.0;
    *steering = 0.0;
    return;
  }
  const double e = fabs(r->st.cross_track_m);
  r->sum_sq_m2 += e * e;
  if (e > r->max_abs_m) r->max_abs_m = e;
  r->samples++;
  const pp_vehicle_t car = pp_vehicle_default();
  const double delta = pp_steer(&r->st, &r->path, x_m, y_m, yaw_rad, r->lookahead_m, &car);
  *throttle = r->speed;
  r->expert_steering = delta / AUTODRIVE_VEHICLE_STEER_LIMIT_RAD;
  const double cmd = r->expert_steering + route_driver_perturbation(r);
  *steering = cmd > 1.0 ? 1.0 : (cmd < -1.0 ? -1.0 : cmd);
  r->updates++;
}

long route_driver_stats(const route_driver_t *r, double *rms_m, double *max_m) {
  *rms_m = r->samples ? sqrt(r->sum_sq_m2 / (double)r->samples) : 0.0;
  *max_m = r->max_abs_m;
  return r->samples;
}
