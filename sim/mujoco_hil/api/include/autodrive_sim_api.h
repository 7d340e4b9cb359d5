/* The simulator as a library for learning (libautodrive_sim_core.so): worlds of N Nigel cars
 * on a map, stepped in process with no pty, no LCM and no wall clock. Each car keeps what
 * HIL gives it: the paper's tyre model, its emulated Nano (the real firmware core) and the
 * 1 ms physics step of autodrive-sim. A command goes through the firmware as real protocol
 * COMMAND frames at 50 Hz (armed with engaged 0, then engaged 1), with the firmware's slew
 * and steering-rate limits, exactly as the runtime's bridge writes them on the pty.
 *
 * Plain C types only: Python loads it with cffi (python/autodrive/gym/_lib.py reads
 * the declarations between the CFFI markers from this file). Cars are 0-based here. Not
 * thread-safe per world; distinct worlds are independent. Errors: functions that can fail
 * return 0 / -1 (or NULL) and write a message naming the bad input into err. */
#ifndef AUTODRIVE_SIM_API_H
#define AUTODRIVE_SIM_API_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/* The library is compiled with -fvisibility=hidden: what this header declares is its whole
 * export list (tests/sim checks nm -D). A pragma rather than a macro on each declaration,
 * because cffi parses the declarations below without a preprocessor. */
#pragma GCC visibility push(default)
/* CFFI-BEGIN */
#define AD_MAX_CARS 32
#define AD_PHYSICS_STEP_US 1000
#define AD_MAX_THREADS 64

typedef struct ad_world ad_world_t;

typedef struct ad_world_config {
  const char *map;         /* map name (maps/<name>.xml) or an MJCF path */
  const char *params_path; /* vehicle description; NULL: vehicle/nigel.params of the tree */
  const char *run_dir;     /* where the generated scene is written; NULL: $TMPDIR or /tmp */
  int cars;                /* 1..AD_MAX_CARS */
  uint64_t seed;           /* IMU biases and noise, LIDAR noise (ad_world_reset changes it) */
  int lidar_rays;          /* 0: no LIDAR; else rays per scan (360: the RPLIDAR A1) */
  int camera_width_px;     /* > 0: each car's front camera can be rendered at this size */
  int camera_height_px;
  int tyre_model; /* -1: as the parameter file says, 0: MuJoCo friction, 1: the paper's */
} ad_world_config_t;

typedef struct ad_obs {
  double time_s;               /* sim time */
  double pos_m[3];             /* base_link (rear-axle centre) in the world */
  double quat_wxyz[4];         /* base_link orientation */
  double yaw_rad;              /* heading, CCW from world +x */
  double vel_body_m_s[3];      /* base_link velocity, car axes (x forward, y left, z up) */
  double gyro_body_rad_s[3];   /* angular velocity, car axes */
  double steering_rad;         /* front-wheel centre angle */
  double wheel_speed_rad_s[4]; /* fl fr rl rr, + forward */
  double imu_accel_m_s2[3];    /* the IMU the firmware reads: sensor + bias, car axes */
  double imu_gyro_rad_s[3];
  int in_collision; /* the chassis touches anything */
  int off_lane;     /* base_link outside its route's (else every lane's) half width; 0 when the
                       map has neither */
  int has_route;    /* 1: the route_* fields below are valid */
  double route_lateral_m;       /* signed distance from the route's centre line, + left */
  double route_heading_err_rad; /* car heading minus the route's direction, in (-pi, pi] */
  double route_progress_m;      /* arc length of the nearest centre-line point */
  double route_length_m;
  double route_half_width_m;
  int nano_engaged; /* the firmware's engaged state (armed and commanded) */
} ad_obs_t;

/* A world: the map compiled with cfg->cars cars at the map's spawn places, reset with
 * cfg->seed. NULL on error (message in err). */
ad_world_t *ad_world_create(const ad_world_config_t *cfg, char *err, size_t err_sz);
void ad_world_destroy(ad_world_t *w);
int ad_world_cars(const ad_world_t *w);
double ad_world_time_s(const ad_world_t *w);

