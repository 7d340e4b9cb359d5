/* A route or lane centre line (polyline in driving order, open or closed) and where a car is
 * on it: the lane flag and the lane-keeping figures of the learning API. The maps contract
 * emits them as MJCF numerics: route_<r> = "loop half_width_m x0 y0 x1 y1 ...", lane_<l> =
 * "half_width_m x0 y0 x1 y1 ...". */
#ifndef SIM_ROUTE_H
#define SIM_ROUTE_H

#include <stddef.h>

#include <mujoco/mujoco.h>

#ifdef __cplusplus
extern "C" {
#endif

typedef struct route {
  int n;       /* points; 0: no route */
  int loop;    /* 1: the last point joins the first */
  double *xy;  /* n points [m] */
  double *s_m; /* arc length at each point [m] */
  double length_m;
  double half_width_m;
} route_t;

typedef struct route_where {
  double lateral_m;       /* signed distance from the centre line, + left of the direction */
  double heading_err_rad; /* yaw minus the segment's direction, in (-pi, pi] */
  double progress_m;      /* arc length of the nearest point */
} route_where_t;

/* From n >= 2 points; half_width_m > 0. Returns 0, or -1 with a message in err. */
int route_from_points(route_t *r, const double *xy, int n, double half_width_m, int loop, char *err,
                      size_t err_sz);
/* From numeric id of m and its continuations <name>.part1, .part2 ... (whole x y pairs):
 * with_loop 1 for route_* (leading loop flag), 0 for lane_*. */
int route_from_numeric(route_t *r, const mjModel *m, int id, int with_loop, char *err,
                       size_t err_sz);
void route_free(route_t *r);
/* Nearest point of the centre line to (x, y) and the car's yaw against it. */
void route_locate(const route_t *r, double x, double y, double yaw_rad, route_where_t *out);

#ifdef __cplusplus
}
#endif
#endif
