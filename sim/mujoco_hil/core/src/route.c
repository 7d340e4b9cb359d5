/* Routes and lanes as polylines (see route.h). */
#include "route.h"

#include <autodrive/angle_wrap.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

int route_from_points(route_t *r, const double *xy, int n, double half_width_m, int loop, char *err,
                      size_t err_sz) {
  memset(r, 0, sizeof *r);
  if (n < 2 || !(half_width_m > 0.0) || !isfinite(half_width_m)) {
    snprintf(err, err_sz, "route: %d points, half width %g m (need >= 2 points, width > 0)", n,
             half_width_m);
    return -1;
  }
  for (int i = 0; i < 2 * n; i++)
    if (!isfinite(xy[i])) {
      snprintf(err, err_sz, "route: point %d is not finite", i / 2);
      return -1;
    }
  r->xy = malloc(sizeof(double) * 2 * (size_t)n);
  r->s_m = malloc(sizeof(double) * (size_t)n);
  if (!r->xy || !r->s_m) {
    route_free(r);
    snprintf(err, err_sz, "route: out of memory");
    return -1;
  }
  memcpy(r->xy, xy, sizeof(double) * 2 * (size_t)n);
  r->n = n;
  r->loop = loop != 0;
  r->half_width_m = half_width_m;
  r->s_m[0] = 0.0;
  for (int i = 1; i < n; i++)
    r->s_m[i] = r->s_m[i - 1] + hypot(xy[2 * i] - xy[2 * i - 2], xy[2 * i + 1] - xy[2 * i - 1]);
  r->length_m = r->s_m[n - 1];
  if (r->loop) r->length_m += hypot(xy[0] - xy[2 * n - 2], xy[1] - xy[2 * n - 1]);
  return 0;
}

int route_from_numeric(route_t *r, const mjModel *m, int id, int with_loop, char *err,
                       size_t err_sz) {
  const char *name = m->names + m->name_numericadr[id];
  const int head = with_loop ? 2 : 1;
  const mjtNum *d = m->numeric_data + m->numeric_adr[id];
  /* the points go on in <name>.part1, .part2 ... (MuJoCo 2.2 holds 500 values per numeric) */
  int total = m->numeric_size[id] - head, parts = 0;
  char part[160];
  for (int k = 1;; k++, parts++) {
    snprintf(part, sizeof part, "%s.part%d", name, k);
    const int pid = mj_name2id(m, mjOBJ_NUMERIC, part);
    if (pid < 0) break;
    total += m->numeric_size[pid];
  }
  if (m->numeric_size[id] < head || total < 4 || total % 2 != 0) {
    snprintf(err, err_sz, "map numeric '%s': %d values in %d part(s), expected %s then x y pairs",
             name, total + head, parts + 1, with_loop ? "loop half_width_m" : "half_width_m");
    return -1;
  }
  double *xy = malloc(sizeof(double) * (size_t)total);
  if (!xy) {
    snprintf(err, err_sz, "map numeric '%s': out of memory", name);
    return -1;
  }
  int n = m->numeric_size[id] - head;
  memcpy(xy, d + head, sizeof(double) * (size_t)n);
  for (int k = 1; k <= parts; k++) {
    snprintf(part, sizeof part, "%s.part%d", name, k);
    const int pid = mj_name2id(m, mjOBJ_NUMERIC, part);
    memcpy(xy + n, m->numeric_data + m->numeric_adr[pid],
           sizeof(double) * (size_t)m->numeric_size[pid]);
    n += m->numeric_size[pid];
  }
  const int rc =
      route_from_points(r, xy, total / 2, d[head - 1], with_loop ? d[0] != 0.0 : 0, err, err_sz);
  free(xy);
  if (rc != 0) {
    char why[256];
    snprintf(why, sizeof why, "%s", err);
    snprintf(err, err_sz, "map numeric '%s': %s", name, why);
  }
  return rc;
}

void route_free(route_t *r) {
  free(r->xy);
  free(r->s_m);
  memset(r, 0, sizeof *r);
}

void route_locate(const route_t *r, double x, double y, double yaw_rad, route_where_t *out) {
  const int segs = r->loop ? r->n : r->n - 1;
  double best = INFINITY;
  memset(out, 0, sizeof *out);
  for (int i = 0; i < segs; i++) {
    const int j = (i + 1) % r->n;
    const double ax = r->xy[2 * i], ay = r->xy[2 * i + 1];
    const double dx = r->xy[2 * j] - ax, dy = r->xy[2 * j + 1] - ay;
    const double len2 = dx * dx + dy * dy;
    double t = len2 > 0.0 ? ((x - ax) * dx + (y - ay) * dy) / len2 : 0.0;
    t = t < 0.0 ? 0.0 : (t > 1.0 ? 1.0 : t);
    const double px = ax + t * dx, py = ay + t * dy;
    const double d2 = (x - px) * (x - px) + (y - py) * (y - py);
    if (d2 >= best) continue;
    best = d2;
    const double len = sqrt(len2);
    /* cross product sign: + when the point is left of the segment's direction */
    const double cross = len > 0.0 ? (dx * (y - ay) - dy * (x - ax)) / len : 0.0;
    out->lateral_m = (cross >= 0.0 ? 1.0 : -1.0) * sqrt(d2);
    out->heading_err_rad = autodrive_angle_wrap_rad(yaw_rad - atan2(dy, dx));
    out->progress_m = r->s_m[i] + t * len;
  }
}
