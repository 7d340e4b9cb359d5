/* The world's own structures and the functions its units share (sim.h is the public face).
 * Private to sim_core: core/, hal_sim/ and nano_link/ include it, nothing else does. Per 1 ms
 * step and car: UART bytes in (pty or scripted driver, paced at the wire rate, nano_link/) ->
 * firmware core (nano_core_rx, nano_core_step with encoder counts, hal_sim/) -> HAL outputs ->
 * servo, Ackermann, motor and tyre forces (core/actuation.c, core/tyre_forces.c) -> mj_step2
 * (core/step.c). */
#ifndef SIM_SIM_INTERNAL_H
#define SIM_SIM_INTERNAL_H

#include <stddef.h>
#include <stdint.h>

#include <mujoco/mujoco.h>

#include "clearance.h"
#include "drive.h"
#include "mjcf_gen.h"
#include "nano_core.h"
#include "ptylink.h"
#include "rng.h"
#include "route_driver.h"
#include "scenario.h"
#include "script.h"
#include "sim.h"
#include "terrain.h"
#include "traffic_lights.h"
#include "tyre.h"
#include "uart.h"
#include "vehicle_params.h"

#include "sim_lidar.h"
#include "sim_rplidar.h"

#define SIM_BUILD_ID 0x51A00001u /* reported in HELLO: "sim" build */
#define SIM_CAR_SPACING_M 0.35   /* cars spawn side by side at this pitch */
#define SIM_CAR_ROW_PITCH_M 0.45 /* and in rows this far behind one another */
#define SIM_PLACES_PER_ROW 16
#define SIM_PLACE_ROWS 8
#define SIM_SPAWN_Z_M 0.002 /* base_link starts this high and settles on its tyres */
/* Parts of the map lower than this are driven over (terrain patches 1 mm, markings), not
 * obstacles, when checking a start pose or a late box [m] */
#define SIM_GROUND_CLEARANCE_M 0.005

enum {
  W_FL = 0,
  W_FR,
  W_RL,
  W_RR,
  W_N
}; /* wheels: front left, front right, rear left, rear right */

#define SIM_LAMPS 9 /* lamp geoms per car (car_lamps.c) */
/* 115200 baud moves 11.5 bytes/ms: 100 ms of Nano output fits, so a batch never drops */
#define SIM_TX_PENDING_BYTES 1152
typedef struct sim_car {
  sim_t *sim;
  int index; /* 1-based */
  /* model addresses */
  int body, root_qpos, root_dof, chassis_geom;
  int wheel_body[W_N], wheel_qpos[W_N], wheel_dof[W_N], tyre_geom[W_N];
  int steer_qpos[2], steer_dof[2];
  int accel_adr, gyro_adr, mag_adr;
  int lamp_geom[SIM_LAMPS]; /* -1 when the model has no such lamp */
  uint8_t lamps_shown;      /* lamp bits last drawn */
  /* tyre contacts recorded after the previous step */
  double fz_n[W_N], mu[W_N], normal[W_N][3], contact_pos[W_N][3];
  int in_collision;
  /* actuator outputs set by the firmware through the HAL */
  uint8_t duty, reverse, brake, lamps;
  uint16_t servo_us;
  double steer_rad; /* servo output shaft, as a centre angle [rad] */
  /* emulated Nano */
  nano_core_t nano;
  nano_core_hal_t hal;
  uart_queue_t rx, tx;
  ptylink_t pty;
  int has_pty, has_script;
  int64_t host_rx_us; /* sim time of the last bytes from the pty's client [us], -1: none yet */
  protocol_parser_t host_parser; /* frames the pty's client wrote, counted as they arrive */
  uint32_t host_frames;
  int host_idle; /* free lockstep: nothing read and the pty refused our bytes last service */
  /* Nano bytes that crossed the wire since the last host-link service, not yet on the pty */
  uint8_t tx_pending[SIM_TX_PENDING_BYTES];
  size_t tx_pending_n;
  script_t script;
  rng_t rng;
  double accel_bias[3], gyro_bias[3];
  sim_lidar_t *lidar;
  sim_rplidar_t *rplidar;
  int lidar_new;
  char lidar_link[512];
} sim_car_t;

