/* The simulator core: MuJoCo world of N Nigel cars, each with its emulated Nano (the real
 * firmware core behind the sim HAL), its UART on a pty, and the drive, steering and tyre
 * models. One call of sim_step advances everything by one 1 ms physics step of sim time.
 * Not thread-safe; no LCM here (the program publishes, tests read state directly). */
#ifndef SIM_SIM_H
#define SIM_SIM_H

#include <stddef.h>
#include <stdint.h>
#include <time.h>

#include <mujoco/mujoco.h>

#include "nano_core.h"
#include "scenario.h"

#ifdef __cplusplus
extern "C" {
#endif

#define SIM_STEP_US 1000 /* physics and Nano loop period [us] */
#define SIM_MAX_CARS 32
#define SIM_MAX_DISTRACTORS 20 /* --distractors */

typedef struct sim_config {
  const char *params_path; /* vehicle parameter file */
  const char *map_path;    /* map MJCF */
  /* NULL: the map's textures; else a folder whose textures/ replaces the map's folder's (a
   * road style of domain randomisation, autodrive.maps.road_styles) */
  const char *texture_dir;
  const char *run_dir;     /* ptys' symlinks and the generated scene go here */
  int cars;                /* 1..SIM_MAX_CARS */
  uint64_t seed;           /* IMU biases and noise */
  int open_ptys;           /* 1: Nano (and LIDAR) ptys with symlinks */
  const char *script;      /* NULL, or the scripted driver spec for every car (script.h) */
  int lidar;               /* 1: simulate the LIDAR */
  int no_map_late_boxes;   /* 1: leave out the map's late_obstacles */
  int tyre_model;          /* -1: as the parameter file says, 0: MuJoCo friction, 1: paper */
  const scn_pose_t *start; /* NULL: car 1 at the map's "spawn" site; else at this pose */
  int late_boxes;          /* 0..SCN_MAX_LATE_BOXES boxes that appear during the run (the
                            * map's late_obstacles come on top, after them) */
  const scn_late_box_t *late_box;
  /* 0..SIM_MAX_DISTRACTORS static cones, boxes and parked-car-sized boxes placed from seed
   * beside the road (distractors.c): off every lane and route, clear of the cars' starts, the
   * map's obstacles, the late boxes and each other. sim_create fails when there is no room.
   * Placed once: sim_reset keeps them where they are, whatever its seed. */
  int distractors;
  /* More start poses the distractors keep clear of, besides where the cars stand after
   * sim_create: poses the program gives with sim_reset later (--start once per car,
   * --car-start). x_m, y_m [m] of base_link and yaw_deg [deg]. */
  int distractor_keep_clear;
  const scn_pose_t *distractor_keep_clear_pose;
  /* Host link service period [ms of sim time, = steps]: the ptys are read and written every
   * this many steps. 0 or 1: every step (real time, --rtf, --lockstep-client). Larger batches
   * the bytes the way a USB-serial adapter's latency timer does; free lockstep uses it so an
   * idle pty costs no system call per step. Wire timing inside the Nano's UART is unchanged. */
  int host_io_period_ms;
  /* 1: the LIDAR has no rotating head stepped every 1 ms; sim_lidar_scan_at_once casts a
   * whole scan when asked (the learning API: a scan costs only when an observation wants it) */
  int lidar_on_request;
  int lidar_rays; /* rays per revolution; 0: the RPLIDAR A1's (sim_lidar_config_default) */
} sim_config_t;

typedef struct sim sim_t;

typedef struct sim_truth {
  double pos_m[3]; /* base_link in the world */
  double quat_wxyz[4];
  double yaw_rad;
  double vel_body_m_s[3]; /* base_link origin velocity, body frame */
  double gyro_body_rad_s[3];
  double steering_rad;         /* centre angle from the two knuckles (Ackermann inverse) */
  double wheel_speed_rad_s[4]; /* fl fr rl rr, + forward */
  int in_collision;            /* chassis touches anything */
  double command_throttle;     /* the last valid COMMAND the car's Nano took, [-1, 1] */
  double command_steering;     /* its steering [-1, 1] (the label of behavioural cloning) */
  double expert_steering;      /* --script route: pure pursuit's own steering before any
                                  perturbation [-1, 1]; NaN without a route driver */
} sim_truth_t;

/* Builds the world. Returns NULL with a message naming the bad input in err. */
sim_t *sim_create(const sim_config_t *cfg, char *err, size_t err_sz);
/* Checks the scenario options against the map: with a start pose, every car's footprint
 * (car 1 there, the others beside it as usual) must be on the floor and clear of walls and
 * static obstacles; every late box likewise. Returns 0, or -1 with a message that starts with
 * the option (--start, --late-box) and says what is in the way. The program refuses to run a
 * scenario that fails it (exit 2); without these options it checks nothing. */
int sim_check_scenario(const sim_t *s, char *err, size_t err_sz);
/* Puts the world back to its state right after sim_create, with seed for the IMU biases and
 * noise and the LIDAR noise: sim time 0, every car's firmware freshly booted, its scripted
 * driver (if any) back at its first frame, late boxes not yet there. poses: NULL for the
 * start poses of sim_create, else ncars poses (x_m, y_m, yaw_rad of base_link) that become
 * the new start poses; each must be on the floor and clear of walls and obstacles. Returns 0,
 * or -1 with a message naming the car and what is in the way. The same seed and poses give
 * the same run, bit for bit. */
int sim_reset(sim_t *s, uint64_t seed, const double *poses, char *err, size_t err_sz);
/* Sets what car's in-process scripted driver (sim_config_t.script, script.h) sends in its
 * next COMMAND frames (throttle, steering in [-1, 1]): the learning API's command path, the
 * same frames and rates the runtime's bridge writes to the pty. -1 when the car has no
 * scripted driver or a value is out of range. */
int sim_drive(sim_t *s, int car, double throttle, double steering);
/* Puts car (1-based) at (x_m, y_m, yaw_rad) of base_link, standing still (its free joint's
 * and wheels' velocities zeroed), without touching sim time, the firmware or the other cars:
 * the evaluation's "put the car back on the centre line" after an intervention. Checked like
 * a start pose (on the floor, clear of walls and obstacles); -1 with the reason in err. */
int sim_teleport(sim_t *s, int car, double x_m, double y_m, double yaw_rad, char *err,
                 size_t err_sz);
struct sim_lidar_scan;
/* Casts car's whole LIDAR scan at the current state (stamped now) and returns it; NULL
 * without a LIDAR. For sim_config_t.lidar_on_request. */
const struct sim_lidar_scan *sim_lidar_scan_at_once(sim_t *s, int car);
/* The IMU the firmware reads less its white noise (drawing none, so observing changes
 * nothing): MuJoCo's accelerometer [m/s^2] and gyro [rad/s] at the IMU site, car axes, plus
 * the car's biases. */
void sim_imu(const sim_t *s, int car, double accel_m_s2[3], double gyro_rad_s[3]);
/* The next sim_step computes the accelerometer for a reader after it (sim_imu): steps compute
 * it only when the emulated Nano samples its IMU or a reader asked, so the value sim_imu
 * gives after a step nobody asked for may be up to one IMU period [10 ms] old. */
void sim_want_accel(sim_t *s);
/* Closes ptys, removes symlinks and the generated scene. NULL is fine. */
void sim_destroy(sim_t *s);

/* One 1 ms step. Returns 0, or -1 on a fatal error (message in err). */
int sim_step(sim_t *s, char *err, size_t err_sz);

int64_t sim_time_us(const sim_t *s);
int sim_cars(const sim_t *s);
/* The physics model and data: the map without its visual-only geoms (they cost MuJoCo 2.2
 * collision time every step although they never collide). */
const mjModel *sim_model(const sim_t *s);
mjData *sim_data(const sim_t *s);
/* What cameras, the Eye and the viewer render: the whole map (road tiles, sign faces, light
 * lamps lit by the sim, car lamps). sim_render_data brings its data to the physics state
 * (positions, mocap, cameras) and returns it. Without visual-only geoms in the map these are
 * the physics model and data. */
mjModel *sim_render_model(const sim_t *s);
mjData *sim_render_data(sim_t *s);
/* The same into dst (made with mj_makeData(sim_render_model(s))): a snapshot that another
 * thread may render while the physics steps on. */
void sim_render_snapshot(const sim_t *s, mjData *dst);
void sim_get_truth(const sim_t *s, int car, sim_truth_t *out); /* car 1-based */
/* The Nano's symlink path (empty without ptys). */
const char *sim_nano_link(const sim_t *s, int car);
const char *sim_lidar_link(const sim_t *s, int car);
/* Waits up to timeout_ms of wall time until bytes a client wrote to car's Nano pty are
 * readable by the sim (the kernel moves pty data asynchronously). 1 if ready, 0 if not. For
 * tests that write and then step a fixed sim time. */
int sim_nano_wait_input(const sim_t *s, int car, int timeout_ms);
/* Sim time at which the client on car's Nano pty last wrote bytes [us]; -1 before the first
 * (or without a pty). --lockstep-client paces the sim by it. */
int64_t sim_host_rx_us(const sim_t *s, int car);
/* Reads what the client on car's Nano pty wrote so far onto the Nano's wire, at the current
 * sim time, and returns how many good frames it has written in all (0 without a pty).
 * --lockstep-frames holds the sim until this grows. */
uint32_t sim_host_frames(sim_t *s, int car);
/* The emulated Nano's firmware state (read-only use, for tests). */
const nano_core_t *sim_nano(const sim_t *s, int car);
/* Last motor outputs the firmware set through the HAL. */
void sim_motor_outputs(const sim_t *s, int car, uint8_t *duty, uint8_t *reverse, uint8_t *brake,
                       uint16_t *servo_us);
/* A completed LIDAR scan this step (NULL otherwise); see sim_lidar.h for the fields. */
struct sim_lidar_scan;
const struct sim_lidar_scan *sim_lidar_new_scan(const sim_t *s, int car);
/* 1 while a client (the runtime's RPLIDAR driver) is scanning on car's emulated RPLIDAR pty. */
int sim_lidar_pty_scanning(const sim_t *s, int car);
#define SIM_MAX_BOXES (SCN_MAX_LATE_BOXES + SCN_MAX_MAP_LATE_BOXES)
/* Late boxes (k 0-based; the --late-box ones, then the map's late_obstacles): the count, and
 * 1 when box k appeared on the floor during the last sim_step; then *car_below (if non-NULL)
 * is the first car (1-based) whose footprint it landed on, or 0. A box stays on the floor once
 * it has appeared, unless its stay_s sends it away again (after a reset it comes back). */
int sim_late_boxes(const sim_t *s);
const scn_late_box_t *sim_late_box(const sim_t *s, int k);
int sim_late_box_appeared(const sim_t *s, int k, int *car_below);
/* 1 when box k (its stay_s > 0) left the floor again during the last sim_step. */
int sim_late_box_left(const sim_t *s, int k);

/* The map's traffic lights (traffic_lights.h): each step updates them at sim time and lights
 * their lamps in the model. Commands (tl_command) take effect at the next step. */
struct traffic_lights;
struct traffic_lights *sim_traffic_lights(sim_t *s);
/* The route driver of --script route:NAME (route_driver.h), or NULL. */
struct route_driver;
const struct route_driver *sim_route(const sim_t *s);

/* The clock id's time now [s] (CLOCK_MONOTONIC, CLOCK_THREAD_CPUTIME_ID, ...). */
double sim_clock_s(clockid_t id);

/* Runs a bare mj_step loop on the same model for steps [1 ms] and returns its wall time [s]
 * (*cpu_s, if given: the thread's CPU time [s]). */
double sim_bare_mj_step_s(const sim_t *s, int steps, double *cpu_s);

/* A bare mj_step loop on its own mjData of the same model, stepped in blocks between blocks of
 * the sim's own steps: tools/bench sim pairs each sim block with the bare block after it, so
 * both see the same load on a shared machine. Each block starts from the sim's state (see
 * sim_bare_sync), so both halves solve the same moving cars' contacts. */
typedef struct sim_bare sim_bare_t;
sim_bare_t *sim_bare_create(const sim_t *s);
/* Copies the sim's state into the bare loop: time, poses, velocities, mocap bodies, controls and
 * the applied forces, which the bare loop then holds (the tyres' last forces keep the cars
 * driving, and the constraint solver's warm start carries over). */
void sim_bare_sync(sim_bare_t *b, const sim_t *s);
/* Steps it steps [1 ms] on; returns the wall time [s] and, in *cpu_s, the thread's CPU [s]. */
double sim_bare_run(sim_bare_t *b, int steps, double *cpu_s);
void sim_bare_destroy(sim_bare_t *b);

#ifdef __cplusplus
}
#endif
#endif
