/* The one pure pursuit of the project (the simulator's route driver, the autonomy's tracker, the
 * city driver and Python's missions through cffi). The path is followed by the rear-axle centre
 * (base_link): the steering angle is the one whose arc from the rear axle, tangent to the
 * heading, passes through a goal point one lookahead [m] ahead, curvature k = 2 y / d^2 (y the
 * goal's lateral offset in the car frame, d its distance), delta = atan(k L). On a circle of any
 * radius that arc is the circle itself, so the steady-state error is zero; the same formula holds
 * in reverse (the travel frame flips and so does tan(delta) / L).
 * The goal is chosen one of two ways, both along a polyline from a progress index:
 *  - by arc length (pp_path_t, pp_point_at: interpolated, s + lookahead) for lanes and routes;
 *  - by distance (pp_goal_index: the first sample at least the lookahead from the car) for
 *    sampled plans (the autonomy's Reeds-Shepp / hybrid A* paths, the loop mission's track).
 * Limits come from the one vehicle description (<autodrive_vehicle.h>, vehicle/nigel.params).
 * No MuJoCo, no I/O, plain C11: unit-testable, built for the car (aarch64) too. */
#ifndef AUTODRIVE_PURE_PURSUIT_H
#define AUTODRIVE_PURE_PURSUIT_H

#include <stddef.h>

#ifdef __cplusplus
extern "C" {
#endif

/* CFFI-BEGIN */
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

/* The car's steering geometry: wheelbase [m] and steering limit [rad]. */
typedef struct pp_vehicle {
  double wheelbase_m;
  double steer_limit_rad;
} pp_vehicle_t;

/* Nigel's (the generated <autodrive_vehicle.h> constants). */
pp_vehicle_t pp_vehicle_default(void);

/* Lookahead [m] growing with speed: min_m + time_s * |speed_m_s|. */
double pp_lookahead_m(double min_m, double time_s, double speed_m_s);

/* Curvature [1/m, + left] of the arc from the rear axle at (x, y, yaw), tangent to the heading,
 * through the goal (gx, gy): 2 y / d^2 (d^2 floored at 1e-6 m^2). */
double pp_curvature_to(double x_m, double y_m, double yaw_rad, double gx_m, double gy_m);

/* Steering angle [rad, + left] that drives curvature k [1/m]: atan(k L), clamped to +-limit. */
double pp_steer_for_curvature(double k_1pm, const pp_vehicle_t *v);

/* Pure pursuit's steering angle [rad, + left] towards the goal: the two above in one. */
double pp_steer_to(double x_m, double y_m, double yaw_rad, double gx_m, double gy_m,
                   const pp_vehicle_t *v);

/* The first index i in [from, n) of the polyline xy_m (n points) whose point is at least
 * lookahead_m from (x, y); n if none is. */
int pp_goal_index(const double *xy_m, int n, int from, double x_m, double y_m, double lookahead_m);

/* Builds the path over n >= 2 points (xy borrowed, must outlive it). Returns 0, or -1 with a
 * message. Free with pp_path_free. */
int pp_path_init(pp_path_t *p, const double *xy_m, int n, int loop, char *err, size_t err_sz);
void pp_path_free(pp_path_t *p);

/* Starts tracking at the path point nearest (x, y) (whole-path search). */
void pp_reset(pp_state_t *st, const pp_path_t *p, double x_m, double y_m);

/* Projects the rear-axle position onto the path (searching forward from the last segment, a
 * few metres at most) and updates cross_track_m, s_m and done. */
void pp_project(pp_state_t *st, const pp_path_t *p, double x_m, double y_m);

/* Steering angle [rad, + left] for pose (x, y, yaw) towards the path point lookahead_m [m]
 * ahead of the projection (0 if that point is the car's position). Call pp_project first. */
double pp_steer(const pp_state_t *st, const pp_path_t *p, double x_m, double y_m, double yaw_rad,
                double lookahead_m, const pp_vehicle_t *v);

/* The path point at arc length s (wrapped on a loop; beyond a path's end it goes on along the
 * last segment's direction). */
void pp_point_at(const pp_path_t *p, double s_m, double out_xy[2]);
/* CFFI-END */

#ifdef __cplusplus
}
#endif
#endif
