/* Pure pursuit on a polyline (the reference driver of the tests and the bench, and later the
 * expert of behavioural cloning). The path is followed by the rear-axle centre (base_link):
 * the steering angle is the one whose arc from the rear axle, tangent to the heading, passes
 * through the goal point one lookahead [m] ahead along the path,
 * delta = atan(2 L sin(alpha) / d), d the distance to that point, alpha its bearing. On a
 * circle of any radius that arc is the circle itself, so the steady-state error is zero.
 * No MuJoCo, no I/O: plain geometry, unit-testable. */
#ifndef SIM_PURE_PURSUIT_H
#define SIM_PURE_PURSUIT_H

#include <stddef.h>

#ifdef __cplusplus
extern "C" {
#endif

typedef struct pp_path {
  int n;              /* points */
  const double *xy_m; /* x0 y0 x1 y1 ... (borrowed) */
  double *s_m;        /* arc length at each point (owned) */
  int loop;           /* 1: the last point joins the first */
  double length_m;    /* total, the closing segment included for a loop */
} pp_path_t;

typedef struct pp_state {
  int seg;              /* segment of the last projection (search starts here) */
  double s_m;           /* arc length of the projection; grows past length_m on a loop's laps */
  double lap_m;         /* loop: arc length at the start of the lap of segment seg */
  double cross_track_m; /* signed distance to the path, + = car left of it */
  int done;             /* a path's end (or one lap of a loop) reached */
} pp_state_t;

/* Builds the path over n >= 2 points (xy borrowed, must outlive it). Returns 0, or -1 with a
 * message. Free with pp_path_free. */
int pp_path_init(pp_path_t *p, const double *xy_m, int n, int loop, char *err, size_t err_sz);
void pp_path_free(pp_path_t *p);

/* Starts tracking at the path point nearest (x, y) (whole-path search). */
void pp_reset(pp_state_t *st, const pp_path_t *p, double x_m, double y_m);

/* Projects the rear-axle position onto the path (searching forward from the last segment, a
 * few metres at most) and updates cross_track_m, s_m and done. */
void pp_project(pp_state_t *st, const pp_path_t *p, double x_m, double y_m);

/* Steering angle [rad, + left] for pose (x, y, yaw) with lookahead [m], wheelbase [m]; the
 * result is clamped to +-steer_limit_rad. Call pp_project first. */
double pp_steer(const pp_state_t *st, const pp_path_t *p, double x_m, double y_m, double yaw_rad,
                double lookahead_m, double wheelbase_m, double steer_limit_rad);

/* The path point at arc length s (wrapped on a loop; beyond a path's end it goes on along the
 * last segment's direction). */
void pp_point_at(const pp_path_t *p, double s_m, double out_xy[2]);

#ifdef __cplusplus
}
#endif
#endif
