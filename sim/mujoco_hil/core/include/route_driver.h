/* Route driver: the scripted driver `--script route:NAME[,speed=F][,start=S][,lookahead=M]`
 * follows the map's named route (MJCF numeric `route_<NAME>` = "loop half_width_m x0 y0 x1 y1
 * ...", contract with the map side) by pure pursuit (<autodrive/pure_pursuit.h>) with the car's
 * wheelbase and steering limit from <autodrive_vehicle.h>, at throttle F (the fraction of top
 * speed), and keeps the cross-track error statistics of the rear-axle centre (base_link). Its
 * throttle and steering reach the emulated Nano as real COMMAND frames (script.h).
 * Perturbations (the expert of behavioural cloning, issue 16): with an amplitude A > 0 the
 * driver now and then adds a seeded steering offset (|offset| in [A/2, A], ROUTE_PERTURB_*
 * durations) to pure pursuit's command, so the car leaves the centre line and pure pursuit's
 * recovery gets recorded; `expert_steering` is always pure pursuit's own (unperturbed) command,
 * the label a cloned driver should learn. `lane_shift=K` drives the lane K lane widths to the
 * route's left in the route's direction (K = 1 on a two-lane road: the oncoming lane). */
#ifndef SIM_ROUTE_DRIVER_H
#define SIM_ROUTE_DRIVER_H

#include <stddef.h>

#include <mujoco/mujoco.h>

#include <autodrive/pure_pursuit.h>
#include "rng.h"

#ifdef __cplusplus
extern "C" {
#endif

/* perturbation timing, in driver updates (one per COMMAND frame, 50 Hz) */
#define ROUTE_PERTURB_FIRST_UPDATES 50 /* 1 s of calm driving first */
#define ROUTE_PERTURB_MIN_UPDATES 10   /* each perturbation lasts 0.2 .. 0.5 s */
#define ROUTE_PERTURB_MAX_UPDATES 25
#define ROUTE_PERTURB_GAP_MIN_UPDATES 75 /* then 1.5 .. 3.5 s of recovery and calm */
#define ROUTE_PERTURB_GAP_MAX_UPDATES 175

typedef struct route_driver {
  char name[64];
  double half_width_m; /* the lane's half width [m] */
  double *xy_m;        /* owned copy of the polyline */
  pp_path_t path;
  pp_state_t st;
  double speed; /* throttle, fraction of top speed */
  double lookahead_m;
  int laps;               /* a loop's laps before done */
  double perturb;         /* perturbation amplitude, normalised steering (0: none) */
  rng_t rng;              /* the perturbations' (seeded) */
  long updates;           /* calls to route_driver_update so far */
  long perturb_next;      /* update at which the next perturbation starts */
  long perturb_end;       /* update at which the current one ends */
  double perturb_offset;  /* current offset, normalised steering */
  double expert_steering; /* pure pursuit's last command before any perturbation [-1, 1] */
  /* cross-track statistics over every update while driving [m] */
  double sum_sq_m2, max_abs_m;
  long samples;
} route_driver_t;

/* Loads route `name` from model m, moved `lanes_left` lane widths (2 x the route's half width
 * [m]) to the left of its direction of travel (0: the route's own lane; 1: the lane to its left
 * driven in the route's direction, e.g. the other lane of a two-lane road). Returns 0, or -1
 * with a message naming the route (and the routes the map has) in err. */
int route_driver_init(route_driver_t *r, const mjModel *m, const char *name, double speed,
                      double lookahead_m, int lanes_left, char *err, size_t err_sz);
void route_driver_free(route_driver_t *r);

/* Drive `laps` laps of a loop (>= 1) and add perturbations of amplitude `amplitude` (0: none,
 * else (0, 1] of full steering), drawn from `seed`. Call after route_driver_init. */
void route_driver_set_laps_perturb(route_driver_t *r, int laps, double amplitude, uint64_t seed);

/* Start pose: the route's first point, heading along its first segment. */
void route_driver_start(const route_driver_t *r, double *x_m, double *y_m, double *yaw_rad);

/* One update at the rear-axle pose: projects, records the cross-track error, and gives the
 * normalised command (throttle 0 once the route is done; steering = angle / limit, plus the
 * perturbation when one is on; pure pursuit's own is kept in expert_steering). */
void route_driver_update(route_driver_t *r, double x_m, double y_m, double yaw_rad,
                         double *throttle, double *steering);

/* Cross-track RMS and max [m] so far; returns the number of samples. */
long route_driver_stats(const route_driver_t *r, double *rms_m, double *max_m);

/* Names of the routes in model m, comma-separated, into out (for messages and --help). */
void route_driver_list(const mjModel *m, char *out, size_t out_sz);

#ifdef __cplusplus
}
#endif
#endif
