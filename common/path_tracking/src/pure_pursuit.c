/* Pure pursuit (see pure_pursuit.h). */
#include "autodrive/pure_pursuit.h"

#include <autodrive_vehicle.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#define PP_SEARCH_M 1.0 /* a projection moves at most this far per call [m] */

pp_vehicle_t pp_vehicle_default(void) {
  const pp_vehicle_t v = {AUTODRIVE_VEHICLE_WHEELBASE_M, AUTODRIVE_VEHICLE_STEER_LIMIT_RAD};
  return v;
}

double pp_lookahead_m(double min_m, double time_s, double speed_m_s) {
  return min_m + time_s * fabs(speed_m_s);
}

double pp_curvature_to(double x_m, double y_m, double yaw_rad, double gx_m, double gy_m) {
  const double dx = gx_m - x_m, dy = gy_m - y_m;
  const double lateral_m = -sin(yaw_rad) * dx + cos(yaw_rad) * dy;
  const double d2 = dx * dx + dy * dy;
  return 2.0 * lateral_m / (d2 > 1e-6 ? d2 : 1e-6);
}

double pp_steer_for_curvature(double k_1pm, const pp_vehicle_t *v) {
  const double delta = atan(k_1pm * v->wheelbase_m);
  if (delta > v->steer_limit_rad) return v->steer_limit_rad;
  if (delta < -v->steer_limit_rad) return -v->steer_limit_rad;
  return delta;
}

double pp_steer_to(double x_m, double y_m, double yaw_rad, double gx_m, double gy_m,
                   const pp_vehicle_t *v) {
  return pp_steer_for_curvature(pp_curvature_to(x_m, y_m, yaw_rad, gx_m, gy_m), v);
}

int pp_goal_index(const double *xy_m, int n, int from, double x_m, double y_m, double lookahead_m) {
  for (int i = from < 0 ? 0 : from; i < n; i++)
    if (hypot(xy_m[2 * i] - x_m, xy_m[2 * i + 1] - y_m) >= lookahead_m) return i;
  return n;
}

static int pp_segments(const pp_path_t *p) {
  return p->loop ? p->n : p->n - 1;
}

static void pp_seg_ends(const pp_path_t *p, int k, const double **a, const double **b) {
  *a = p->xy_m + 2 * k;
  *b = p->xy_m + 2 * ((k + 1) % p->n);
}

int pp_path_init(pp_path_t *p, const double *xy_m, int n, int loop, char *err, size_t err_sz) {
  p->s_m = NULL;
  if (n < 2) {
    snprintf(err, err_sz, "a path needs at least 2 points (got %d)", n);
    return -1;
  }
  p->n = n;
  p->xy_m = xy_m;
  p->loop = loop;
  p->s_m = malloc(sizeof(double) * (size_t)(n + 1));
  if (!p->s_m) {
    snprintf(err, err_sz, "out of memory");
    return -1;
  }
  p->s_m[0] = 0.0;
  for (int k = 0; k < n; k++) {
    if (k == n - 1 && !loop) break;
    const double *a, *b;
    pp_seg_ends(p, k, &a, &b);
    const double len = hypot(b[0] - a[0], b[1] - a[1]);
    p->s_m[k + 1] = p->s_m[k] + len;
  }
  p->length_m = p->s_m[pp_segments(p)];
  if (!(p->length_m > 0)) {
    snprintf(err, err_sz, "the path has zero length");
    free(p->s_m);
    p->s_m = NULL;
    return -1;
  }
  return 0;
}

void pp_path_free(pp_path_t *p) {
  free(p->s_m);
  p->s_m = NULL;
}

/* Distance^2 from (x, y) to segment k, its parameter t in [0, 1] and signed side (+ left). */
static double pp_seg_dist2(const pp_path_t *p, int k, double x, double y, double *t, double *side) {
  const double *a, *b;
  pp_seg_ends(p, k, &a, &b);
  const double dx = b[0] - a[0], dy = b[1] - a[1], l2 = dx * dx + dy * dy;
  double u = l2 > 0 ? ((x - a[0]) * dx + (y - a[1]) * dy) / l2 : 0.0;
  u = u < 0 ? 0 : (u > 1 ? 1 : u);
  const double px = a[0] + u * dx - x, py = a[1] + u * dy - y;
  *t = u;
  *side = dx * (y - a[1]) - dy * (x - a[0]) >= 0 ? 1.0 : -1.0;
  return px * px + py * py;
}