struct sim {
  vehicle_params_t p;
  mjModel *m; /* physics: the map without its visual-only geoms */
  mjData *d;
  /* render model: the whole map (road tiles, lamps, sign faces), kept in step with the physics
   * for the cameras, the Eye and the viewer; NULL when the map has no visual-only geoms */
  mjModel *mv;
  mjData *dv;
  int ncars;
  sim_car_t *car;
  int64_t time_us;
  char scene_dir[512], scene_path[600];
  tyre_curve_t lon, lat;
  motor_model_t motor;
  int tyre_paper;
  terrain_t terrain; /* the map's terrain patches; out of the physics model with tyre_paper */
  int host_io_period_steps; /* >= 1: ptys serviced every this many steps */
  int *geom_tyre;           /* per geom: car * W_N + wheel, or -1 */
  int ntag_files;           /* roof tag PNGs that may exist in scene_dir */
  int has_start;
  scn_pose_t start;
  int nbox;
  /* --late-box boxes, then the map's late_obstacles */
  scn_late_box_t box[SIM_MAX_BOXES];
  int box_geom[SIM_MAX_BOXES];         /* its world geom in m, moved through geom_pos */
  int box_geom_v[SIM_MAX_BOXES];       /* the same geom in the render model mv (when split) */
  mjtNum box_parked[SIM_MAX_BOXES][3]; /* where it waits before and after [m] */
  int box_placed[SIM_MAX_BOXES];       /* has appeared */
  int box_new[SIM_MAX_BOXES];          /* appeared during the last step */
  int box_car_below[SIM_MAX_BOXES];    /* car it landed on (1-based), 0: none */
  int64_t box_at_us[SIM_MAX_BOXES];    /* when it appeared [us] */
  int box_gone[SIM_MAX_BOXES];         /* has left again (stay_s) */
  int box_left[SIM_MAX_BOXES];         /* left during the last step */
  int ndistractor; /* --distractors: drawn in sim_draw_distractors, placed after the cars */
  mjcf_gen_distractor_t distractor[SIM_MAX_DISTRACTORS];
  int distractor_geom[SIM_MAX_DISTRACTORS];     /* its world geom in m */
  double distractor_xy[SIM_MAX_DISTRACTORS][2]; /* where it stands [m] */
  int ndistractor_keep_clear; /* sim_config_t's distractor_keep_clear poses, copied */
  scn_pose_t distractor_keep_clear[2 * SIM_MAX_CARS];
  uint64_t seed;         /* of the current run (sim_create, sim_reset) */
  char script_spec[256]; /* every car's scripted driver, "" for none */
  int lidar, lidar_on_request, lidar_rays;
  int accel_wanted;      /* sim_want_accel: the next step computes the accelerometer */
  traffic_lights_t tl;   /* the map's lights (traffic_lights.h) */
  route_driver_t *route; /* --script route:NAME (car 1), else NULL */
};

/* ---- functions shared between the world's units ----------------------------------------- */
/* hal_sim/sim_hal.c: the firmware HAL on the sim, and the firmware's turn in a step */
void sim_hal_bind(sim_car_t *c);
void sim_nano_step(sim_t *s, sim_car_t *c);

/* car_binding.c, car_lamps.c: model addresses of a car's parts; its lamps' colours */
int sim_bind_car(sim_t *s, sim_car_t *c, char *err, size_t err_sz);
void sim_bind_lamps(sim_t *s, sim_car_t *c);
void sim_draw_lamps(sim_t *s, sim_car_t *c);

/* car_placement.c: start poses and the footprints the scenario checks test */
void sim_set_car_pose(sim_t *s, int i, const double base[3], double yaw, int row, int col);
int sim_place_cars(sim_t *s, char *err, size_t err_sz);
void sim_car_prism(const sim_t *s, int i, clearance_prism_t *out);
/* The same with base_link at x_m, y_m, z_m [m], heading yaw [rad]. */
void sim_car_prism_at(const sim_t *s, double x_m, double y_m, double z_m, double yaw,
                      clearance_prism_t *out);
void sim_box_prism(const scn_late_box_t *b, clearance_prism_t *out);

/* distractors.c: --distractors, their kinds and sizes before the scene is written, their
 * places once the cars stand */
void sim_draw_distractors(sim_t *s, const sim_config_t *cfg);
int sim_place_distractors(sim_t *s, char *err, size_t err_sz);

/* late_boxes.c */
int sim_read_map_late_boxes(sim_t *s, const mjModel *mm, const char *path, char *err,
                            size_t err_sz);
int sim_bind_late_boxes(sim_t *s, char *err, size_t err_sz);
void sim_place_late_boxes(sim_t *s);
void sim_reset_late_boxes(sim_t *s);

/* scene_load.c: the generated scene, its physics twin, the models and data */
int sim_fail(char *err, size_t err_sz, const char *fmt, const char *a, const char *b);
int sim_load_model(sim_t *s, const sim_config_t *cfg, char *err, size_t err_sz);

/* car_setup.c */
int sim_car_boot(sim_t *s, sim_car_t *c, char *err, size_t err_sz);
int sim_setup_car(sim_t *s, const sim_config_t *cfg, sim_car_t *c, char *err, size_t err_sz);

/* nano_link/host_link.c: the client on the Nano pty and the in-process scripted driver */
/* Free lockstep (a host I/O period > 1 ms): while nobody is on the pty (nothing read, and the
 * pty's buffer full so our last bytes were refused) it is served only every
 * SIM_HOST_IDLE_PERIOD_MS, saving two system calls per period; a client's first bytes are then
 * seen within that time, and the next service that moves bytes ends the idle state. The
 * RPLIDAR pty nobody scans on is served at this period too (step.c). */
#define SIM_HOST_IDLE_PERIOD_MS 100
int sim_host_io_due(const sim_t *s);
void sim_read_host(sim_t *s, sim_car_t *c);
typedef struct sim_host_turn {
  int io_due;             /* this car's pty is serviced in this step */
  uint32_t frames_before; /* the client's frames and last bytes before the step's read */
  int64_t rx_before_us;
} sim_host_turn_t;
void sim_host_receive(sim_t *s, sim_car_t *c, int io_due_all, sim_host_turn_t *turn);
void sim_script_feed(sim_t *s, sim_car_t *c);
void sim_host_send(sim_t *s, sim_car_t *c, const sim_host_turn_t *turn);

/* actuation.c, tyre_forces.c, contacts.c */
void sim_actuate(sim_t *s, sim_car_t *c);
void sim_tyres(sim_t *s, sim_car_t *c);
void sim_record_contacts(sim_t *s);

#endif
