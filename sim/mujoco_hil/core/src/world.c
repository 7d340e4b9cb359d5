/* Simulator core (see sim.h). Per 1 ms step and car: UART bytes in (pty or scripted driver,
 * paced at the wire rate) -> firmware core (nigel_rx, nigel_step with encoder counts) -> HAL
 * outputs -> servo, Ackermann, motor and tyre forces -> mj_step2. */
#include "sim.h"

#include <errno.h>
#include <math.h>
#include <poll.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "clearance.h"
#include "drive.h"
#include "enc.h"
#include "mjcf_gen.h"
#include "ptylink.h"
#include "rng.h"
#include "route_driver.h"
#include "script.h"
#include "terrain.h"
#include "traffic_lights.h"
#include "tyre.h"
#include "uart.h"
#include "vehicle_params.h"

#include "sim_lidar.h"
#include "sim_rplidar.h"
#include "sim_tags.h"

#define SIM_G_M_S2 9.80665
#define SIM_BUILD_ID 0x51A00001u /* reported in HELLO: "sim" build */
#define SIM_CAR_SPACING_M 0.35   /* cars spawn side by side at this pitch */
#define SIM_CAR_ROW_PITCH_M 0.45 /* and in rows this far behind one another */
#define SIM_PLACES_PER_ROW 16
#define SIM_PLACE_ROWS 8
#define SIM_SPAWN_Z_M 0.002 /* base_link starts this high and settles on its tyres */
/* Parts of the map lower than this are driven over (terrain patches 1 mm, markings), not
 * obstacles, when checking a start pose or a late box [m] */
#define SIM_GROUND_CLEARANCE_M 0.005

enum { W_FL = 0, W_FR, W_RL, W_RR, W_N };

/* Lamp geoms and the NIGEL_LAMP_* bit and colours that drive each. */
#define SIM_LAMPS 9
/* 115200 baud moves 11.5 bytes/ms: 100 ms of Nano output fits, so a batch never drops */
#define SIM_TX_PENDING_BYTES 1152
static const struct {
  const char *name;
  uint8_t bits;
  float on[3], off[3];
} sim_lamp[SIM_LAMPS] = {
    {"lamp_head_l",
     NIGEL_LAMP_HEAD_LOW | NIGEL_LAMP_HEAD_HIGH,
     {1, 1, 0.85f},
     {0.25f, 0.25f, 0.22f}},
    {"lamp_head_r",
     NIGEL_LAMP_HEAD_LOW | NIGEL_LAMP_HEAD_HIGH,
     {1, 1, 0.85f},
     {0.25f, 0.25f, 0.22f}},
    {"lamp_ind_fl", NIGEL_LAMP_IND_LEFT, {1, 0.55f, 0}, {0.3f, 0.18f, 0.05f}},
    {"lamp_ind_fr", NIGEL_LAMP_IND_RIGHT, {1, 0.55f, 0}, {0.3f, 0.18f, 0.05f}},
    {"lamp_tail_l", NIGEL_LAMP_TAIL, {1, 0, 0}, {0.3f, 0.02f, 0.02f}},
    {"lamp_tail_r", NIGEL_LAMP_TAIL, {1, 0, 0}, {0.3f, 0.02f, 0.02f}},
    {"lamp_ind_rl", NIGEL_LAMP_IND_LEFT, {1, 0.55f, 0}, {0.3f, 0.18f, 0.05f}},
    {"lamp_ind_rr", NIGEL_LAMP_IND_RIGHT, {1, 0.55f, 0}, {0.3f, 0.18f, 0.05f}},
    {"lamp_reverse", NIGEL_LAMP_REVERSE, {1, 1, 1}, {0.25f, 0.25f, 0.25f}},
};

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
  nigel_t nano;
  nigel_hal_t hal;
  uart_queue_t rx, tx;
  ptylink_t pty;
  int has_pty, has_script;
  int64_t host_rx_us; /* sim time of the last bytes from the pty's client [us], -1: none yet */
  proto_parser_t host_parser; /* frames the pty's client wrote, counted as they arrive */
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
  uint64_t seed;                       /* of the current run (sim_create, sim_reset) */
  char script_spec[256];               /* every car's scripted driver, "" for none */
  int lidar, lidar_on_request, lidar_rays;
  int accel_wanted;      /* sim_want_accel: the next step computes the accelerometer */
  traffic_lights_t tl;   /* the map's lights (traffic_lights.h) */
  route_driver_t *route; /* --script route:NAME (car 1), else NULL */
};

/* ---- sim HAL: what the firmware core sees as hardware --------------------------------- */
static void hal_motor_set(void *ctx, uint8_t duty, uint8_t reverse, uint8_t brake) {
  sim_car_t *c = ctx;
  c->duty = duty;
  c->reverse = reverse;
  c->brake = brake;
}

static void hal_servo_set_us(void *ctx, uint16_t pulse_us) {
  ((sim_car_t *)ctx)->servo_us = pulse_us;
}

static void hal_lamps_set(void *ctx, uint8_t lamps) {
  ((sim_car_t *)ctx)->lamps = lamps;
}

static int16_t sim_sat16(double v) {
  if (v > 32767.0) return 32767;
  if (v < -32768.0) return -32768;
  return (int16_t)lround(v);
}

/* MPU-9250 sample from MuJoCo's accelerometer/gyro/magnetometer at the IMU site (car axes:
 * x forward, y left, z up), plus the car's bias and white noise, in the chip's LSB. */
static int hal_imu_read(void *ctx, nigel_imu_raw_t *out) {
  sim_car_t *c = ctx;
  const sim_t *s = c->sim;
  const mjtNum *sd = s->d->sensordata;
  for (int k = 0; k < 3; k++) {
    const double a =
        sd[c->accel_adr + k] + c->accel_bias[k] + rng_gauss(&c->rng, s->p.accel_noise_m_s2);
    const double w =
        sd[c->gyro_adr + k] + c->gyro_bias[k] + rng_gauss(&c->rng, s->p.gyro_noise_rad_s);
    const double b = sd[c->mag_adr + k] + rng_gauss(&c->rng, s->p.mag_noise_ut);
    out->accel[k] = sim_sat16(a / SIM_G_M_S2 * PROTO_ACCEL_LSB_PER_G);
    out->gyro[k] = sim_sat16(w * (180.0 / M_PI) * PROTO_GYRO_LSB_PER_DPS);
    out->mag[k] = sim_sat16(b / PROTO_MAG_UT_PER_LSB);
  }
  return 0;
}

static uint16_t hal_battery_read_mv(void *ctx) {
  sim_car_t *c = ctx;
  const double v = c->sim->p.battery_v + rng_gauss(&c->rng, c->sim->p.battery_noise_v);
  return (uint16_t)lround(fmax(0.0, v) * 1000.0);
}

static void hal_serial_write(void *ctx, const uint8_t *data, uint8_t n) {
  uart_push(&((sim_car_t *)ctx)->tx, data, n);
}

/* ---- model binding ---------------------------------------------------------------------- */
static int sim_id(const mjModel *m, int type, int car, const char *part, char *err, size_t err_sz) {
  char name[64];
  snprintf(name, sizeof name, "nigel%d/%s", car, part);
  const int id = mj_name2id(m, type, name);
  if (id < 0) snprintf(err, err_sz, "generated model lacks '%s'", name);
  return id;
}

static int sim_bind_car(sim_t *s, sim_car_t *c, char *err, size_t err_sz) {
  const mjModel *m = s->m;
  static const char *wn[W_N] = {"fl", "fr", "rl", "rr"};
  char part[32];
  if ((c->body = sim_id(m, mjOBJ_BODY, c->index, "base_link", err, err_sz)) < 0) return -1;
  int j = sim_id(m, mjOBJ_JOINT, c->index, "root", err, err_sz);
  if (j < 0) return -1;
  c->root_qpos = m->jnt_qposadr[j];
  c->root_dof = m->jnt_dofadr[j];
  if ((c->chassis_geom = sim_id(m, mjOBJ_GEOM, c->index, "chassis", err, err_sz)) < 0) return -1;
  for (int w = 0; w < W_N; w++) {
    snprintf(part, sizeof part, "wheel_%s", wn[w]);
    if ((c->wheel_body[w] = sim_id(m, mjOBJ_BODY, c->index, part, err, err_sz)) < 0) return -1;
    if ((j = sim_id(m, mjOBJ_JOINT, c->index, part, err, err_sz)) < 0) return -1;
    c->wheel_qpos[w] = m->jnt_qposadr[j];
    c->wheel_dof[w] = m->jnt_dofadr[j];
    snprintf(part, sizeof part, "tyre_%s", wn[w]);
    if ((c->tyre_geom[w] = sim_id(m, mjOBJ_GEOM, c->index, part, err, err_sz)) < 0) return -1;
    s->geom_tyre[c->tyre_geom[w]] = (c->index - 1) * W_N + w;
  }
  for (int w = 0; w < 2; w++) {
    snprintf(part, sizeof part, "steer_%s", wn[w]);
    if ((j = sim_id(m, mjOBJ_JOINT, c->index, part, err, err_sz)) < 0) return -1;
    c->steer_qpos[w] = m->jnt_qposadr[j];
    c->steer_dof[w] = m->jnt_dofadr[j];
  }
  for (int k = 0; k < SIM_LAMPS; k++) { /* optional: older scenes may lack lamps */
    char name[64];
    snprintf(name, sizeof name, "nigel%d/%s", c->index, sim_lamp[k].name);
    c->lamp_geom[k] = mj_name2id(s->mv ? s->mv : m, mjOBJ_GEOM, name); /* drawn there */
  }
  c->lamps_shown = 0xFF; /* draw on the first step */
  static const char *sn[3] = {"accel", "gyro", "mag"};
  int *adr[3] = {&c->accel_adr, &c->gyro_adr, &c->mag_adr};
  for (int k = 0; k < 3; k++) {
    const int id = sim_id(m, mjOBJ_SENSOR, c->index, sn[k], err, err_sz);
    if (id < 0) return -1;
    *adr[k] = m->sensor_adr[id];
  }
  return 0;
}