static void pp_take(pp_state_t *st, const pp_path_t *p, int k, double t, double d2, double side,
                    double lap_m) {
  const double seg_len = p->s_m[k + 1] - p->s_m[k];
  st->seg = k;
  st->lap_m = lap_m;
  st->s_m = lap_m + p->s_m[k] + t * seg_len;
  st->cross_track_m = side * sqrt(d2);
}

void pp_reset(pp_state_t *st, const pp_path_t *p, double x_m, double y_m) {
  double best = INFINITY;
  st->done = 0;
  for (int k = 0; k < pp_segments(p); k++) {
    double t, side;
    const double d2 = pp_seg_dist2(p, k, x_m, y_m, &t, &side);
    if (d2 < best) {
      best = d2;
      pp_take(st, p, k, t, d2, side, 0.0);
    }
  }
}

void pp_project(pp_state_t *st, const pp_path_t *p, double x_m, double y_m) {
  const int nseg = pp_segments(p);
  const double lap0 = st->lap_m;
  double best = INFINITY;
  int best_k = st->seg;
  double best_t = 0, best_side = 1, best_lap = lap0;
  /* forward from the last segment (a little back too, for noise), PP_SEARCH_M of path */
  int k = st->seg;
  double lap = lap0;
  for (int back = 0; back < 2 && (p->loop || k > 0); back++) {
    if (k == 0) {
      k = nseg - 1;
      lap -= p->length_m;
    } else {
      k--;
    }
  }
  for (double walked = 0.0; walked < PP_SEARCH_M + 0.2;) {
    double t, side;
    const double d2 = pp_seg_dist2(p, k, x_m, y_m, &t, &side);
    if (d2 < best) {
      best = d2;
      best_k = k;
      best_t = t;
      best_side = side;
      best_lap = lap;
    }
    walked += p->s_m[k + 1] - p->s_m[k];
    if (k + 1 < nseg) {
      k++;
    } else if (p->loop) {
      k = 0;
      lap += p->length_m;
    } else {
      break;
    }
  }
  pp_take(st, p, best_k, best_t, best, best_side, best_lap);
  if (!p->loop) {
    /* past the end: the distance to the last point is no cross-track error */
    if (best_k == nseg - 1 && best_t >= 1.0) {
      st->done = 1;
      st->cross_track_m = 0.0;
    }
  } else if (st->s_m >= p->length_m) {
    st->done = 1;
  }
}

void pp_point_at(const pp_path_t *p, double s_m, double out_xy[2]) {
  const int nseg = pp_segments(p);
  if (p->loop) {
    s_m = fmod(s_m, p->length_m);
    if (s_m < 0) s_m += p->length_m;
  } else if (s_m <= 0) {
    s_m = 0;
  }
  int lo = 0, hi = nseg - 1; /* last segment with s_m[k] <= s */
  while (lo < hi) {
    const int mid = (lo + hi + 1) / 2;
    if (p->s_m[mid] <= s_m)
      lo = mid;
    else
      hi = mid - 1;
  }
  const double *a, *b;
  pp_seg_ends(p, lo, &a, &b);
  const double len = p->s_m[lo + 1] - p->s_m[lo];
  const double u = len > 0 ? (s_m - p->s_m[lo]) / len : 0.0; /* > 1 past a path's end */
  out_xy[0] = a[0] + u * (b[0] - a[0]);
  out_xy[1] = a[1] + u * (b[1] - a[1]);
}

double pp_steer(const pp_state_t *st, const pp_path_t *p, double x_m, double y_m, double yaw_rad,
                double lookahead_m, const pp_vehicle_t *v) {
  double goal[2];
  pp_point_at(p, st->s_m + lookahead_m, goal);
  if (hypot(goal[0] - x_m, goal[1] - y_m) < 1e-6) return 0.0;
  return pp_steer_to(x_m, y_m, yaw_rad, goal[0], goal[1], v);
}
