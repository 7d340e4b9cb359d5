/* The multi-agent intersection policy's shared core (C11, no dependencies): the observation
 * builder and the time-to-collision safety shield. Python's batch training and evaluation
 * (cffi, ABI mode: python/autodrive/learn/marl/core.py reads the declarations between the CFFI
 * markers) and the C++ autodrive-marl both call it, so the observation and the shield exist
 * once.
 *
 * Frames: world x, y [m], yaw CCW from world +x [rad]. A car's pose is its base_link (rear-axle
 * centre); its chassis box is centred chassis_offset_m ahead of it. Speeds are along the
 * heading [m/s]. Functions that can fail return 0 / -1 and write what is wrong into err. */
#ifndef AUTODRIVE_MARL_CORE_H
#define AUTODRIVE_MARL_CORE_H

#include <stddef.h>

#ifdef __cplusplus
extern "C" {
#endif

/* CFFI-BEGIN */
/* Observation layout version 1 (D = 24 float32), all in the car's own frame:
 *   [0..1] goal x, y / ADM_POSITION_SCALE_M
 *   [2..3] route waypoint (lookahead point on the own route) x, y / ADM_WAYPOINT_SCALE_M
 *   [4]    own speed / ADM_SPEED_SCALE_M_S
 *   [5]    own last steering command (normalised, [-1, 1])
 *   then ADM_PEER_SLOTS slots of 6, nearest peer first (ties: lower id first); peers farther
 *   than ADM_PEER_RANGE_M leave their slot at zeros:
 *   [+0] 1 (present)  [+1..2] relative x, y / ADM_POSITION_SCALE_M
 *   [+3..4] cos, sin of the relative yaw  [+5] peer speed / ADM_SPEED_SCALE_M_S */
#define ADM_OBS_VERSION 1
#define ADM_OWN_FEATURES 6
#define ADM_PEER_FEATURES 6
#define ADM_PEER_SLOTS 3
#define ADM_OBS_DIM 24
#define ADM_POSITION_SCALE_M 2.0
#define ADM_WAYPOINT_SCALE_M 0.5
#define ADM_SPEED_SCALE_M_S 0.5
#define ADM_PEER_RANGE_M 4.0
#define ADM_STOPPED_M_S 0.02 /* the shield: a car slower than this stands */

typedef struct adm_car {
  int id;           /* vehicle number (tie-breaks: the lower id goes first) */
  double x_m, y_m;  /* base_link in the world */
  double yaw_rad;   /* heading */
  double speed_m_s; /* along the heading, + forward */
} adm_car_t;

typedef struct adm_command {
  double throttle; /* normalised [-1, 1] as the Nano protocol's COMMAND */
  double steering; /* normalised [-1, 1], + left */
} adm_command_t;

/* obs (obs_len must be ADM_OBS_DIM) for self heading to goal_xy_m, following waypoint_xy_m,
 * with its last steering command and n_peers peers (self may be among them: skipped by id). */
int adm_observation(const adm_car_t *self, const double *goal_xy_m, const double *waypoint_xy_m,
                    double last_steering, const adm_car_t *peers, int n_peers, float *obs,
                    int obs_len, char *err, size_t err_sz);

/* On a route of n_points (x, y [m], driving order): the nearest point to (x_m, y_m), searched
 * from *hint_index (-1: everywhere; updated, never moves backwards by more than a few points),
 * the point lookahead_m further along the route (clamped at its end) into waypoint_xy_m, and the
 * route's remaining length from the nearest point into remaining_m. */
int adm_route_waypoint(const double *route_xy_m, int n_points, double x_m, double y_m,
                       double lookahead_m, int *hint_index, double *waypoint_xy_m,
                       double *remaining_m, char *err, size_t err_sz);

typedef struct adm_shield_config {
  double horizon_s;        /* predict this far ahead */
  double dt_s;             /* prediction step */
  double steer_hold_s;     /* the intended steering is held this long, then the heading */
  double margin_m;         /* clearance added to each car's footprint */
  double pose_error_m;     /* each car's pose may be this far off (0: true poses, the batch; HIL
                              without the Eye: the EKF's dead reckoning), added to every
                              footprint, the bare one of the emergency check too */
  double emergency_s;      /* with the right of way, brake for a touch within this */
  double chassis_length_m; /* the car's footprint (chassis box) */
  double chassis_width_m;
  double chassis_offset_m; /* box centre ahead of base_link */
  double wheelbase_m;
  double steer_limit_rad; /* full lock (steering 1) */
  double top_speed_m_s;   /* speed at throttle 1 */
  double brake_throttle;  /* the throttle sent while the shield brakes (0: stop) */
  double back_throttle;   /* a standing car blocking a standing car that goes first backs at
                             this (< 0; 0: never backs) */
  double back_check_s;    /* ... if its path back stays clear (margin) for this long */
  /* The lane term (with an adm_lane_t): the car alone against the road's edge and what stands
   * beside it (the traffic lights' poles just off the road at the stop lines). */
  double lane_horizon_s;   /* the intended steering must keep the chassis in bounds this long */
  double lane_margin_m;    /* a chassis corner may pass its lane's edge by this much */
  double lane_lookahead_m; /* the fallback lane follower's aim point ahead on the route */
  double lane_gain;        /* ... its steering = gain x the aim point's bearing [rad], clamped */
  double steer_rate_rad_s; /* the steering servo's slew (0: instant), the car's figure */
} adm_shield_config_t;

/* The car's own lane for the shield's lane term: its route polyline, the lane's half width and
 * the wheels' present steering (the servo slews from there to the command). */
typedef struct adm_lane {
  const double *route_xy_m; /* n_points x (x, y) [m], driving order (adm_route_waypoint's) */
  int n_points;
  int hint_index;      /* the nearest route point found last (adm_route_waypoint's), -1: any */
  double half_width_m; /* the lane's half width (the map's) */
  double steering_now; /* the wheels' steering now, normalised [-1, 1]: the measured angle
                          where known, else the last command sent */
} adm_lane_t;

typedef struct adm_shield_result {
  adm_command_t command; /* what to send */
  int intervened;        /* 1: braked (or backed) instead of the intended command */
  int peer_id;           /* the peer it braked for, else -1 */
  double ttc_s;          /* predicted time to collision with it, else the horizon */
  int steered;           /* 1: the lane term replaced the steering (command.steering) */
} adm_shield_result_t;

/* Defaults of the shield's tuning (horizon, step, margin ...); the car's figures (chassis,
 * wheelbase, steering limit, top speed) are left at 0 for the caller to fill from the vehicle
 * description (vehicle/nigel.params). */
void adm_shield_defaults(adm_shield_config_t *cfg);

/* The time-to-collision shield. Self follows the intended command (kinematic bicycle, steering
 * held steer_hold_s, speed at least throttle * top_speed), and also goes straight on (the
 * steering servo lags the command); each peer keeps its heading and speed. Footprints are two
 * circles per car covering its chassis box. Right of way between two cars is the same seen from
 * either: the car that has the other farther ahead along its own heading gives way (equal within 5
 * cm, or both standing: the lower id goes first). Giving way, self brakes for any predicted contact
 * (footprints plus margin_m) within the horizon; with the right of way, only for a touch of the
 * bare footprints within emergency_s. A peer behind self at the contact is left to that peer's
 * shield.
 * Standing cars: while both stand, a peer that goes first is also predicted starting straight on
 * at top speed, so that self does not start into its way. Self, standing or already rolling
 * back, that stands within emergency_s of a standing first peer's way (straight on or at either
 * full lock) backs up straight at back_throttle while its way back stays clear for back_check_s
 * (sliding past a corner within 5 mm of the distance now counts as clear).
 * Lane term (lane not NULL; first, so that the peers are checked with the steering sent): self
 * driven with the intended steering for lane_horizon_s (the servo slewing at steer_rate_rad_s
 * from lane->steering_now) must keep every chassis corner within half_width_m + lane_margin_m
 * of its route, or no farther out than now; else the steering becomes the lane follower's
 * (steered = 1), and if that path leaves the bounds too, self brakes while the wheels turn. */
int adm_shield(const adm_shield_config_t *cfg, const adm_car_t *self, const adm_command_t *intended,
               const adm_car_t *peers, int n_peers, const adm_lane_t *lane,
               adm_shield_result_t *out, char *err, size_t err_sz);
/* CFFI-END */

#ifdef __cplusplus
}
#endif
#endif