static void sim_set_car_pose(sim_t *s, int i, const double base[3], double yaw, int row, int col) {
  mjtNum *qp = s->d->qpos + s->car[i].root_qpos;
  const double right = -SIM_CAR_SPACING_M * col, back = -SIM_CAR_ROW_PITCH_M * row;
  qp[0] = base[0] + back * cos(yaw) - right * sin(yaw);
  qp[1] = base[1] + back * sin(yaw) + right * cos(yaw);
  qp[2] = SIM_SPAWN_Z_M;
  qp[3] = cos(0.5 * yaw);
  qp[4] = qp[5] = 0.0;
  qp[6] = sin(0.5 * yaw);
  mju_copy(s->m->qpos0 + s->car[i].root_qpos, qp, 7);
}

static void sim_car_prism(const sim_t *s, int i, cl_prism_t *out);

/* Car 1 stands at --start, else at the map's "spawn" site (or the origin); the others side
 * by side to its right. With --start they stay in that one row and sim_check_scenario judges
 * it; at the spawn site a car that would stand on a wall, an obstacle or off the floor takes
 * the next free place, in rows behind car 1 when a row is full. The model's qpos0 gets the
 * same poses, so a reset (mj_resetData, the viewer's R) puts the cars back where they
 * started. Returns 0, or -1 when a car finds no place. */
static int sim_place_cars(sim_t *s, char *err, size_t err_sz) {
  double base[3] = {0, 0, 0}, yaw = 0.0;
  const int site = mj_name2id(s->m, mjOBJ_SITE, "spawn");
  if (s->has_start) {
    base[0] = s->start.x_m;
    base[1] = s->start.y_m;
    yaw = s->start.yaw_deg * (M_PI / 180.0);
  } else if (site >= 0) {
    mju_copy3(base, s->m->site_pos + 3 * site);
    const mjtNum *q = s->m->site_quat + 4 * site;
    yaw = atan2(2.0 * (q[0] * q[3] + q[1] * q[2]), 1.0 - 2.0 * (q[2] * q[2] + q[3] * q[3]));
  }
  if (s->has_start) {
    for (int i = 0; i < s->ncars; i++) sim_set_car_pose(s, i, base, yaw, 0, i);
    return 0;
  }
  mj_kinematics(s->m, s->d); /* the static geoms' poses, for the clearance check */
  const mjModel *m = s->m;
  const int ct = m->geom_contype[s->car[0].chassis_geom],
            ca = m->geom_conaffinity[s->car[0].chassis_geom];
  int place = 0; /* next place to try: row place / SIM_PLACES_PER_ROW, column the rest */
  for (int i = 0; i < s->ncars; i++) {
    for (;; place++) {
      if (place >= SIM_PLACES_PER_ROW * SIM_PLACE_ROWS) {
        snprintf(err, err_sz,
                 "no room for NIGEL%d: %d rows of %d places from the map's spawn site are taken "
                 "or blocked (fewer --cars, or --start elsewhere)",
                 i + 1, SIM_PLACE_ROWS, SIM_PLACES_PER_ROW);
        return -1;
      }
      sim_set_car_pose(s, i, base, yaw, place / SIM_PLACES_PER_ROW, place % SIM_PLACES_PER_ROW);
      cl_prism_t pr;
      sim_car_prism(s, i, &pr);
      char why[512];
      if (cl_check_on_map(m, s->d, &pr, ct, ca, why, sizeof why) == 0) break;
    }
    place++;
  }
  return 0;
}

/* The upright prism around car i's chassis and wheels at its current pose. */
static void sim_car_prism(const sim_t *s, int i, cl_prism_t *out) {
  const vehicle_params_t *p = &s->p;
  const double *co = p->chassis_offset_m, *cs = p->chassis_size_m;
  const double r = p->wheel_radius_m, wy = 0.5 * (p->track_m + p->wheel_width_m);
  const double x0 = fmin(co[0] - 0.5 * cs[0], -r),
               x1 = fmax(co[0] + 0.5 * cs[0], p->wheelbase_m + r);
  const double y0 = fmin(co[1] - 0.5 * cs[1], -wy), y1 = fmax(co[1] + 0.5 * cs[1], wy);
  const mjtNum *qp = s->d->qpos + s->car[i].root_qpos;
  const double yaw =
      atan2(2.0 * (qp[3] * qp[6] + qp[4] * qp[5]), 1.0 - 2.0 * (qp[5] * qp[5] + qp[6] * qp[6]));
  const double cx = 0.5 * (x0 + x1), cy = 0.5 * (y0 + y1); /* in the car's frame */
  out->centre_m[0] = qp[0] + cos(yaw) * cx - sin(yaw) * cy;
  out->centre_m[1] = qp[1] + sin(yaw) * cx + cos(yaw) * cy;
  out->yaw_rad = yaw;
  out->half_m[0] = 0.5 * (x1 - x0);
  out->half_m[1] = 0.5 * (y1 - y0);
  out->z_lo_m = SIM_GROUND_CLEARANCE_M;
  out->z_hi_m = qp[2] + co[2] + 0.5 * cs[2];
}

static void sim_box_prism(const scn_late_box_t *b, cl_prism_t *out) {
  out->centre_m[0] = b->x_m;
  out->centre_m[1] = b->y_m;
  out->yaw_rad = b->yaw_rad;
  out->half_m[0] = b->half_x_m;
  out->half_m[1] = b->half_y_m;
  out->z_lo_m = SIM_GROUND_CLEARANCE_M;
  out->z_hi_m = 2.0 * scn_late_box_half_z(b);
}

int sim_check_scenario(const sim_t *s, char *err, size_t err_sz) {
  const mjModel *m = s->m;
  const int ct = m->geom_contype[s->car[0].chassis_geom],
            ca = m->geom_conaffinity[s->car[0].chassis_geom];
  char why[512];
  cl_prism_t pr;
  for (int i = 0; s->has_start && i < s->ncars; i++) {
    sim_car_prism(s, i, &pr);
    if (cl_check_on_map(m, s->d, &pr, ct, ca, why, sizeof why) == 0) continue;
    const mjtNum *qp = s->d->qpos + s->car[i].root_qpos;
    char who[96] = "";
    if (i > 0)
      snprintf(who, sizeof who, " (%.2f m to the right of NIGEL1 with --cars %d)",
               SIM_CAR_SPACING_M * i, s->ncars);
    snprintf(err, err_sz, "--start '%g,%g,%g': NIGEL%d%s at x %.3f, y %.3f m %s", s->start.x_m,
             s->start.y_m, s->start.yaw_deg, i + 1, who, qp[0], qp[1], why);
    return -1;
  }
  for (int k = 0; k < s->nbox; k++) {
    const scn_late_box_t *b = &s->box[k];
    sim_box_prism(b, &pr);
    if (cl_check_on_map(m, s->d, &pr, ct, ca, why, sizeof why) == 0) continue;
    if (b->name[0])
      snprintf(err, err_sz, "map late obstacle '%s' at x %g, y %g m: the box %s", b->name, b->x_m,
               b->y_m, why);
    else
      snprintf(err, err_sz, "--late-box '%g,%g,%g,%g,%g': the box %s", b->x_m, b->y_m, b->t_s,
               b->half_x_m, b->half_y_m, why);
    return -1;
  }
  return 0;
}

/* A late box is a world geom, moved by its model position: MuJoCo's kinematics recompute world
 * geoms each step, and a world geom costs the step far less than a (mocap) body would. */
static void sim_move_late_box(sim_t *s, int k, const mjtNum pos_m[3]) {
  mju_copy3(s->m->geom_pos + 3 * s->box_geom[k], pos_m);
  if (s->mv) mju_copy3(s->mv->geom_pos + 3 * s->box_geom_v[k], pos_m);
}