/* Back to sim time 0 with seed. poses_xy_yaw: NULL keeps the start poses, else 3 values per
 * car (x [m], y [m], yaw [rad] of base_link) that become the start poses; a pose off the
 * floor or on an obstacle is refused (the start poses stay; reset again before stepping).
 * The same seed and poses give the same episode. */
int ad_world_reset(ad_world_t *w, uint64_t seed, const double *poses_xy_yaw, char *err,
                   size_t err_sz);
/* What car's driver sends from its next COMMAND frame on: throttle and steering in [-1, 1]
 * (the protocol's normalised values). After a reset every driver arms the Nano with three
 * engaged=0 frames (60 ms) and then sends engaged frames. */
int ad_world_command(ad_world_t *w, int car, double throttle, double steering, char *err,
                     size_t err_sz);
/* Advances the world by period_ms physics steps of 1 ms. */
int ad_world_step(ad_world_t *w, int period_ms, char *err, size_t err_sz);
/* Advances each of k worlds by period_ms: the batch step (no more than k single steps). On
 * an error, stops and names the world's index. */
int ad_worlds_step(ad_world_t *const *worlds, int k, int period_ms, char *err, size_t err_sz);

/* The same on up to `threads` threads (the calling one included; 1: ad_worlds_step): worlds
 * are independent, so the result is the same as stepping them one by one. On an error the
 * message names the lowest failing world's index. */
int ad_worlds_step_threads(ad_world_t *const *worlds, int k, int period_ms, int threads, char *err,
                           size_t err_sz);

/* car's observation now (0 / -1 for a bad car). */
int ad_world_observe(const ad_world_t *w, int car, ad_obs_t *out);
/* Casts car's LIDAR scan now (all rays at this instant) into ranges_m: n must be the world's
 * lidar_rays; ray i at i * 2 pi / n CCW from the car's x axis; no return = +inf. */
int ad_world_lidar(ad_world_t *w, int car, float *ranges_m, int n, char *err, size_t err_sz);
/* Renders car's front camera now into rgb (height x width x 3, rows top-down); n_bytes must
 * be width * height * 3 of the world's config. Needs EGL or OSMesa (Mesa). */
int ad_world_camera(ad_world_t *w, int car, uint8_t *rgb, size_t n_bytes, char *err, size_t err_sz);

/* car follows route name: the map's MJCF numeric route_<name> (else lane_<name>) of the maps
 * contract. NULL clears it. */
int ad_world_set_route(ad_world_t *w, int car, const char *name, char *err, size_t err_sz);
/* car follows a route given as n points (x, y [m]) in driving order, closed when loop. */
int ad_world_set_route_points(ad_world_t *w, int car, const double *xy, int n, double half_width_m,
                              int loop, char *err, size_t err_sz);

/* Benchmark: wall time [s] of a bare mj_step loop of steps steps on a copy of the world's
 * model and state (MuJoCo alone, the baseline of api_overhead_ratio). */
double ad_world_bare_mj_step_s(const ad_world_t *w, int steps);
/* Videos of episodes (the simulator's own MP4 writer, sim/mujoco_hil/sensors/sim_video.h,
 * through Debian's ffmpeg): frames of width x height x 3 RGB (rows top-down) at fps frames per
 * second of sim time. ad_video_frame stamps each with t_s (sim time [s]) unless t_s < 0.
 * NULL / -1 with the cause in err; ad_video_close finishes the file (0, or -1). */
typedef struct ad_video ad_video_t;
ad_video_t *ad_video_open(const char *path, int width_px, int height_px, double fps, char *err,
                          size_t err_sz);
int ad_video_frame(ad_video_t *v, const uint8_t *rgb, size_t n_bytes, double t_s, char *err,
                   size_t err_sz);
int ad_video_close(ad_video_t *v, char *err, size_t err_sz);
/* CFFI-END */
#pragma GCC visibility pop

#ifdef __cplusplus
}
#endif
#endif