static void sim_park_late_boxes(sim_t *s) {
  for (int k = 0; k < s->nbox; k++) sim_move_late_box(s, k, s->box_parked[k]);
}

/* Moves the late boxes that are due onto the floor (again after a reset). */
static void sim_place_late_boxes(sim_t *s) {
  for (int k = 0; k < s->nbox; k++) {
    s->box_new[k] = s->box_left[k] = 0;
    const scn_late_box_t *b = &s->box[k];
    if (s->box_gone[k] || s->time_us < (int64_t)llround(b->t_s * 1e6)) continue;
    if (!s->box_placed[k] && b->near_m > 0) { /* a box that steps out as the car comes near */
      const mjtNum *car = s->d->qpos + s->car[0].root_qpos;
      if (hypot(car[0] - b->x_m, car[1] - b->y_m) > b->near_m) continue;
    }
    if (s->box_placed[k] && b->stay_s > 0 &&
        s->time_us - s->box_at_us[k] >= (int64_t)llround(b->stay_s * 1e6)) {
      sim_move_late_box(s, k, s->box_parked[k]); /* back where it waited */
      s->box_gone[k] = s->box_left[k] = 1;
      continue;
    }
    if (s->box_placed[k]) continue;
    const mjtNum pos[3] = {b->x_m, b->y_m, scn_late_box_half_z(b)};
    sim_move_late_box(s, k, pos);
    s->box_placed[k] = s->box_new[k] = 1;
    s->box_at_us[k] = s->time_us;
    cl_prism_t bp, cp;
    sim_box_prism(b, &bp);
    for (int i = 0; i < s->ncars && !s->box_car_below[k]; i++) {
      sim_car_prism(s, i, &cp);
      if (cl_prisms_overlap(&bp, &cp)) s->box_car_below[k] = i + 1;
    }
  }
}

static int sim_bind_late_boxes(sim_t *s, char *err, size_t err_sz) {
  for (int k = 0; k < s->nbox; k++) {
    char name[48];
    snprintf(name, sizeof name, "scenario/late_box%d", k + 1);
    const int g = mj_name2id(s->m, mjOBJ_GEOM, name);
    const int gv = s->mv ? mj_name2id(s->mv, mjOBJ_GEOM, name) : -1;
    if (g < 0 || s->m->geom_bodyid[g] != 0 || (s->mv && gv < 0)) {
      snprintf(err, err_sz, "generated model lacks world geom '%s'", name);
      return -1;
    }
    s->box_geom[k] = g;
    s->box_geom_v[k] = gv;
    mju_copy3(s->box_parked[k], s->m->geom_pos + 3 * g);
  }
  return 0;
}

/* ---- setup --------------------------------------------------------------------------- */
static int sim_fail(char *err, size_t err_sz, const char *fmt, const char *a, const char *b) {
  snprintf(err, err_sz, fmt, a, b);
  return -1;
}

/* The map's late_obstacles (tools/gen-maps writes each as the custom numeric late_<name>:
 * x y yaw [m, rad], full sizes x y z [m], appear_s [s] or 0, trigger_radius_m [m] or 0) join
 * the --late-box boxes, after them. */
static int sim_read_map_late_boxes(sim_t *s, const mjModel *mm, const char *path, char *err,
                                   size_t err_sz) {
  int found = 0;
  for (int i = 0; i < mm->nnumeric; i++) {
    const char *name = mm->names + mm->name_numericadr[i];
    if (strncmp(name, "late_", 5) != 0) continue;
    if (++found > SCN_MAX_MAP_LATE_BOXES) {
      snprintf(err, err_sz, "map file '%s': more than %d late obstacles", path,
               SCN_MAX_MAP_LATE_BOXES);
      return -1;
    }
    const mjtNum *v = mm->numeric_data + mm->numeric_adr[i];
    if (mm->numeric_size[i] != 8 || !(v[3] > 0 && v[4] > 0 && v[5] > 0) || v[6] < 0 || v[7] < 0) {
      snprintf(err, err_sz,
               "map file '%s': numeric '%s' must be x y yaw sx sy sz appear_s trigger_radius_m "
               "(sizes > 0, times and radius >= 0)",
               path, name);
      return -1;
    }
    scn_late_box_t *b = &s->box[s->nbox++];
    memset(b, 0, sizeof *b);
    snprintf(b->name, sizeof b->name, "%s", name + 5);
    b->x_m = v[0];
    b->y_m = v[1];
    b->yaw_rad = v[2];
    b->half_x_m = 0.5 * v[3];
    b->half_y_m = 0.5 * v[4];
    b->half_z_m = 0.5 * v[5];
    b->t_s = v[6];
    b->near_m = v[7];
  }
  return 0;
}

/* The map alone must compile: its errors then name the map file, not the generated scene. It
 * gives the terrain patches and, with late_boxes, the map's late obstacles. */
static int sim_check_map(sim_t *s, const char *path, int late_boxes, char *err, size_t err_sz) {
  if (access(path, R_OK) != 0)
    return sim_fail(err, err_sz, "map file '%s': %s", path, strerror(errno));
  char merr[1000] = "";
  mjModel *mm = mj_loadXML(path, NULL, merr, sizeof merr);
  if (!mm) return sim_fail(err, err_sz, "bad map file '%s': %s", path, merr);
  int rc = terrain_load(&s->terrain, mm, path, err, err_sz);
  if (rc == 0 && late_boxes) rc = sim_read_map_late_boxes(s, mm, path, err, err_sz);
  mj_deleteModel(mm);
  return rc;
}

/* Writes the roof tag PNGs into the scene dir and collects their MJCF snippets. */
static int sim_tag_snippets(sim_t *s, int cars, char **asset, char ***geoms, char *err,
                            size_t err_sz) {
  const size_t asz = 1024;
  *asset = calloc((size_t)cars, asz);
  *geoms = calloc((size_t)cars, sizeof(char *));
  if (!*asset || !*geoms) return sim_fail(err, err_sz, "%s%s", "out of memory", "");
  for (int i = 1; i <= cars; i++) {
    char png[700], file[64], prefix[32], a[asz];
    snprintf(file, sizeof file, "tag36h11_%d.png", mg_tag_id(i));
    snprintf(png, sizeof png, "%s/%s", s->scene_dir, file);
    if (sim_tags_write_png(png, mg_tag_id(i), 8, err, err_sz) != 0) return -1;
    snprintf(prefix, sizeof prefix, "nigel%d/", i);
    (*geoms)[i - 1] = malloc(1024);
    /* the tag's PNG by its absolute path: the scene's texturedir is the map's folder (its
     * textures), and the run dir may be given relative */
    char abs_png[4096];
    if (!realpath(png, abs_png))
      return sim_fail(err, err_sz, "roof tag '%s': %s", png, strerror(errno));
    if (!(*geoms)[i - 1] ||
        sim_tags_mjcf(prefix, abs_png, s->p.tag_size_m, a, sizeof a, (*geoms)[i - 1], 1024) != 0)
      return sim_fail(err, err_sz, "%s%s", "roof tag MJCF did not fit its buffer", "");
    strcat(*asset, a);
    strcat(*asset, "\n");
  }
  return 0;
}

static int sim_load_model(sim_t *s, const sim_config_t *cfg, char *err, size_t err_sz) {
  char map_abs[4096];
  if (!realpath(cfg->map_path, map_abs))
    return sim_fail(err, err_sz, "map file '%s': %s", cfg->map_path, strerror(errno));
  if (sim_check_map(s, map_abs, !cfg->no_map_late_boxes, err, err_sz) != 0) return -1;
  mg_options_t o = {cfg->cars, NULL, NULL, NULL, s->nbox, s->box, NULL, 0};
  o.map_path = map_abs;
  char *asset = NULL, **geoms = NULL;
  int rc = sim_tag_snippets(s, cfg->cars, &asset, &geoms, err, err_sz);
  o.tag_asset_xml = asset;
  o.tag_geom_xml = (const char *const *)geoms;
  if (rc == 0) rc = mg_write_scene(s->scene_path, &s->p, &o, err, err_sz);
  /* the physics scene: the same with a copy of the map without visual-only geoms */
  char map_dir[4096], phys_map[700], phys_scene[700];
  snprintf(map_dir, sizeof map_dir, "%s", map_abs);
  char *slash = strrchr(map_dir, '/');
  if (slash) slash[1] = '\0';
  snprintf(phys_map, sizeof phys_map, "%s/map_physics.xml", s->scene_dir);
  snprintf(phys_scene, sizeof phys_scene, "%s/scene_physics.xml", s->scene_dir);
  int dropped = 0;
  /* the paper tyres read the terrain's friction from s->terrain: its geoms need not collide */
  const char *drop = s->tyre_paper ? s->terrain.names : NULL;
  if (rc == 0 && (dropped = mg_write_physics_map(map_abs, phys_map, drop, err, err_sz)) < 0)
    rc = -1;
  if (rc == 0 && dropped > 0) {
    mg_options_t po = o;
    po.map_path = phys_map;
    po.texture_dir = map_dir;
    po.physics_only = 1;
    rc = mg_write_scene(phys_scene, &s->p, &po, err, err_sz);
  }
  if (geoms)
    for (int i = 0; i < cfg->cars; i++) free(geoms[i]);
  free(geoms);
  free(asset);
  if (rc != 0) return -1;
  char merr[1000] = "";
  s->m = mj_loadXML(s->scene_path, NULL, merr, sizeof merr);
  if (!s->m)
    return sim_fail(err, err_sz, "generated scene '%s' does not compile: %s", s->scene_path, merr);
  if (dropped > 0) {
    mjModel *pm = mj_loadXML(phys_scene, NULL, merr, sizeof merr);
    /* the same bodies and joints (only geoms left out), or no split at all */
    if (pm && pm->nq == s->m->nq && pm->nv == s->m->nv && pm->nbody == s->m->nbody &&
        pm->nmocap == s->m->nmocap) {
      s->mv = s->m;
      s->m = pm;
      s->dv = mj_makeData(s->mv);
      if (!s->dv) return sim_fail(err, err_sz, "%s%s", "mj_makeData failed (out of memory)", "");
    } else if (pm) {
      mj_deleteModel(pm);
    }
  }
  s->d = mj_makeData(s->m);
  if (!s->d) return sim_fail(err, err_sz, "%s%s", "mj_makeData failed (out of memory)", "");
  return 0;
}

/* A car at power-on: actuators idle, UARTs empty, the firmware freshly booted, its noise and
 * biases drawn from (seed, car), its scripted driver at its first frame, its LIDAR head (with
 * its own noise seed) at the start of a revolution. sim_create and sim_reset share it. */
static int sim_car_boot(sim_t *s, sim_car_t *c, char *err, size_t err_sz) {
  memset(c->fz_n, 0, sizeof c->fz_n);
  memset(c->mu, 0, sizeof c->mu);
  memset(c->normal, 0, sizeof c->normal);
  memset(c->contact_pos, 0, sizeof c->contact_pos);
  c->in_collision = 0;
  c->duty = c->reverse = c->lamps = 0;
  c->brake = 1;
  c->servo_us = 1500;
  c->steer_rad = 0.0;
  c->lamps_shown = 0xFF; /* draw on the first step */
  c->tx_pending_n = 0;
  c->host_idle = 0;
  c->lidar_new = 0;
  uart_init(&c->rx, PROTO_BAUD);
  uart_init(&c->tx, PROTO_BAUD);
  /* every car draws its own biases and noise from (seed, car) */
  rng_seed(&c->rng, s->seed * 1000003ull + (uint64_t)c->index);
  for (int k = 0; k < 3; k++) {
    c->accel_bias[k] = (2.0 * rng_uniform(&c->rng) - 1.0) * s->p.accel_bias_m_s2;
    c->gyro_bias[k] = (2.0 * rng_uniform(&c->rng) - 1.0) * s->p.gyro_bias_rad_s;
  }
  if (s->script_spec[0]) {
    if (script_parse(&c->script, s->script_spec, err, err_sz) != 0) return -1;
    c->has_script = 1;
  }
  if (s->lidar) {
    sim_lidar_config_t lc;
    sim_lidar_config_default(&lc);
    mju_copy3(lc.mount_pos_m, s->p.lidar_pos_m);
    lc.seed = s->seed * 7919ull + (uint64_t)c->index;
    if (s->lidar_rays > 0) lc.num_rays = s->lidar_rays;
    char body[32];
    snprintf(body, sizeof body, "nigel%d/base_link", c->index);
    sim_lidar_destroy(c->lidar);
    c->lidar = sim_lidar_create(s->m, body, &lc, err, err_sz);
    if (!c->lidar) return -1;
  }
  nigel_init(&c->nano, &c->hal, 0, 0, SIM_BUILD_ID);
  return 0;
}

static int sim_setup_car(sim_t *s, const sim_config_t *cfg, sim_car_t *c, char *err,
                         size_t err_sz) {
  c->sim = s;
  c->hal.ctx = c;
  c->hal.motor_set = hal_motor_set;
  c->hal.servo_set_us = hal_servo_set_us;
  c->hal.lamps_set = hal_lamps_set;
  c->hal.imu_read = hal_imu_read;
  c->hal.battery_read_mv = hal_battery_read_mv;
  c->hal.serial_write = hal_serial_write;
  if (cfg->open_ptys) {
    char link[512];
    snprintf(link, sizeof link, "%s/nigel%d-nano", cfg->run_dir, c->index);
    if (ptylink_open(&c->pty, link, err, err_sz) != 0) return -1;
    c->has_pty = 1;
    c->host_rx_us = -1;
    proto_parser_init(&c->host_parser);
  }
  if (sim_car_boot(s, c, err, err_sz) != 0) return -1;
  if (cfg->lidar && cfg->open_ptys) {
    snprintf(c->lidar_link, sizeof c->lidar_link, "%s/nigel%d-lidar", cfg->run_dir, c->index);
    c->rplidar = sim_rplidar_create(c->lidar_link, SIM_RPLIDAR_BAUD, err, err_sz);
    if (!c->rplidar) return -1;
  }
  return 0;
}

int sim_lidar_pty_scanning(const sim_t *s, int car) {
  const sim_car_t *c = &s->car[car - 1];
  return c->rplidar ? sim_rplidar_scanning(c->rplidar) : 0;
}

int sim_late_boxes(const sim_t *s) {
  return s->nbox;
}
const scn_late_box_t *sim_late_box(const sim_t *s, int k) {
  return &s->box[k];
}
int sim_late_box_appeared(const sim_t *s, int k, int *car_below) {
  if (car_below) *car_below = s->box_car_below[k];
  return s->box_new[k];
}
int sim_late_box_left(const sim_t *s, int k) {
  return s->box_left[k];
}

/* --script route:NAME: the route driver of car 1, which starts at the route's start unless
 * --start says otherwise. */
static int sim_bind_route(sim_t *s, const sim_config_t *cfg, char *err, size_t err_sz) {
  if (!cfg->script) return 0;
  script_t sc;
  if (script_parse(&sc, cfg->script, err, err_sz) != 0) return -1;
  if (!sc.route) return 0;
  if (cfg->cars != 1) {
    snprintf(err, err_sz, "--script '%s': a route driver drives one car (--cars 1, got %d)",
             cfg->script, cfg->cars);
    return -1;
  }
  s->route = calloc(1, sizeof *s->route);
  if (!s->route) return sim_fail(err, err_sz, "%s%s", "out of memory", "");
  if (route_driver_init(s->route, s->m, sc.route_name, sc.throttle, sc.lookahead_m, sc.lane_shift,
                        err, err_sz) != 0) {
    free(s->route);
    s->route = NULL;
    return -1;
  }
  route_driver_set_laps_perturb(s->route, sc.laps, sc.perturb, cfg->seed);
  if (!s->has_start) {
    double yaw;
    route_driver_start(s->route, &s->start.x_m, &s->start.y_m, &yaw);
    s->start.yaw_deg = yaw * (180.0 / M_PI);
    s->has_start = 1;
  }
  return 0;
}

sim_t *sim_create(const sim_config_t *cfg, char *err, size_t err_sz) {
  if (cfg->cars < 1 || cfg->cars > SIM_MAX_CARS) {
    snprintf(err, err_sz, "--cars %d: must be 1..%d", cfg->cars, SIM_MAX_CARS);
    return NULL;
  }
  if (cfg->late_boxes < 0 || cfg->late_boxes > SCN_MAX_LATE_BOXES) {
    snprintf(err, err_sz, "--late-box: at most %d boxes (got %d)", SCN_MAX_LATE_BOXES,
             cfg->late_boxes);
    return NULL;
  }
  sim_t *s = calloc(1, sizeof *s);
  if (!s) return NULL;
  if (cfg->start) {
    s->has_start = 1;
    s->start = *cfg->start;
  }
  s->nbox = cfg->late_boxes;
  for (int k = 0; k < s->nbox; k++) s->box[k] = cfg->late_box[k];
  s->seed = cfg->seed;
  s->lidar = cfg->lidar;
  s->lidar_on_request = cfg->lidar_on_request;
  s->lidar_rays = cfg->lidar_rays;
  if (cfg->script) {
    if (strlen(cfg->script) >= sizeof s->script_spec) {
      snprintf(err, err_sz, "--script '%s': longer than %zu characters", cfg->script,
               sizeof s->script_spec - 1);
      goto fail;
    }
    snprintf(s->script_spec, sizeof s->script_spec, "%s", cfg->script);
  }
  if (vehicle_params_load(cfg->params_path, &s->p, err, err_sz) != 0) goto fail;
  if (cfg->tyre_model >= 0) s->p.tyre_model_paper = cfg->tyre_model;
  s->tyre_paper = s->p.tyre_model_paper;
  s->host_io_period_steps = cfg->host_io_period_ms > 1 ? cfg->host_io_period_ms : 1;
  if (mkdir(cfg->run_dir, 0755) != 0 && errno != EEXIST) {
    snprintf(err, err_sz, "run dir '%s': %s", cfg->run_dir, strerror(errno));
    goto fail;
  }
  /* the generated scene lives in a private dir so that parallel sims do not collide */
  snprintf(s->scene_dir, sizeof s->scene_dir, "%s/scene-XXXXXX", cfg->run_dir);
  if (!mkdtemp(s->scene_dir)) {
    snprintf(err, err_sz, "scene dir in '%s': %s", cfg->run_dir, strerror(errno));
    s->scene_dir[0] = '\0';
    goto fail;
  }
  snprintf(s->scene_path, sizeof s->scene_path, "%s/scene.xml", s->scene_dir);
  s->ntag_files = cfg->cars;
  if (sim_load_model(s, cfg, err, err_sz) != 0) goto fail;
  s->ncars = cfg->cars;
  s->car = calloc((size_t)cfg->cars, sizeof *s->car);
  s->geom_tyre = malloc(sizeof(int) * (size_t)s->m->ngeom);
  if (!s->car || !s->geom_tyre) goto fail;
  for (int g = 0; g < s->m->ngeom; g++) s->geom_tyre[g] = -1;
  const vehicle_params_t *p = &s->p;
  s->lon = (tyre_curve_t){p->long_extremum[0], p->long_extremum[1], p->long_asymptote[0],
                          p->long_asymptote[1]};
  s->lat = (tyre_curve_t){p->lat_extremum[0], p->lat_extremum[1], p->lat_asymptote[0],
                          p->lat_asymptote[1]};
  s->motor =
      (motor_model_t){p->motor_stall_torque_nm, p->motor_noload_speed_rad_s, p->motor_nominal_v};
  for (int i = 0; i < cfg->cars; i++) {
    s->car[i].index = i + 1;
    if (sim_bind_car(s, &s->car[i], err, err_sz) != 0) goto fail;
  }
  if (sim_bind_late_boxes(s, err, err_sz) != 0) goto fail;
  if (tl_load(&s->tl, s->mv ? s->mv : s->m, err, err_sz) != 0) goto fail;
  if (sim_bind_route(s, cfg, err, err_sz) != 0) goto fail;
  if (sim_place_cars(s, err, err_sz) != 0) goto fail;
  mj_forward(s->m, s->d);
  for (int i = 0; i < cfg->cars; i++)
    if (sim_setup_car(s, cfg, &s->car[i], err, err_sz) != 0) goto fail;
  return s;
fail:
  sim_destroy(s);
  return NULL;
}

void sim_destroy(sim_t *s) {
  if (!s) return;
  for (int i = 0; s->car && i < s->ncars; i++) {
    if (s->car[i].has_pty) ptylink_close(&s->car[i].pty);
    sim_rplidar_destroy(s->car[i].rplidar);
    sim_lidar_destroy(s->car[i].lidar);
  }
  if (s->d) mj_deleteData(s->d);
  if (s->m) mj_deleteModel(s->m);
  if (s->dv) mj_deleteData(s->dv);
  if (s->mv) mj_deleteModel(s->mv);
  if (s->route) route_driver_free(s->route);
  free(s->route);
  if (s->scene_dir[0]) { /* the generated scene and tag textures */
    char path[700];
    snprintf(path, sizeof path, "%s/scene.xml", s->scene_dir);
    unlink(path);
    snprintf(path, sizeof path, "%s/scene_physics.xml", s->scene_dir);
    unlink(path);
    snprintf(path, sizeof path, "%s/map_physics.xml", s->scene_dir);
    unlink(path);
    for (int i = 1; i <= s->ntag_files; i++) {
      snprintf(path, sizeof path, "%s/tag36h11_%d.png", s->scene_dir, mg_tag_id(i));
      unlink(path);
    }
    rmdir(s->scene_dir);
  }
  free(s->geom_tyre);
  free(s->car);
  free(s);
}

/* ---- per step ------------------------------------------------------------------------- */
/* Is the host link (ptys) serviced in the step that ends at s->time_us + SIM_STEP_US? */
static int sim_host_io_due(const sim_t *s) {
  return (s->time_us / SIM_STEP_US + 1) % s->host_io_period_steps == 0;
}

static void sim_count_host_frame(const proto_frame_t *f, void *ctx) {
  (void)f;
  ((sim_car_t *)ctx)->host_frames++;
}

/* Moves what the client wrote on the pty onto the Nano's RX wire, now; counts its frames. */
static void sim_read_host(sim_t *s, sim_car_t *c) {
  uint8_t buf[512];
  const size_t room = uart_space(&c->rx) < sizeof buf ? uart_space(&c->rx) : sizeof buf;
  const size_t n = ptylink_read(&c->pty, buf, room);
  if (n == 0) return;
  uart_push(&c->rx, buf, n);
  c->host_rx_us = s->time_us;
  proto_parser_feed(&c->host_parser, buf, n, sim_count_host_frame, c);
}

/* Free lockstep (a host I/O period > 1 ms): while nobody is on the pty (nothing read, and the
 * pty's buffer full so our last bytes were refused) it is served only every
 * SIM_HOST_IDLE_PERIOD_MS, saving two system calls per period; a client's first bytes are then
 * seen within that time, and the next service that moves bytes ends the idle state. */
#define SIM_HOST_IDLE_PERIOD_MS 100
/* Unread bytes [bytes] on the pty above which nobody is reading it (free lockstep only): 40 ms
 * of the Nano's telemetry. Writing on into the kernel's queue costs tens of microseconds per
 * write (the tty layer hands each write to a kernel worker), more than the car's whole 1 ms
 * step; a client that reads keeps the queue near empty. */
#define SIM_PTY_UNREAD_IDLE_BYTES 256
static int sim_host_io_due_car(const sim_t *s, const sim_car_t *c, int io_due) {
  if (!io_due || !c->host_idle) return io_due;
  return (s->time_us / SIM_STEP_US + 1) % SIM_HOST_IDLE_PERIOD_MS == 0;
}

static int sim_nano_io(sim_t *s, sim_car_t *c, int io_due_all, char *err, size_t err_sz) {
  uint8_t buf[512];
  const int io_due = c->has_pty && sim_host_io_due_car(s, c, io_due_all);
  const uint32_t frames_before = c->host_frames;
  const int64_t rx_before = c->host_rx_us;
  if (c->has_pty && io_due) sim_read_host(s, c);
  if (c->has_script) {
    if (s->route && s->time_us >= c->script.next_us) { /* pure pursuit before each frame */
      const mjtNum *q = s->d->qpos + c->root_qpos;
      const double yaw =
          atan2(2.0 * (q[3] * q[6] + q[4] * q[5]), 1.0 - 2.0 * (q[5] * q[5] + q[6] * q[6]));
      route_driver_update(s->route, q[0], q[1], yaw, &c->script.throttle, &c->script.steering);
    }
    const size_t n = script_poll(&c->script, s->time_us, buf, sizeof buf);
    uart_push(&c->rx, buf, n);
  }
  /* bytes that finished crossing the wire during this step reach the firmware now */
  size_t n = uart_pop(&c->rx, SIM_STEP_US, buf, 255);
  if (n > 0) nigel_rx(&c->nano, buf, (uint8_t)n, (uint32_t)s->time_us);
  const double k = (double)ENC_COUNTS_PER_REV / (2.0 * M_PI);
  const int32_t enc_l = (int32_t)floor(s->d->qpos[c->wheel_qpos[W_RL]] * k);
  const int32_t enc_r = (int32_t)floor(s->d->qpos[c->wheel_qpos[W_RR]] * k);
  nigel_step(&c->nano, (uint32_t)s->time_us, enc_l, enc_r);
  if (!c->has_pty) {
    uart_pop(&c->tx, SIM_STEP_US, buf, sizeof buf); /* nobody listens: the wire just drains */
  } else {
    const size_t room = sizeof c->tx_pending - c->tx_pending_n;
    c->tx_pending_n += uart_pop(&c->tx, SIM_STEP_US, c->tx_pending + c->tx_pending_n, room);
    const int full = c->tx_pending_n == sizeof c->tx_pending;
    if (full && !io_due && c->host_idle) {
      c->tx_pending_n = 0; /* idle: dropped here, as the full pty would drop them */
    } else if (io_due || full) {
      const int read_any = c->host_rx_us != rx_before || c->host_frames != frames_before;
      const int may_idle = s->host_io_period_steps > 1 && !read_any;
      if (may_idle && ptylink_unread(&c->pty) >= SIM_PTY_UNREAD_IDLE_BYTES) {
        c->host_idle = 1; /* nobody reads: one ioctl instead of a write into a queue */
      } else {
        /* a full pty drops bytes */
        const size_t sent = ptylink_write(&c->pty, c->tx_pending, c->tx_pending_n);
        c->host_idle = may_idle && c->tx_pending_n > 0 && sent == 0;
      }
      c->tx_pending_n = 0;
    }
  }
  (void)err;
  (void)err_sz;
  return 0;
}

/* Colours the lamp geoms when the firmware's lamp outputs change. */
static void sim_draw_lamps(sim_t *s, sim_car_t *c) {
  if (c->lamps == c->lamps_shown) return;
  c->lamps_shown = c->lamps;
  for (int k = 0; k < SIM_LAMPS; k++) {
    if (c->lamp_geom[k] < 0) continue;
    const float *rgb = (c->lamps & sim_lamp[k].bits) ? sim_lamp[k].on : sim_lamp[k].off;
    float *dst = (s->mv ? s->mv : s->m)->geom_rgba + 4 * c->lamp_geom[k];
    dst[0] = rgb[0];
    dst[1] = rgb[1];
    dst[2] = rgb[2];
  }
}

static void sim_actuate(sim_t *s, sim_car_t *c) {
  const vehicle_params_t *p = &s->p;
  mjData *d = s->d;
  mjModel *m = s->m;
  const double dt = m->opt.timestep;
  /* servo: pulse -> commanded angle -> rate-limited shaft -> Ackermann knuckle targets */
  const double target =
      steer_command_rad(c->servo_us, p->servo_center_us, p->servo_us_per_full, p->steer_limit_rad);
  c->steer_rad = steer_rate_limit(c->steer_rad, target, p->steer_rate_rad_s, dt);
  double ang[2];
  steer_ackermann(c->steer_rad, p->wheelbase_m, p->track_m, &ang[0], &ang[1]);
  for (int w = 0; w < 2; w++) {
    const double e = ang[w] - d->qpos[c->steer_qpos[w]];
    d->qfrc_applied[c->steer_dof[w]] =
        p->steer_kp_nm_rad * e - p->steer_kv_nms_rad * d->qvel[c->steer_dof[w]];
  }
  /* rear gearmotors (one driver channel) and the brake's holding friction */
  for (int w = W_RL; w <= W_RR; w++) {
    const int dof = c->wheel_dof[w];
    d->qfrc_applied[dof] =
        motor_torque_nm(&s->motor, c->duty, c->reverse, c->brake, p->battery_v, d->qvel[dof]);
    m->dof_frictionloss[dof] = p->gearbox_friction_nm + (c->brake ? p->brake_hold_torque_nm : 0.0);
  }
}

/* Adds to qfrc_applied the generalized force of a world-frame force f [N] acting at point p [m]
 * on body b: the sum mj_applyFT forms, taken over the dofs of b's own chain (Jacobian columns
 * from cdof about the root's subtree centre of mass, as mj_jac builds them). Through
 * xfrc_applied, MuJoCo built an nv-wide dense Jacobian per wheel: with 16 cars that was a
 * fifth of the run. Needs the kinematics of mj_step1. */
static void sim_apply_point_force(const mjModel *m, mjData *d, int b, const mjtNum p[3],
                                  const mjtNum f[3]) {
  const mjtNum *com = d->subtree_com + 3 * m->body_rootid[b];
  const mjtNum r[3] = {p[0] - com[0], p[1] - com[1], p[2] - com[2]};
  /* f . (v + w x r) = f . v + w . (r x f): one torque for every dof of the chain */
  const mjtNum tau[3] = {r[1] * f[2] - r[2] * f[1], r[2] * f[0] - r[0] * f[2],
                         r[0] * f[1] - r[1] * f[0]};
  while (b && !m->body_dofnum[b]) b = m->body_parentid[b];
  if (!b) return;
  for (int i = m->body_dofadr[b] + m->body_dofnum[b] - 1; i >= 0; i = m->dof_parentid[i]) {
    const mjtNum *cdof = d->cdof + 6 * i; /* [angular, linear] motion of dof i */
    d->qfrc_applied[i] += cdof[0] * tau[0] + cdof[1] * tau[1] + cdof[2] * tau[2] + cdof[3] * f[0] +
                          cdof[4] * f[1] + cdof[5] * f[2];
  }
}

/* World-frame linear velocity [m/s] of body b's centre of mass into out: what
 * mj_objectVelocity(mjOBJ_BODY, world frame) gives in its linear half, the same arithmetic
 * (cvel's linear part moved from the root's subtree CoM to the body's CoM, v - dif x w),
 * without its rotation bookkeeping: four wheels per car every step. */
static void sim_body_velocity(const mjModel *m, const mjData *d, int b, mjtNum out[3]) {
  const mjtNum *cvel = d->cvel + 6 * b, *w = cvel, *v = cvel + 3;
  const mjtNum *com = d->subtree_com + 3 * m->body_rootid[b], *p = d->xipos + 3 * b;
  const mjtNum dif[3] = {p[0] - com[0], p[1] - com[1], p[2] - com[2]};
  out[0] = v[0] - (dif[1] * w[2] - dif[2] * w[1]);
  out[1] = v[1] - (dif[2] * w[0] - dif[0] * w[2]);
  out[2] = v[2] - (dif[0] * w[1] - dif[1] * w[0]);
}

/* Paper tyre forces from the contacts recorded after the previous step, applied at each
 * contact point of the wheel body. sim_actuate has set the wheel and steering dofs' own
 * forces for this step; the free joint's are the tyres' alone. */
static void sim_tyres(sim_t *s, sim_car_t *c) {
  const vehicle_params_t *p = &s->p;
  const mjModel *m = s->m;
  mjData *d = s->d;
  mju_zero(d->qfrc_applied + c->root_dof, 6);
  for (int w = 0; w < W_N; w++) {
    const int b = c->wheel_body[w];
    if (c->fz_n[w] <= 0.0) continue;
    const mjtNum *R = d->xmat + 9 * b;
    const double axis[3] = {R[1], R[4], R[7]}; /* wheel y axis (spin axis) in the world */
    double fwd[3], lat[3];
    mju_cross(fwd, axis, c->normal[w]);
    if (mju_normalize3(fwd) < 1e-9) continue;
    mju_cross(lat, c->normal[w], fwd);
    mjtNum v_lin[3];
    sim_body_velocity(m, d, b, v_lin);
    const double i_spin = m->body_inertia[3 * b + 1] + m->dof_armature[c->wheel_dof[w]];
    const double r = p->wheel_radius_m;
    tyre_in_t in;
    in.v_x_m_s = mju_dot3(v_lin, fwd);
    in.v_y_m_s = mju_dot3(v_lin, lat);
    in.omega_r_m_s = d->qvel[c->wheel_dof[w]] * r;
    in.fz_n = c->fz_n[w];
    in.mu = c->mu[w];
    in.v_min_m_s = p->tyre_v_min_m_s;
    in.rolling_resistance = p->tyre_rolling_resistance;
    /* no-overshoot clamp: half the reduced mass of (wheel spin, car mass on this wheel) so
     * one step never reverses the slip; the lateral mass is the wheel's load share (Fz / g),
     * so the clamp keeps the axles' cornering stiffness proportional to their load (neutral
     * steer, as the curves themselves are) */
    const double m_load = c->fz_n[w] / 9.80665;
    in.m_long_kg = 0.5 / (r * r / i_spin + 1.0 / fmax(m_load, 1e-3));
    in.m_lat_kg = 1.0 * m_load;
    in.dt_s = m->opt.timestep;
    double fx, fy;
    tyre_force(&s->lon, &s->lat, &in, &fx, &fy);
    double f[3];
    for (int k = 0; k < 3; k++) f[k] = fx * fwd[k] + fy * lat[k];
    sim_apply_point_force(m, d, b, c->contact_pos[w], f);
  }
}

/* After the step: normal load, surface friction and geometry of every tyre contact, and
 * chassis collisions. */
static void sim_record_contacts(sim_t *s) {
  const mjModel *m = s->m;
  const mjData *d = s->d;
  for (int i = 0; i < s->ncars; i++) {
    sim_car_t *c = &s->car[i];
    c->in_collision = 0;
    for (int w = 0; w < W_N; w++) c->fz_n[w] = 0.0;
  }
  double best[SIM_MAX_CARS * W_N] = {0};
  for (int k = 0; k < d->ncon; k++) {
    const mjContact *con = d->contact + k;
    for (int side = 0; side < 2; side++) {
      const int g = side ? con->geom2 : con->geom1, other = side ? con->geom1 : con->geom2;
      const int t = s->geom_tyre[g];
      if (t < 0) continue;
      sim_car_t *c = &s->car[t / W_N];
      const int w = t % W_N;
      mjtNum f6[6];
      mj_contactForce(m, d, k, f6);
      const double fn = f6[0];
      c->fz_n[w] += fn;
      if (fn > best[t]) { /* the most loaded contact gives surface, point and normal */
        best[t] = fn;
        c->mu[w] = m->geom_friction[3 * other];
        if (s->tyre_paper && con->pos[2] < SIM_GROUND_CLEARANCE_M) /* on the floor */
          c->mu[w] = terrain_mu(&s->terrain, con->pos[0], con->pos[1], c->mu[w]);
        mju_copy3(c->contact_pos[w], con->pos);
        /* frame[0..2] points from geom1 to geom2: make it point from the ground to the tyre */
        for (int q = 0; q < 3; q++) c->normal[w][q] = side ? con->frame[q] : -con->frame[q];
      }
    }
  }
  for (int i = 0; i < s->ncars; i++) {
    sim_car_t *c = &s->car[i];
    for (int k = 0; k < d->ncon; k++)
      if (d->contact[k].geom1 == c->chassis_geom || d->contact[k].geom2 == c->chassis_geom)
        c->in_collision = 1;
  }
}

/* Will anyone read the accelerometer after this step? The emulated Nano samples its IMU at
 * 100 Hz (its own schedule, imu_next_us, read in the next step's nigel_step) and the learning
 * API asks before the last step of a control period (sim_want_accel). */
static int sim_accel_due(const sim_t *s) {
  if (s->accel_wanted) return 1;
  const uint32_t next_step_us = (uint32_t)(s->time_us + SIM_STEP_US);
  for (int i = 0; i < s->ncars; i++)
    if ((int32_t)(next_step_us - s->car[i].nano.imu_next_us) >= 0) return 1;
  return 0;
}

/* MuJoCo 2.2's mj_step2 (actuation, acceleration, constraint, acceleration sensors, checks,
 * integration), except that the acceleration-stage sensors are computed only in the steps
 * whose values are read: the accelerometer's mj_rnePostConstraint is ~6 % of a step, and the
 * Nano reads it every 10th step. The values read are the ones mj_step2 would give. */
static void sim_step2(sim_t *s) {
  const mjModel *m = s->m;
  mjData *d = s->d;
  if (m->opt.integrator == mjINT_IMPLICIT) { /* its integrator is not in 2.2's public API */
    mj_step2(m, d);
    s->accel_wanted = 0;
    return;
  }
  mj_fwdActuation(m, d);
  mj_fwdAcceleration(m, d);
  mj_fwdConstraint(m, d);
  if (sim_accel_due(s)) mj_sensorAcc(m, d);
  s->accel_wanted = 0;
  mj_checkAcc(m, d);
  if (mjENABLED(mjENBL_FWDINV)) mj_compareFwdInv(m, d);
  mj_Euler(m, d); /* mj_step2 integrates RK4 models with Euler too */
}

void sim_want_accel(sim_t *s) {
  s->accel_wanted = 1;
}

int sim_step(sim_t *s, char *err, size_t err_sz) {
  if (s->tl.n > 0) { /* lights: program or command, lamps lit in the model for the cameras */
    tl_update(&s->tl, s->time_us);
    tl_draw(&s->tl, s->mv ? s->mv : s->m);
  }
  sim_place_late_boxes(s); /* before mj_step1: its kinematics, contacts and rays see them */
  mj_step1(s->m, s->d);
  const int io_due = sim_host_io_due(s);
  for (int i = 0; i < s->ncars; i++) {
    sim_car_t *c = &s->car[i];
    if (sim_nano_io(s, c, io_due, err, err_sz) != 0) return -1;
    sim_actuate(s, c);
    sim_draw_lamps(s, c);
    if (s->tyre_paper) sim_tyres(s, c);
  }
  sim_step2(s);
  sim_record_contacts(s);
  s->time_us += SIM_STEP_US;
  for (int i = 0; i < s->ncars; i++) {
    sim_car_t *c = &s->car[i];
    c->lidar_new = 0;
    if (!c->lidar || s->lidar_on_request) continue;
    /* mj_step2 leaves kinematics at the start of the step: fine for 1 ms ray timing */
    if (sim_lidar_update(s->m, s->d, c->lidar, s->time_us)) c->lidar_new = 1;
    if (c->rplidar) { /* stream the rays just measured, as the real device does */
      int from, to, num_rays;
      const float *ranges_m, *quality;
      sim_lidar_last_cast(c->lidar, &from, &to, &num_rays, &ranges_m, &quality);
      sim_rplidar_push_rays(c->rplidar, ranges_m, quality, from, to, num_rays);
    }
    /* free lockstep: an RPLIDAR pty nobody scans on is served at the idle period, too */
    const int lidar_io_due = c->rplidar && io_due &&
                             (s->host_io_period_steps == 1 || sim_rplidar_scanning(c->rplidar) ||
                              (s->time_us / SIM_STEP_US) % SIM_HOST_IDLE_PERIOD_MS == 0);
    if (c->rplidar && lidar_io_due && sim_rplidar_poll(c->rplidar, s->time_us, err, err_sz) != 0)
      return -1;
  }
  if (s->d->warning[mjWARN_BADQACC].number > 0) {
    snprintf(err, err_sz, "physics diverged (bad qacc) at t = %.3f s", s->time_us * 1e-6);
    return -1;
  }
  return 0;
}

/* ---- queries ------------------------------------------------------------------------- */
traffic_lights_t *sim_traffic_lights(sim_t *s) {
  return &s->tl;
}
const route_driver_t *sim_route(const sim_t *s) {
  return s->route;
}

int64_t sim_time_us(const sim_t *s) {
  return s->time_us;
}
int sim_cars(const sim_t *s) {
  return s->ncars;
}
const mjModel *sim_model(const sim_t *s) {
  return s->m;
}
mjData *sim_data(const sim_t *s) {
  return s->d;
}
mjModel *sim_render_model(const sim_t *s) {
  return s->mv ? s->mv : s->m;
}
void sim_render_snapshot(const sim_t *s, mjData *dst) {
  const mjModel *m = s->m;
  dst->time = s->d->time;
  mju_copy(dst->qpos, s->d->qpos, m->nq);
  mju_copy(dst->qvel, s->d->qvel, m->nv);
  mju_copy(dst->mocap_pos, s->d->mocap_pos, 3 * m->nmocap);
  mju_copy(dst->mocap_quat, s->d->mocap_quat, 4 * m->nmocap);
  mj_kinematics(sim_render_model(s), dst);
  mj_camlight(sim_render_model(s), dst);
}
mjData *sim_render_data(sim_t *s) {
  if (!s->mv) return s->d;
  sim_render_snapshot(s, s->dv);
  return s->dv;
}
const char *sim_nano_link(const sim_t *s, int car) {
  return s->car[car - 1].has_pty ? s->car[car - 1].pty.link_path : "";
}
const char *sim_lidar_link(const sim_t *s, int car) {
  return s->car[car - 1].lidar_link;
}
const nigel_t *sim_nano(const sim_t *s, int car) {
  return &s->car[car - 1].nano;
}

int64_t sim_host_rx_us(const sim_t *s, int car) {
  const sim_car_t *c = &s->car[car - 1];
  return c->has_pty ? c->host_rx_us : -1;
}

uint32_t sim_host_frames(sim_t *s, int car) {
  sim_car_t *c = &s->car[car - 1];
  if (!c->has_pty) return 0;
  sim_read_host(s, c);
  return c->host_frames;
}

int sim_nano_wait_input(const sim_t *s, int car, int timeout_ms) {
  const sim_car_t *c = &s->car[car - 1];
  if (!c->has_pty) return 0;
  struct pollfd p = {c->pty.master_fd, POLLIN, 0};
  return poll(&p, 1, timeout_ms) > 0 && (p.revents & POLLIN);
}

void sim_motor_outputs(const sim_t *s, int car, uint8_t *duty, uint8_t *reverse, uint8_t *brake,
                       uint16_t *servo_us) {
  const sim_car_t *c = &s->car[car - 1];
  *duty = c->duty;
  *reverse = c->reverse;
  *brake = c->brake;
  *servo_us = c->servo_us;
}

const struct sim_lidar_scan *sim_lidar_new_scan(const sim_t *s, int car) {
  const sim_car_t *c = &s->car[car - 1];
  return (c->lidar && c->lidar_new) ? sim_lidar_last_scan(c->lidar) : NULL;
}

void sim_get_truth(const sim_t *s, int car, sim_truth_t *o) {
  const sim_car_t *c = &s->car[car - 1];
  const mjData *d = s->d;
  const mjtNum *qp = d->qpos + c->root_qpos, *qv = d->qvel + c->root_dof;
  memset(o, 0, sizeof *o);
  mju_copy3(o->pos_m, qp);
  mju_copy4(o->quat_wxyz, qp + 3);
  o->yaw_rad =
      atan2(2.0 * (qp[3] * qp[6] + qp[4] * qp[5]), 1.0 - 2.0 * (qp[5] * qp[5] + qp[6] * qp[6]));
  /* free joint: linear velocity of the body origin in the world, angular in the body frame */
  mjtNum R[9];
  mju_quat2Mat(R, qp + 3);
  mju_mulMatTVec(o->vel_body_m_s, R, qv, 3, 3);
  mju_copy3(o->gyro_body_rad_s, qv + 3);
  const double tl = tan(d->qpos[c->steer_qpos[0]]), tr = tan(d->qpos[c->steer_qpos[1]]);
  o->steering_rad = (fabs(tl + tr) > 1e-12) ? atan(2.0 * tl * tr / (tl + tr)) : 0.0;
  for (int w = 0; w < W_N; w++) o->wheel_speed_rad_s[w] = d->qvel[c->wheel_dof[w]];
  o->in_collision = c->in_collision;
  o->command_throttle = c->nano.cmd.throttle_milli / (double)PROTO_MILLI;
  o->command_steering = c->nano.cmd.steering_milli / (double)PROTO_MILLI;
  o->expert_steering = (car == 1 && s->route) ? s->route->expert_steering : NAN;
}

double sim_clock_s(clockid_t id) {
  struct timespec t;
  clock_gettime(id, &t);
  return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

struct sim_bare {
  const mjModel *m;
  mjData *d;
};

sim_bare_t *sim_bare_create(const sim_t *s) {
  sim_bare_t *b = calloc(1, sizeof *b);
  if (!b) return NULL;
  b->m = s->m;
  b->d = mj_makeData(s->m);
  if (!b->d) {
    free(b);
    return NULL;
  }
  sim_bare_sync(b, s);
  return b;
}

void sim_bare_sync(sim_bare_t *b, const sim_t *s) {
  const mjModel *m = s->m;
  const mjData *d = s->d;
  b->d->time = d->time;
  mju_copy(b->d->qpos, d->qpos, m->nq);
  mju_copy(b->d->qvel, d->qvel, m->nv);
  mju_copy(b->d->qacc_warmstart, d->qacc_warmstart, m->nv);
  mju_copy(b->d->act, d->act, m->na);
  mju_copy(b->d->ctrl, d->ctrl, m->nu);
  mju_copy(b->d->qfrc_applied, d->qfrc_applied, m->nv);
  mju_copy(b->d->xfrc_applied, d->xfrc_applied, 6 * m->nbody);
  mju_copy(b->d->mocap_pos, d->mocap_pos, 3 * m->nmocap);
  mju_copy(b->d->mocap_quat, d->mocap_quat, 4 * m->nmocap);
}

double sim_bare_run(sim_bare_t *b, int steps, double *cpu_s) {
  const double w0 = sim_clock_s(CLOCK_MONOTONIC), c0 = sim_clock_s(CLOCK_THREAD_CPUTIME_ID);
  for (int k = 0; k < steps; k++) mj_step(b->m, b->d);
  if (cpu_s) *cpu_s = sim_clock_s(CLOCK_THREAD_CPUTIME_ID) - c0;
  return sim_clock_s(CLOCK_MONOTONIC) - w0;
}

void sim_bare_destroy(sim_bare_t *b) {
  if (!b) return;
  mj_deleteData(b->d);
  free(b);
}

double sim_bare_mj_step_s(const sim_t *s, int steps, double *cpu_s) {
  sim_bare_t *b = sim_bare_create(s);
  if (!b) return -1.0;
  const double wall = sim_bare_run(b, steps, cpu_s);
  sim_bare_destroy(b);
  return wall;
}

/* ---- learning API support ----------------------------------------------------------- */
int sim_reset(sim_t *s, uint64_t seed, const double *poses, char *err, size_t err_sz) {
  if (poses) {
    mjtNum saved[7 * SIM_MAX_CARS]; /* the old start poses, back in place on a refusal */
    for (int i = 0; i < s->ncars; i++)
      mju_copy(saved + 7 * i, s->m->qpos0 + s->car[i].root_qpos, 7);
    for (int i = 0; i < s->ncars; i++) {
      const double *p = poses + 3 * i;
      if (!isfinite(p[0]) || !isfinite(p[1]) || !isfinite(p[2]) || fabs(p[0]) > SCN_COORD_MAX_M ||
          fabs(p[1]) > SCN_COORD_MAX_M) {
        snprintf(err, err_sz, "reset pose of car %d (%g, %g, %g): not a finite pose on the map", i,
                 p[0], p[1], p[2]);
        return -1;
      }
      sim_set_car_pose(s, i, p, p[2], 0, 0); /* and qpos0: the new start pose */
    }
    mj_kinematics(s->m, s->d); /* the static geoms' poses, for the clearance check */
    const int ct = s->m->geom_contype[s->car[0].chassis_geom],
              ca = s->m->geom_conaffinity[s->car[0].chassis_geom];
    for (int i = 0; i < s->ncars; i++) {
      cl_prism_t pr;
      char why[512];
      sim_car_prism(s, i, &pr);
      if (cl_check_on_map(s->m, s->d, &pr, ct, ca, why, sizeof why) != 0) {
        snprintf(err, err_sz, "reset pose of car %d (x %.3f, y %.3f m, yaw %.3f rad): %s", i,
                 poses[3 * i], poses[3 * i + 1], poses[3 * i + 2], why);
        for (int j = 0; j < s->ncars; j++)
          mju_copy(s->m->qpos0 + s->car[j].root_qpos, saved + 7 * j, 7);
        return -1;
      }
    }
  }
  s->seed = seed;
  s->time_us = 0;
  mj_resetData(s->m, s->d); /* qpos0 holds the start poses */
  sim_park_late_boxes(s);
  for (int k = 0; k < s->nbox; k++)
    s->box_placed[k] = s->box_new[k] = s->box_car_below[k] = s->box_gone[k] = s->box_left[k] = 0;
  mj_forward(s->m, s->d);
  for (int i = 0; i < s->ncars; i++)
    if (sim_car_boot(s, &s->car[i], err, err_sz) != 0) return -1;
  return 0;
}

int sim_teleport(sim_t *s, int car, double x_m, double y_m, double yaw_rad, char *err,
                 size_t err_sz) {
  if (car < 1 || car > s->ncars) {
    snprintf(err, err_sz, "no car %d (the sim has %d)", car, s->ncars);
    return -1;
  }
  if (!isfinite(x_m) || !isfinite(y_m) || !isfinite(yaw_rad) || fabs(x_m) > SCN_COORD_MAX_M ||
      fabs(y_m) > SCN_COORD_MAX_M) {
    snprintf(err, err_sz, "(%g, %g, %g) is not a finite pose on the map", x_m, y_m, yaw_rad);
    return -1;
  }
  sim_car_t *c = &s->car[car - 1];
  mjtNum *qp = s->d->qpos + c->root_qpos;
  mjtNum saved[7], saved0[7];
  mju_copy(saved, qp, 7);
  mju_copy(saved0, s->m->qpos0 + c->root_qpos, 7);
  const double base[3] = {x_m, y_m, 0.0};
  sim_set_car_pose(s, car - 1, base, yaw_rad, 0, 0);
  mju_copy(s->m->qpos0 + c->root_qpos, saved0, 7); /* the start pose stays the reset's */
  cl_prism_t pr;
  char why[512];
  sim_car_prism(s, car - 1, &pr);
  if (cl_check_on_map(s->m, s->d, &pr, s->m->geom_contype[c->chassis_geom],
                      s->m->geom_conaffinity[c->chassis_geom], why, sizeof why) != 0) {
    mju_copy(qp, saved, 7);
    snprintf(err, err_sz, "(x %.3f, y %.3f m, yaw %.3f rad): %s", x_m, y_m, yaw_rad, why);
    return -1;
  }
  for (int j = 0; j < s->m->njnt; j++) { /* every joint of the car: free, knuckles, wheels */
    int b = s->m->jnt_bodyid[j];
    while (b > 0 && b != c->body) b = s->m->body_parentid[b];
    if (b == c->body)
      mju_zero(s->d->qvel + s->m->jnt_dofadr[j], s->m->jnt_type[j] == mjJNT_FREE ? 6 : 1);
  }
  mj_forward(s->m, s->d);
  return 0;
}

int sim_drive(sim_t *s, int car, double throttle, double steering) {
  if (car < 1 || car > s->ncars) return -1;
  sim_car_t *c = &s->car[car - 1];
  if (!c->has_script || !(fabs(throttle) <= 1.0) || !(fabs(steering) <= 1.0)) return -1;
  c->script.throttle = throttle;
  c->script.steering = steering;
  return 0;
}

const struct sim_lidar_scan *sim_lidar_scan_at_once(sim_t *s, int car) {
  sim_car_t *c = &s->car[car - 1];
  if (!c->lidar) return NULL;
  sim_lidar_scan_now(s->m, s->d, c->lidar, s->time_us);
  return sim_lidar_last_scan(c->lidar);
}

void sim_imu(const sim_t *s, int car, double accel_m_s2[3], double gyro_rad_s[3]) {
  const sim_car_t *c = &s->car[car - 1];
  const mjtNum *sd = s->d->sensordata;
  for (int k = 0; k < 3; k++) {
    accel_m_s2[k] = sd[c->accel_adr + k] + c->accel_bias[k];
    gyro_rad_s[k] = sd[c->gyro_adr + k] + c->gyro_bias[k];
  }
}
