/* autodrive-sim: the MuJoCo 2.2 HIL simulator of Nigel. See --help and README.md. */
#include <autodrive_channels.h>
#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <pthread.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include <lcm/lcm.h>

#include "camera_fx.h"
#include "lcmpub.h"
#include "route_driver.h"
#include "script.h"
#include "sim.h"
#include "teleport_lcm.h"
#include "tl_lcm.h"

#include "bench_pairs.h"
#include "sim_camera.h"
#include "sim_lidar_lcm.h"
#include "sim_render.h"
#include "sim_viewer.h"

#define MAIN_DEFAULT_URL AUTODRIVE_LCM_URL_DEFAULT
#define MAIN_TRUTH_EVERY 10 /* steps between ground-truth messages: 100 Hz */
#define MAIN_CLOCK_EVERY 10 /* steps between SIM_CLOCK messages: 100 Hz */
/* free lockstep serves the ptys every 10 ms of sim time: a client there sees the sim run
 * tens of times faster than real time anyway, and an idle pty then costs no system call in
 * nine steps of ten (tools/bench sim: overhead_ratio) */
#define MAIN_FREE_LOCKSTEP_IO_MS 10
#define MAIN_LCM_FLUSH_S 0.001 /* [s] wall: longest a queued LCM message waits */
/* [s] wall, free lockstep: nothing waits on its messages, and each flush wakes the LCM thread
 * (a system call, and with it the other core) */
#define MAIN_FREE_LCM_FLUSH_S 0.004
#define MAIN_FREE_CLOCK_EVERY 8 /* [steps] free lockstep: 8 ms of sim time, ~0.15 ms of wall */
#define MAIN_PROGRESS_S 5.0     /* [s] wall time between progress lines */

static volatile sig_atomic_t main_stop = 0;
/* Largest lag behind the real-time schedule [s] before the schedule slips (see pacing). */
#define MAIN_MAX_LAG_S 0.02
static void main_on_signal(int sig) {
  (void)sig;
  main_stop = 1;
}

static void main_usage(FILE *f) {
  fprintf(
      f,
      "usage: autodrive-sim [options]\n"
      "MuJoCo 2.2 HIL simulator of the AutoDRIVE Nigel car. Each car's emulated Nano (the real\n"
      "firmware core) speaks the serial protocol on a pty at <run-dir>/nigel<i>-nano.\n\n"
      "  --cars N            cars (1..%d), vehicle names NIGEL1..NIGELN (default 1)\n"
      "  --map NAME|FILE     parking_school (default), driving_school, intersection_school,\n"
      "                      tiny_town, or an MJCF map file\n"
      "  --params FILE       vehicle description (default %s/vehicle/nigel.params)\n"
      "  --seed N            seed of IMU biases and noise (default 1)\n"
      "  --start X,Y,YAW_DEG car 1's start pose instead of the map's spawn site (given once per\n"
      "                      car with --cars N: car k at the k-th): x, y [m] of\n"
      "                      its rear-axle centre (base_link), yaw [deg] from +x; the other\n"
      "                      cars line up to its right as usual. Refused when a car would\n"
      "                      be off the floor or overlap a wall or obstacle (at the spawn\n"
      "                      site such a car takes the next free place, in rows behind)\n"
      "  --car-start I,X,Y,YAW_DEG\n"
      "                      car I (1..--cars) starts at this pose instead (repeatable; the\n"
      "                      intersection demo places each car on its approach). Refused like\n"
      "                      --start when a car would be off the floor or on an obstacle\n"
      "  --late-box X,Y,T[,SX,SY[,R]]\n"
      "                      a box obstacle (half sizes SX, SY [m], default %g; %g m tall)\n"
      "                      that appears at x, y [m] at sim time T [s]: a change to the\n"
      "                      place after it was mapped. With R [m], not before car 1's\n"
      "                      base_link is within R of it (one stepping out in front of\n"
      "                      the car). Up to %d; LIDAR, cameras and the collision flag\n"
      "                      see it once it is there\n"
      "  --lockstep          run as fast as possible (sim time only), publish SIM_CLOCK\n"
      "  --lockstep-client   lockstep with the client on each Nano pty (HIL): never more\n"
      "                      than 40 ms of sim time ahead of its last bytes, as fast as it\n"
      "                      keeps up; real time until it first writes; publish SIM_CLOCK\n"
      "  --lockstep-frames   lockstep frame by frame (repeatable HIL): at 0 and every 20 ms\n"
      "                      of sim time the sim waits for one more frame from the client\n"
      "                      on each Nano pty (a runtime with bridge.sync_to_sim_clock);\n"
      "                      publish SIM_CLOCK\n"
      "  --allow-teleport    (lockstep modes only) obey SIM_TELEPORT: a pose2d_t naming a\n"
      "                      car puts it there, standing still (evaluations that put a car\n"
      "                      back on its lane after an intervention)\n"
      "  --rtf X             run at X times real time (e.g. 4), publish SIM_CLOCK\n"
      "                      (default: real time, 1 sim second per wall second)\n"
      "  --host-io-ms N      serve the ptys every N ms of sim time, like a USB-serial\n"
      "                      adapter's latency timer (default: %d with --lockstep, else 1:\n"
      "                      every step)\n"
      "  --duration S        stop after S sim seconds (default: until SIGINT/SIGTERM)\n"
      "  --lcm-url URL       LCM provider (default %s)\n"
      "  --run-dir DIR       ptys' symlinks and the generated scene (default /tmp/autodrive-sim)\n"
      "  --script SPEC       scripted driver instead of a client on the pty, for tests and\n"
      "                      benchmarks: constant:throttle=T,steering=S[,start=s][,stop_after=s]\n"
      "                      or route:NAME[,speed=F][,start=s][,lookahead=M][,laps=N]\n"
      "                      [,perturb=A]: pure pursuit on the map's route NAME at F of top\n"
      "                      speed (default %g), lookahead M [m] (default %g), from the\n"
      "                      route's start (--cars 1); the run ends when the route does (N\n"
      "                      laps of a loop, default 1); A > 0 adds seeded steering\n"
      "                      perturbations up to A (normalised) now and then (expert\n"
      "                      recordings with recoveries, tools/pilot)\n"
      "  --no-pty            do not open ptys (with --script)\n"
      "  --no-lidar          do not simulate the LIDAR\n"
      "  --late-box-stay S   the --late-box before it leaves again S s after it appeared\n"
      "                      (an obstacle that goes away)\n"
      "  --no-late-obstacles leave out the map's late_obstacles (--late-box boxes stay)\n"
      "  --no-lidar-lcm      never publish NIGEL<i>_LIDAR (by default the sim publishes it\n"
      "                      unless a client is scanning on the RPLIDAR pty)\n"
      "  --cameras           render each car's front and rear camera (640x480 JPEG) on LCM\n"
      "  --front-camera      render only each car's front camera (half the rendering)\n"
      "  --eye               render the map's overhead camera 'eye' (1280x960) on EYE_IMAGE,\n"
      "                      or, on a map with eye_cameras (Tiny Town), each of those on\n"
      "                      <CAM>_IMAGE (EYE1_IMAGE, ...) and <CAM>_CAMERA_INFO\n"
      "  --camera-fps F      camera frame rate in sim time (default 30)\n"
      "  --light-level X     scene light level 0..1 (1 = day) instead of the map's own\n"
      "  --camera-noise S    Gaussian noise on rendered frames, sigma S [8-bit levels, 0..%g]\n"
      "  --camera-blur PX    Gaussian blur on rendered frames, sigma PX [px, 0..%g]\n"
      "                      (noise and blur are seeded by --seed: a run repeats)\n"
      "  --tyre-model M      paper or mujoco (default: the parameter file's)\n"
      "  --truth-log FILE    also write every ground-truth message to FILE (determinism checks)\n"
      "  --bench             print a JSON summary (sim_s, wall_s, rtf, bare_mj_step_rtf) at exit\n"
      "  --view              open a window (needs a display): 1/2/3 driver's, bird's, god's\n"
      "                      eye; Tab next car; N day/night; Space pause; R reset; Esc quit\n"
      "  --quiet             no progress lines\n"
      "  -h, --help          this text\n"
      "Publishes NIGEL<i>_GROUND_TRUTH (100 Hz), NIGEL<i>_LIDAR (when built with sensors),\n"
      "SIM_CLOCK (100 Hz, with --lockstep or --rtf) and, on maps with traffic lights,\n"
      "TRAFFIC_LIGHT_STATE (10 Hz per light and on each change); obeys TRAFFIC_LIGHT_COMMAND.\n"
      "Exit status: 0 done; 2 a bad option or value (also a --start or --late-box that does\n"
      "not fit the map); 1 any other error (files, map, LCM, physics).\n",
      SIM_MAX_CARS, AUTODRIVE_ROOT_DIR, SCN_LATE_BOX_HALF_DEFAULT_M, SCN_LATE_BOX_HEIGHT_M,
      SCN_MAX_LATE_BOXES, MAIN_FREE_LOCKSTEP_IO_MS, MAIN_DEFAULT_URL, SCRIPT_ROUTE_SPEED_DEFAULT,
      SCRIPT_ROUTE_LOOKAHEAD_DEFAULT_M, CFX_MAX_NOISE, CFX_MAX_BLUR_PX);
}

static double main_wall_s(void) {
  return sim_clock_s(CLOCK_MONOTONIC);
}
/* CPU time of this process [s]: on a shared, loaded machine it shows the cost without the
 * time spent waiting for a core */
static double main_cpu_s(void) {
  return sim_clock_s(CLOCK_PROCESS_CPUTIME_ID);
}

/* --lockstep-client: the sim never runs more than MAIN_SYNC_HORIZON_US of sim time past the
 * last bytes a client wrote on a car's Nano pty. The runtime's bridge writes a COMMAND frame
 * every 20 ms of its clock, which is SIM_CLOCK: so the sim goes as fast as the runtime keeps
 * up, and the emulated Nano never sees a gap the runtime did not make (its failsafe is 100 ms). */
#define MAIN_SYNC_HORIZON_US 40000
#define MAIN_SYNC_LOST_S 2.0 /* [s] wall without bytes: the client is gone; stop waiting for it */
typedef struct {
  int started;                          /* a client has written at least once */
  int64_t lost_rx_us[SIM_MAX_CARS + 1]; /* host_rx of a client given up on (0: none) */
  uint32_t frames[SIM_MAX_CARS + 1];    /* --lockstep-frames: the client's frames so far */
} main_sync_t;

static void main_sync_wait(sim_t *s, main_sync_t *st) {
  const int64_t now_us = sim_time_us(s);
  for (int c = 1; c <= sim_cars(s); c++) {
    const int64_t rx_us = sim_host_rx_us(s, c);
    if (rx_us < 0) continue; /* no client yet on this car */
    st->started = 1;
    if (st->lost_rx_us[c] == rx_us + 1 || now_us - rx_us < MAIN_SYNC_HORIZON_US) continue;
    const double t_give_up = main_wall_s() + MAIN_SYNC_LOST_S;
    while (!main_stop && !sim_nano_wait_input(s, c, 50)) {
      if (main_wall_s() > t_give_up) {
        fprintf(stderr,
                "[autodrive-sim] " AUTODRIVE_VEHICLE_PREFIX
                "%d: no bytes from the client for %.1f s (wall): "
                "running on without it\n",
                c, MAIN_SYNC_LOST_S);
        st->lost_rx_us[c] = rx_us + 1;
        break;
      }
      struct timespec ts = {0, 1000000}; /* a hung-up pty polls ready at once: 1 ms pause */
      nanosleep(&ts, NULL);
    }
  }
}

/* --lockstep-frames: at every MAIN_FRAME_TICK_US of sim time (0 included) the sim waits until
 * the client on each car's Nano pty has written one more whole frame, and hands it to the
 * emulated Nano at that step. A runtime whose bridge sends one frame per SIM_CLOCK tick
 * (bridge.sync_to_sim_clock) then reaches the firmware at the same sim steps in every run, so
 * a HIL run with a seed gives the same ground truth twice. A client silent for MAIN_SYNC_LOST_S
 * of wall time (MAIN_FRAME_FIRST_S before its first frame) is given up, as --lockstep-client
 * does. */
#define MAIN_FRAME_TICK_US 20000
#define MAIN_FRAME_FIRST_S 60.0
static void main_frame_wait(sim_t *s, main_sync_t *st) {
  for (int c = 1; c <= sim_cars(s); c++) {
    if (st->lost_rx_us[c] != 0) continue;
    const uint32_t before = st->frames[c];
    const double t_give_up = main_wall_s() + (before ? MAIN_SYNC_LOST_S : MAIN_FRAME_FIRST_S);
    while (!main_stop && (st->frames[c] = sim_host_frames(s, c)) == before) {
      if (main_wall_s() > t_give_up) {
        fprintf(stderr,
                "[autodrive-sim] " AUTODRIVE_VEHICLE_PREFIX
                "%d: no frame from the client for %.1f s (wall): "
                "running on without it\n",
                c, before ? MAIN_SYNC_LOST_S : MAIN_FRAME_FIRST_S);
        st->lost_rx_us[c] = 1;
        break;
      }
      if (!sim_nano_wait_input(s, c, 50)) {
        struct timespec ts = {0, 1000000}; /* a hung-up pty polls ready at once: 1 ms pause */
        nanosleep(&ts, NULL);
      }
    }
    st->started = 1;
  }
}

static int main_number(const char *opt, const char *v, double lo, double hi, double *out) {
  char *end;
  errno = 0;
  const double x = v ? strtod(v, &end) : 0.0;
  if (!v || end == v || *end || errno || !isfinite(x) || x < lo || x > hi) {
    fprintf(stderr, "autodrive-sim: %s '%s': expected a number in [%g, %g]\n", opt, v ? v : "", lo,
            hi);
    return -1;
  }
  *out = x;
  return 0;
}

/* One line on stdout per late box as it appears (scenario logs, tests). */
static void main_report_late_boxes(const sim_t *s) {
  for (int k = 0; k < sim_late_boxes(s); k++) {
    int car = 0;
    if (!sim_late_box_appeared(s, k, &car)) continue;
    const scn_late_box_t *b = sim_late_box(s, k);
    printf("late box %d appeared at t = %.3f s: centre x %.3f, y %.3f m, half sizes %.3f x %.3f m",
           k + 1, (sim_time_us(s) - SIM_STEP_US) * 1e-6, b->x_m, b->y_m, b->half_x_m, b->half_y_m);
    if (car) printf(" (on top of NIGEL%d: contacts will push the car out)", car);
    printf("\n");
    fflush(stdout);
  }
  for (int k = 0; k < sim_late_boxes(s); k++)
    if (sim_late_box_left(s, k)) {
      printf("late box %d left at t = %.3f s\n", k + 1, (sim_time_us(s) - SIM_STEP_US) * 1e-6);
      fflush(stdout);
    }
}

/* Cameras rendered headless (sensors library): front/rear of every car, the overhead Eye. */
#define MAIN_CAMERAS_ALL 1   /* --cameras: front and rear */
#define MAIN_CAMERAS_FRONT 2 /* --front-camera: front only */
#define MAIN_MAX_EYE_CAMS 8  /* a map's eye_cameras (autodrive.maps MAX_EYE_CAMERAS) */
#define MAIN_MAX_CAMS (2 * SIM_MAX_CARS + MAIN_MAX_EYE_CAMS)
typedef struct main_cams {
  int n;
  sim_render_t *render;
  sim_camera_t *cam[MAIN_MAX_CAMS];
  int cam_id[MAIN_MAX_CAMS];
  char channel[MAIN_MAX_CAMS][48], info_channel[MAIN_MAX_CAMS][48];
  int64_t next_info_us;
  cfx_t fx[MAIN_MAX_CAMS]; /* --camera-noise / --camera-blur, seeded per camera */
} main_cams_t;

static void main_cam_fx(uint8_t *rgb, int w, int h, void *ctx) {
  cfx_apply(ctx, rgb, w, h);
}

/* Noise and blur on every camera: each its own seeded noise stream. */
static void main_cams_fx(main_cams_t *k, double noise, double blur_px, uint64_t seed) {
  for (int i = 0; i < k->n; i++) {
    cfx_init(&k->fx[i], noise, blur_px, seed * 2654435761ull + (uint64_t)i);
    if (cfx_active(&k->fx[i])) sim_camera_set_filter(k->cam[i], main_cam_fx, &k->fx[i]);
  }
}

/* A map's several overhead cameras (its eye_cameras): the MJCF cameras whose user data holds
 * their image size (width, height px), as tools/gen-maps writes them. */
static int main_eye_cam_size(const mjModel *m, int id, int *w, int *h) {
  if (m->nuser_cam < 2 || m->cam_user[id * m->nuser_cam] <= 0) return 0;
  *w = (int)m->cam_user[id * m->nuser_cam];
  *h = (int)m->cam_user[id * m->nuser_cam + 1];
  return 1;
}

static int main_eye_cams_n(const mjModel *m) {
  int n = 0, w, h;
  for (int id = 0; id < m->ncam; id++) n += main_eye_cam_size(m, id, &w, &h);
  return n;
}

/* Each on <CAM>_IMAGE and <CAM>_CAMERA_INFO, <CAM> its name in capitals. */
static int main_eye_cams_open(main_cams_t *k, const mjModel *m, char *err, size_t err_sz) {
  for (int id = 0, w, h; id < m->ncam; id++) {
    if (!main_eye_cam_size(m, id, &w, &h)) continue;
    if (k->n >= MAIN_MAX_CAMS) {
      snprintf(err, err_sz, "--eye: more than %d overhead cameras", MAIN_MAX_EYE_CAMS);
      return -1;
    }
    const char *name = mj_id2name(m, mjOBJ_CAMERA, id);
    char cam[24];
    size_t i = 0;
    for (; name[i] && i + 1 < sizeof cam; i++) cam[i] = (char)toupper((unsigned char)name[i]);
    cam[i] = '\0';
    k->cam[k->n] = sim_camera_create(k->render, m, name, name, w, h, 90, err, err_sz);
    if (!k->cam[k->n]) return -1;
    k->cam_id[k->n] = id;
    snprintf(k->channel[k->n], sizeof k->channel[0], "%s" AUTODRIVE_CH_IMAGE_SUFFIX, cam);
    snprintf(k->info_channel[k->n], sizeof k->info_channel[0], "%s" AUTODRIVE_CH_CAMERA_INFO_SUFFIX,
             cam);
    k->n++;
  }
  return 0;
}

static int main_cams_open(main_cams_t *k, const sim_t *s, int cameras, int eye, char *err,
                          size_t err_sz) {
  memset(k, 0, sizeof *k);
  if (!cameras && !eye) return 0;
  const mjModel *m = sim_render_model(s);
  int rw = eye ? 1280 : 640, rh = eye ? 960 : 480; /* the render buffer: the largest image */
  for (int id = 0, w, h; eye && id < m->ncam; id++)
    if (main_eye_cam_size(m, id, &w, &h)) {
      rw = w > rw ? w : rw;
      rh = h > rh ? h : rh;
    }
  k->render = sim_render_create(m, rw, rh, SIM_RENDER_AUTO, err, err_sz);
  if (!k->render) return -1;
  for (int c = 1; cameras && c <= sim_cars(s); c++)
    for (int rear = 0; rear < (cameras == MAIN_CAMERAS_FRONT ? 1 : 2); rear++) {
      char name[48], frame[48];
      snprintf(name, sizeof name, "nigel%d/cam_%s", c, rear ? "rear" : "front");
      snprintf(frame, sizeof frame, "camera_%s", rear ? "rear" : "front");
      k->cam[k->n] = sim_camera_create(k->render, m, name, frame, 640, 480, 85, err, err_sz);
      if (!k->cam[k->n]) return -1;
      k->cam_id[k->n] = mj_name2id(m, mjOBJ_CAMERA, name);
      snprintf(k->channel[k->n], sizeof k->channel[0], AUTODRIVE_VEHICLE_PREFIX "%d%s", c,
               rear ? AUTODRIVE_CH_CAM_REAR_SUFFIX : AUTODRIVE_CH_CAM_FRONT_SUFFIX);
      snprintf(k->info_channel[k->n], sizeof k->info_channel[0], AUTODRIVE_VEHICLE_PREFIX "%d%s", c,
               rear ? AUTODRIVE_CH_CAM_REAR_INFO_SUFFIX : AUTODRIVE_CH_CAM_FRONT_INFO_SUFFIX);
      k->n++;
    }
  if (eye && main_eye_cams_open(k, m, err, err_sz) != 0) return -1;
  if (eye && !main_eye_cams_n(m)) {
    if (mj_name2id(m, mjOBJ_CAMERA, "eye") < 0) {
      snprintf(err, err_sz, "--eye: the map has no camera named 'eye'");
      return -1;
    }
    k->cam[k->n] = sim_camera_create(k->render, m, "eye", "eye", 1280, 960, 90, err, err_sz);
    if (!k->cam[k->n]) return -1;
    snprintf(k->channel[k->n], sizeof k->channel[0], "%s", AUTODRIVE_CH_EYE_IMAGE);
    snprintf(k->info_channel[k->n], sizeof k->info_channel[0], "%s", AUTODRIVE_CH_EYE_CAMERA_INFO);
    k->n++;
  }
  return 0;
}

/* Renders and publishes every camera from dv (the whole map at sim time now_us). */
static int main_cams_publish(main_cams_t *k, const mjModel *mv, mjData *dv, lcm_t *lcm,
                             int64_t now_us, char *err, size_t err_sz) {
  const int info = now_us >= k->next_info_us;
  if (info) k->next_info_us = now_us + 1000000; /* camera_info at 1 Hz */
  for (int i = 0; i < k->n; i++) {
    if (sim_camera_capture(k->cam[i], mv, dv, now_us) != 0) {
      snprintf(err, err_sz, "rendering %s failed", k->channel[i]);
      return -1;
    }
    sim_camera_publish_image(k->cam[i], lcm, k->channel[i]);
    if (info) sim_camera_publish_info(k->cam[i], mv, lcm, k->info_channel[i], now_us);
  }
  return 0;
}

static void main_cams_close(main_cams_t *k) {
  for (int i = 0; i < k->n; i++) {
    sim_camera_destroy(k->cam[i]);
    cfx_free(&k->fx[i]);
  }
  if (k->render) sim_render_destroy(k->render);
  k->n = 0;
}

/* The cameras on their own thread (real time, --rtf, --lockstep-client). Software OpenGL
 * takes ~40 ms of CPU per 1280x960 frame, so rendering Tiny Town's four overhead cameras on
 * the stepping thread stalled it for over 500 ms under load, and the runtimes, which want a
 * Nano frame every 500 ms of wall time, dropped their links. The stepping thread queues a
 * snapshot of the state at each frame time and steps on; the render thread renders them in
 * order. While snapshots wait, the stepping thread sleeps MAIN_RENDER_YIELD_US per step and
 * waiting frame, so the sim slows to what the renderer follows (frames stay in sim time, the
 * ptys never go quiet for long); a frame time that finds the queue full is skipped and
 * counted. Free --lockstep and --lockstep-frames render on the stepping thread, every frame
 * time (repeatable runs). The GL context lives on the render thread. */
#define MAIN_RENDER_QUEUE 4
#define MAIN_RENDER_YIELD_US 3000
typedef struct main_render_thread {
  pthread_t th;
  pthread_mutex_t mu;
  pthread_cond_t cv;
  main_cams_t cams;
  sim_t *s;
  lcm_t *lcm;
  mjData *snap[MAIN_RENDER_QUEUE]; /* a ring of states at frame times */
  int64_t frame_us[MAIN_RENDER_QUEUE];
  int head, queued;         /* next to render; queued (the one in hand included) */
  int stop, opened, failed; /* opened: 1 ok, -1 failed */
  int cameras, eye;         /* main_cams_open's arguments */
  double noise, blur_px;
  uint64_t seed;
  long rendered, skipped;
  char err[256];
} main_render_thread_t;

static void *main_render_run(void *arg) {
  main_render_thread_t *t = arg;
  char err[256] = "";
  int rc = main_cams_open(&t->cams, t->s, t->cameras, t->eye, err, sizeof err);
  if (rc == 0) main_cams_fx(&t->cams, t->noise, t->blur_px, t->seed);
  pthread_mutex_lock(&t->mu);
  t->opened = rc == 0 ? 1 : -1;
  snprintf(t->err, sizeof t->err, "%s", err);
  pthread_cond_broadcast(&t->cv);
  while (rc == 0) {
    while (!t->queued && !t->stop) pthread_cond_wait(&t->cv, &t->mu);
    if (t->stop) break;
    mjData *snap = t->snap[t->head];
    const int64_t frame_us = t->frame_us[t->head];
    pthread_mutex_unlock(&t->mu);
    const int r = main_cams_publish(&t->cams, sim_render_model(t->s), snap, t->lcm, frame_us, err,
                                    sizeof err);
    pthread_mutex_lock(&t->mu);
    if (r != 0) {
      t->failed = 1;
      snprintf(t->err, sizeof t->err, "%s", err);
    }
    t->rendered++;
    t->head = (t->head + 1) % MAIN_RENDER_QUEUE;
    t->queued--;
  }
  pthread_mutex_unlock(&t->mu);
  main_cams_close(&t->cams);
  return NULL;
}

static int main_render_start(main_render_thread_t *t, sim_t *s, lcm_t *lcm, char *err,
                             size_t err_sz) {
  t->s = s;
  t->lcm = lcm;
  for (int i = 0; i < MAIN_RENDER_QUEUE; i++)
    if (!(t->snap[i] = mj_makeData(sim_render_model(s)))) {
      snprintf(err, err_sz, "cannot allocate the render thread's snapshots");
      return -1;
    }
  if (pthread_mutex_init(&t->mu, NULL) != 0 || pthread_cond_init(&t->cv, NULL) != 0 ||
      pthread_create(&t->th, NULL, main_render_run, t) != 0) {
    snprintf(err, err_sz, "cannot start the render thread");
    return -1;
  }
  pthread_mutex_lock(&t->mu);
  while (!t->opened) pthread_cond_wait(&t->cv, &t->mu);
  pthread_mutex_unlock(&t->mu);
  if (t->opened > 0) return 0;
  pthread_join(t->th, NULL);
  snprintf(err, err_sz, "%s", t->err);
  return -1;
}

/* The state at frame time now_us to the render thread's queue, unless it is full. */
static int main_render_submit(main_render_thread_t *t, const sim_t *s, int64_t now_us, char *err,
                              size_t err_sz) {
  pthread_mutex_lock(&t->mu);
  const int failed = t->failed;
  if (failed) {
    snprintf(err, err_sz, "%s", t->err);
  } else if (t->queued == MAIN_RENDER_QUEUE) {
    t->skipped++;
  } else {
    const int tail = (t->head + t->queued) % MAIN_RENDER_QUEUE;
    sim_render_snapshot(s, t->snap[tail]);
    t->frame_us[tail] = now_us;
    t->queued++;
    pthread_cond_signal(&t->cv);
  }
  pthread_mutex_unlock(&t->mu);
  return failed ? -1 : 0;
}

/* Frames waiting behind the one being rendered: the stepping thread's pause this step [us]. */
static long main_render_backlog_us(main_render_thread_t *t) {
  pthread_mutex_lock(&t->mu);
  const int waiting = t->queued > 1 ? t->queued - 1 : 0;
  pthread_mutex_unlock(&t->mu);
  return (long)waiting * MAIN_RENDER_YIELD_US;
}

static void main_render_stop(main_render_thread_t *t) {
  pthread_mutex_lock(&t->mu);
  t->stop = 1;
  pthread_cond_signal(&t->cv);
  pthread_mutex_unlock(&t->mu);
  pthread_join(t->th, NULL);
  for (int i = 0; i < MAIN_RENDER_QUEUE; i++) mj_deleteData(t->snap[i]);
  fprintf(stderr,
          "autodrive-sim: cameras (render thread): %ld frame times rendered, %ld skipped (its "
          "queue was full)\n",
          t->rendered, t->skipped);
}

/* The optional window (sensors library, EGL context): drawn at ~30 Hz of wall time. */
typedef struct main_view {
  sim_viewer_t *v; /* NULL when off */
  double next_frame_s;
} main_view_t;

static int main_view_open(main_view_t *w, const sim_t *s, int want, char *err, size_t err_sz) {
  memset(w, 0, sizeof *w);
  if (!want) return 0;
  if (!sim_viewer_display_available()) {
    snprintf(err, err_sz, "no display (DISPLAY and WAYLAND_DISPLAY are unset); run headless");
    return -1;
  }
  w->v = sim_viewer_create(sim_render_model(s), sim_cars(s), "nigel%d/base_link",
                           "nigel%d/cam_front", 1024, 768, err, err_sz);
  return w->v ? 0 : -1;
}

/* Draws a frame when one is due; blocks while paused (shifting *t0_s so pacing resumes
 * smoothly). Returns 1 when the user quit. */
static int main_view_frame(main_view_t *w, sim_t *s, double *t0_s) {
  sim_viewer_input_t in;
  double now = main_wall_s();
  if (now < w->next_frame_s) return 0;
  do {
    w->next_frame_s = now + 1.0 / 30.0;
    if (sim_viewer_frame(w->v, sim_render_model(s), sim_render_data(s), &in) != 0) return 1;
    if (in.quit || main_stop) return 1;
    if (in.reset_requested) {
      /* back to the start poses (qpos0, sim.c); late boxes that appeared come back on the next
       * step; encoder counts restart with the wheel angles, as when a car
       * is picked up and put back */
      mj_resetData(sim_model(s), sim_data(s));
      mj_forward(sim_model(s), sim_data(s));
    }
    if (in.paused) {
      struct timespec ts = {0, 30000000L};
      nanosleep(&ts, NULL);
      const double later = main_wall_s();
      *t0_s += later - now;
      now = later;
    }
  } while (in.paused);
  return 0;
}

static void main_view_close(main_view_t *w) {
  if (w->v) sim_viewer_destroy(w->v);
  w->v = NULL;
}

/* --car-start: the given cars at their poses, the others where sim_create placed them; through
 * sim_reset, which refuses a pose off the floor or on an obstacle (naming the car). */
static int main_place_cars(sim_t *s, uint64_t seed, const scn_pose_t *pose, const int *given,
                           char *err, size_t err_sz) {
  int any = 0;
  double poses[3 * SIM_MAX_CARS];
  for (int i = 0; i < sim_cars(s); i++) {
    sim_truth_t t;
    sim_get_truth(s, i + 1, &t);
    poses[3 * i] = given[i] ? pose[i].x_m : t.pos_m[0];
    poses[3 * i + 1] = given[i] ? pose[i].y_m : t.pos_m[1];
    poses[3 * i + 2] = given[i] ? pose[i].yaw_deg * (M_PI / 180.0) : t.yaw_rad;
    any |= given[i];
  }
  for (int i = sim_cars(s); i < SIM_MAX_CARS; i++)
    if (given[i]) {
      snprintf(err, err_sz, "car %d, but --cars is %d", i + 1, sim_cars(s));
      return -1;
    }
  return any ? sim_reset(s, seed, poses, err, err_sz) : 0;
}

int main(int argc, char **argv) {
  sim_config_t cfg = {0};
  char params[1024], map[1024];
  snprintf(params, sizeof params, "%s/vehicle/nigel.params", AUTODRIVE_ROOT_DIR);
  snprintf(map, sizeof map, "%s/parking_school.xml", AUTODRIVE_MAPS_DIR);
  cfg.params_path = params;
  cfg.map_path = map;
  cfg.run_dir = "/tmp/autodrive-sim";
  cfg.cars = 1;
  cfg.seed = 1;
  cfg.open_ptys = 1;
  cfg.lidar = 1;
  cfg.tyre_model = -1;
  const char *url = MAIN_DEFAULT_URL, *truth_log = NULL;
  int lockstep = 0, client_sync = 0, frame_sync = 0, bench = 0, quiet = 0, cameras = 0, eye = 0,
      lidar_lcm = 1, view = 0, allow_teleport = 0;
  double camera_fps = 30.0, light_level = -1.0, camera_noise = 0.0, camera_blur = 0.0;
  double rtf = 1.0, duration = 0.0, x;
  int rtf_given = 0;
  int host_io_ms = 0;              /* 0: the mode's default */
  scn_pose_t starts[SIM_MAX_CARS]; /* --start, once for car 1 or once per car */
  int nstarts = 0;
  scn_pose_t car_start[SIM_MAX_CARS]; /* --car-start I,...: car I alone */
  int car_start_given[SIM_MAX_CARS] = {0};
  scn_late_box_t late_box[SCN_MAX_LATE_BOXES];
  char perr[512];
  for (int i = 1; i < argc; i++) {
    const char *a = argv[i], *v = (i + 1 < argc) ? argv[i + 1] : NULL;
    if (!strcmp(a, "-h") || !strcmp(a, "--help")) {
      main_usage(stdout);
      return 0;
    } else if (!strcmp(a, "--cars")) {
      if (main_number(a, v, 1, SIM_MAX_CARS, &x)) return 2;
      cfg.cars = (int)x;
      i++;
    } else if (!strcmp(a, "--map") && v) {
      if (strchr(v, '/') || strstr(v, ".xml"))
        snprintf(map, sizeof map, "%s", v);
      else
        snprintf(map, sizeof map, "%s/%s.xml", AUTODRIVE_MAPS_DIR, v);
      i++;
    } else if (!strcmp(a, "--params") && v) {
      snprintf(params, sizeof params, "%s", v);
      i++;
    } else if (!strcmp(a, "--seed")) {
      if (main_number(a, v, 0, 4e18, &x)) return 2;
      cfg.seed = (uint64_t)x;
      i++;
    } else if (!strcmp(a, "--start")) {
      if (nstarts == SIM_MAX_CARS) {
        fprintf(stderr, "autodrive-sim: --start: more than %d given\n", SIM_MAX_CARS);
        return 2;
      }
      if (scn_parse_start(v, &starts[nstarts], perr, sizeof perr) != 0) {
        fprintf(stderr, "autodrive-sim: %s\n", perr);
        return 2;
      }
      cfg.start = &starts[0];
      nstarts++;
      i++;
    } else if (!strcmp(a, "--car-start")) {
      /* "I,X,Y,YAW_DEG": the car number, then what --start takes */
      char *rest = NULL;
      const long car = v ? strtol(v, &rest, 10) : 0;
      if (!v || rest == v || *rest != ',' || car < 1 || car > SIM_MAX_CARS ||
          scn_parse_start(rest + 1, &car_start[car - 1], perr, sizeof perr) != 0) {
        fprintf(stderr, "autodrive-sim: --car-start '%s': want I,X,Y,YAW_DEG (I = 1..%d)%s%s\n",
                v ? v : "", SIM_MAX_CARS, rest && *rest == ',' ? ": " : "",
                rest && *rest == ',' ? perr : "");
        return 2;
      }
      car_start_given[car - 1] = 1;
      i++;
    } else if (!strcmp(a, "--late-box")) {
      if (cfg.late_boxes == SCN_MAX_LATE_BOXES) {
        fprintf(stderr, "autodrive-sim: --late-box '%s': at most %d late boxes\n", v ? v : "",
                SCN_MAX_LATE_BOXES);
        return 2;
      }
      if (scn_parse_late_box(v, &late_box[cfg.late_boxes], perr, sizeof perr) != 0) {
        fprintf(stderr, "autodrive-sim: %s\n", perr);
        return 2;
      }
      cfg.late_boxes++;
      cfg.late_box = late_box;
      i++;
    } else if (!strcmp(a, "--late-box-stay")) {
      if (cfg.late_boxes == 0) {
        fprintf(stderr, "autodrive-sim: --late-box-stay: give it after the --late-box it is for\n");
        return 2;
      }
      if (main_number(a, v, 0.01, 1e6, &x)) return 2;
      late_box[cfg.late_boxes - 1].stay_s = x;
      i++;
    } else if (!strcmp(a, "--lockstep")) {
      lockstep = 1;
    } else if (!strcmp(a, "--lockstep-client")) {
      lockstep = client_sync = 1;
    } else if (!strcmp(a, "--allow-teleport")) {
      allow_teleport = 1;
    } else if (!strcmp(a, "--lockstep-frames")) {
      lockstep = client_sync = frame_sync = 1;
    } else if (!strcmp(a, "--rtf")) {
      if (main_number(a, v, 0.01, 1e6, &rtf)) return 2;
      rtf_given = 1;
      i++;
    } else if (!strcmp(a, "--duration")) {
      if (main_number(a, v, 0, 1e9, &duration)) return 2;
      i++;
    } else if (!strcmp(a, "--lcm-url") && v) {
      url = v;
      i++;
    } else if (!strcmp(a, "--run-dir") && v) {
      cfg.run_dir = v;
      i++;
    } else if (!strcmp(a, "--script") && v) {
      cfg.script = v;
      i++;
    } else if (!strcmp(a, "--host-io-ms")) {
      if (main_number(a, v, 1, 100, &x)) return 2;
      host_io_ms = (int)x;
      i++;
    } else if (!strcmp(a, "--no-pty")) {
      cfg.open_ptys = 0;
    } else if (!strcmp(a, "--no-lidar")) {
      cfg.lidar = 0;
    } else if (!strcmp(a, "--no-late-obstacles")) {
      cfg.no_map_late_boxes = 1;
    } else if (!strcmp(a, "--no-lidar-lcm")) {
      lidar_lcm = 0;
    } else if (!strcmp(a, "--cameras")) {
      cameras = MAIN_CAMERAS_ALL;
    } else if (!strcmp(a, "--front-camera")) {
      cameras = MAIN_CAMERAS_FRONT;
    } else if (!strcmp(a, "--eye")) {
      eye = 1;
    } else if (!strcmp(a, "--view")) {
      view = 1;
    } else if (!strcmp(a, "--camera-fps")) {
      if (main_number(a, v, 0.1, 1000, &camera_fps)) return 2;
      i++;
    } else if (!strcmp(a, "--light-level")) {
      if (main_number(a, v, 0, 1, &light_level)) return 2;
      i++;
    } else if (!strcmp(a, "--camera-noise")) {
      if (main_number(a, v, 0, CFX_MAX_NOISE, &camera_noise)) return 2;
      i++;
    } else if (!strcmp(a, "--camera-blur")) {
      if (main_number(a, v, 0, CFX_MAX_BLUR_PX, &camera_blur)) return 2;
      i++;
    } else if (!strcmp(a, "--tyre-model") && v) {
      if (!strcmp(v, "paper"))
        cfg.tyre_model = 1;
      else if (!strcmp(v, "mujoco"))
        cfg.tyre_model = 0;
      else {
        fprintf(stderr, "autodrive-sim: --tyre-model '%s': expected paper or mujoco\n", v);
        return 2;
      }
      i++;
    } else if (!strcmp(a, "--truth-log") && v) {
      truth_log = v;
      i++;
    } else if (!strcmp(a, "--bench")) {
      bench = 1;
    } else if (!strcmp(a, "--quiet")) {
      quiet = 1;
    } else {
      fprintf(stderr, "autodrive-sim: unknown option or missing value: '%s' (see --help)\n", a);
      return 2;
    }
  }
  if (lockstep && rtf_given) {
    fprintf(stderr, "autodrive-sim: --lockstep%s and --rtf exclude each other\n",
            client_sync ? "-client" : "");
    return 2;
  }
  if (allow_teleport && !lockstep) {
    fprintf(stderr,
            "autodrive-sim: --allow-teleport needs --lockstep, --lockstep-client or "
            "--lockstep-frames (a car never jumps in a real-time run)\n");
    return 2;
  }
  if (client_sync && !cfg.open_ptys) {
    fprintf(stderr, "autodrive-sim: --lockstep-client needs the ptys (drop --no-pty)\n");
    return 2;
  }

  lcm_t *lcm = lcm_create(url);
  if (!lcm) {
    fprintf(stderr,
            "autodrive-sim: cannot open LCM url '%s' (udpm:// needs a multicast route, e.g. "
            "'ip route add 239.0.0.0/8 dev lo')\n",
            url);
    return 1;
  }
  FILE *tlog = NULL;
  if (truth_log && !(tlog = fopen(truth_log, "wb"))) {
    fprintf(stderr, "autodrive-sim: --truth-log '%s': %s\n", truth_log, strerror(errno));
    lcm_destroy(lcm);
    return 1;
  }
  char err[2048] = "";
  const int free_lockstep = lockstep && !client_sync; /* as fast as it can, nobody to wait for */
  cfg.host_io_period_ms = host_io_ms ? host_io_ms : free_lockstep ? MAIN_FREE_LOCKSTEP_IO_MS : 1;
  sim_t *s = sim_create(&cfg, err, sizeof err);
  if (!s) {
    fprintf(stderr, "autodrive-sim: %s\n", err);
    if (tlog) fclose(tlog);
    lcm_destroy(lcm);
    return 1;
  }
  int bad_starts = nstarts > 1 && nstarts != cfg.cars;
  if (bad_starts)
    snprintf(err, sizeof err,
             "--start given %d times for %d cars: give it once (car 1) or once per car", nstarts,
             cfg.cars);
  if (!bad_starts && nstarts > 1) { /* one start pose per car: car k at the k-th --start */
    double poses[3 * SIM_MAX_CARS];
    for (int k = 0; k < nstarts; k++) {
      poses[3 * k] = starts[k].x_m;
      poses[3 * k + 1] = starts[k].y_m;
      poses[3 * k + 2] = starts[k].yaw_deg * M_PI / 180.0;
    }
    char rerr[400];
    if (sim_reset(s, cfg.seed, poses, rerr, sizeof rerr) != 0) {
      snprintf(err, sizeof err, "--start: %s", rerr);
      bad_starts = 1;
    }
  }
  if (bad_starts ||
      sim_check_scenario(s, err, sizeof err) != 0) { /* a bad --start / --late-box value */
    fprintf(stderr, "autodrive-sim: %s\n", err);
    sim_destroy(s);
    if (tlog) fclose(tlog);
    lcm_destroy(lcm);
    return 2;
  }
  if (main_place_cars(s, cfg.seed, car_start, car_start_given, err, sizeof err) != 0) {
    fprintf(stderr, "autodrive-sim: --car-start: %s\n", err);
    sim_destroy(s);
    if (tlog) fclose(tlog);
    lcm_destroy(lcm);
    return 2;
  }
  if (light_level >= 0 && cfx_set_light_level(sim_render_model(s), light_level) != 0) {
    fprintf(stderr,
            "autodrive-sim: --light-level %g: the map '%s' is dark (level 0): nothing "
            "to scale\n",
            light_level, cfg.map_path);
    sim_destroy(s);
    if (tlog) fclose(tlog);
    lcm_destroy(lcm);
    return 2;
  }
  struct sigaction sa;
  memset(&sa, 0, sizeof sa);
  sa.sa_handler = main_on_signal;
  sigaction(SIGINT, &sa, NULL);
  sigaction(SIGTERM, &sa, NULL);
  signal(SIGPIPE, SIG_IGN);

  main_cams_t cams; /* rendered on this thread; empty when the render thread has them */
  memset(&cams, 0, sizeof cams);
  static main_render_thread_t rthread; /* static: zeroed, and large (its cameras) */
  const int threaded = (cameras || eye) && !(lockstep && (frame_sync || !client_sync));
  rthread.cameras = cameras;
  rthread.eye = eye;
  rthread.noise = camera_noise;
  rthread.blur_px = camera_blur;
  rthread.seed = cfg.seed;
  if (threaded ? main_render_start(&rthread, s, lcm, err, sizeof err) != 0
               : main_cams_open(&cams, s, cameras, eye, err, sizeof err) != 0) {
    fprintf(stderr, "autodrive-sim: %s\n", err);
    sim_destroy(s);
    if (tlog) fclose(tlog);
    lcm_destroy(lcm);
    return 1;
  }
  main_cams_fx(&cams, camera_noise, camera_blur, cfg.seed);
  const int64_t cam_period_us = (int64_t)llround(1e6 / camera_fps);
  /* the map's traffic lights on LCM (none: NULL, nothing subscribed or published) */
  tl_lcm_t *lights =
      tl_lcm_create(lcm, url, sim_traffic_lights(s), !allow_teleport, err, sizeof err);
  if (!lights && err[0]) {
    fprintf(stderr, "autodrive-sim: %s\n", err);
    main_cams_close(&cams);
    sim_destroy(s);
    if (tlog) fclose(tlog);
    lcm_destroy(lcm);
    return 1;
  }
  teleport_lcm_t *teleport = allow_teleport ? teleport_lcm_create(lcm, s, err, sizeof err) : NULL;
  if (allow_teleport && !teleport) {
    fprintf(stderr, "autodrive-sim: %s\n", err);
    tl_lcm_destroy(lights);
    main_cams_close(&cams);
    sim_destroy(s);
    if (tlog) fclose(tlog);
    lcm_destroy(lcm);
    return 1;
  }
  if (teleport) printf("teleport: obeying " AUTODRIVE_CH_SIM_TELEPORT " (--allow-teleport)\n");
  main_view_t viewer;
  if (main_view_open(&viewer, s, view, err, sizeof err) != 0) {
    fprintf(stderr, "autodrive-sim: --view: %s\n", err);
    main_cams_close(&cams);
    sim_destroy(s);
    if (tlog) fclose(tlog);
    lcm_destroy(lcm);
    return 1;
  }
  /* ground truth and SIM_CLOCK leave through a worker thread (lcmq.h) */
  lcmq_t *pubq = lcmq_create(lcm, err, sizeof err);
  if (!pubq) {
    fprintf(stderr, "autodrive-sim: %s\n", err);
    main_view_close(&viewer);
    main_cams_close(&cams);
    sim_destroy(s);
    if (tlog) fclose(tlog);
    lcm_destroy(lcm);
    return 1;
  }
  for (int c = 1; c <= sim_cars(s); c++) {
    if (sim_nano_link(s, c)[0])
      printf(AUTODRIVE_VEHICLE_PREFIX "%d nano: %s\n", c, sim_nano_link(s, c));
    if (sim_lidar_link(s, c)[0])
      printf(AUTODRIVE_VEHICLE_PREFIX "%d lidar: %s\n", c, sim_lidar_link(s, c));
  }
  printf("map: %s, cars: %d, mode: %s, lcm: %s\n", cfg.map_path, cfg.cars,
         frame_sync    ? "lockstep with the client, frame by frame"
         : client_sync ? "lockstep with the client"
         : lockstep    ? "lockstep"
                       : (rtf_given ? "rtf" : "real time"),
         url);
  const route_driver_t *route = sim_route(s);
  if (route)
    printf(
        "route %s: %s, %d points, %.2f m, lane half width %.3f m, throttle %.2f, lookahead "
        "%.2f m\n",
        route->name, route->path.loop ? "loop" : "open", route->path.n, route->path.length_m,
        route->half_width_m, route->speed, route->lookahead_m);
  if (sim_traffic_lights(s)->n)
    printf("traffic lights: %d (%d conflicting pairs) on " AUTODRIVE_CH_TRAFFIC_LIGHT_STATE "\n",
           sim_traffic_lights(s)->n, sim_traffic_lights(s)->nconflicts);
  if (cfg.start)
    printf(AUTODRIVE_VEHICLE_DEFAULT " start (--start): x %.3f, y %.3f m, yaw %.1f deg\n",
           starts[0].x_m, starts[0].y_m, starts[0].yaw_deg);
  fflush(stdout);

  const int64_t end_us = duration > 0 ? (int64_t)llround(duration * 1e6) : -1;
  double t0 = main_wall_s(); /* moved forward by the time spent paused in the viewer */
  const double cpu0 = main_cpu_s(), step_cpu0 = sim_clock_s(CLOCK_THREAD_CPUTIME_ID);
  double next_progress = t0 + MAIN_PROGRESS_S, rtf_now = 0.0, next_flush = t0;
  int64_t last_progress_us = 0;
  int rc = 0;
  long step = 0, slips = 0;
  main_sync_t sync = {0};
  /* --bench in free lockstep: sim blocks paired with bare mj_step blocks (bench_pairs.h) */
  bench_pairs_t pairs = {0};
  const int paired = bench && lockstep && !client_sync && !frame_sync && !viewer.v;
  if (paired && bench_pairs_start(&pairs, s) != 0) {
    fprintf(stderr, "autodrive-sim: --bench: out of memory for the bare mj_step blocks\n");
    rc = 1;
  }
  if (frame_sync) lcmpub_clock(pubq, 0, 0.0, 0); /* the client's first tick */
  while (rc == 0 && !main_stop && (end_us < 0 || sim_time_us(s) < end_us)) {
    if (frame_sync) {
      if (sim_time_us(s) % MAIN_FRAME_TICK_US == 0) {
        lcmq_flush(pubq); /* this tick's SIM_CLOCK: the client answers it with a frame */
        main_frame_wait(s, &sync);
      }
    } else if (client_sync) {
      lcmq_flush(pubq); /* the client may be waiting for the SIM_CLOCK we queued */
      main_sync_wait(s, &sync);
    }
    /* light commands: every step, but every host-I/O period in free lockstep (a system call) */
    if (lights && step % cfg.host_io_period_ms == 0) tl_lcm_poll(lights, sim_time_us(s));
    if (teleport && step % cfg.host_io_period_ms == 0) teleport_lcm_poll(teleport);
    if (sim_step(s, err, sizeof err) != 0) {
      fprintf(stderr, "autodrive-sim: %s\n", err);
      rc = 1;
      break;
    }
    step++;
    const int64_t now_us = sim_time_us(s);
    main_report_late_boxes(s);
    tl_lcm_publish(lights, now_us);
    if (route && route->st.done) {
      printf("route %s done at t = %.3f s\n", route->name, now_us * 1e-6);
      break;
    }
    if (step % MAIN_TRUTH_EVERY == 0)
      for (int c = 1; c <= sim_cars(s); c++) lcmpub_truth(pubq, s, c, tlog);
    for (int c = 1; c <= sim_cars(s); c++) {
      const sim_lidar_scan_t *scan = sim_lidar_new_scan(s, c);
      /* while the runtime's RPLIDAR driver scans on the pty it publishes <VEH>_LIDAR itself:
       * the sim then stays off the channel so that nobody sees every scan twice */
      if (scan && lidar_lcm && !sim_lidar_pty_scanning(s, c)) {
        char ch[32];
        snprintf(ch, sizeof ch, AUTODRIVE_VEHICLE_PREFIX "%d" AUTODRIVE_CH_LIDAR_SUFFIX, c);
        lcmpub_lidar(pubq, ch, "laser", scan);
      }
    }
    if (now_us % cam_period_us < SIM_STEP_US &&
        ((cams.n > 0 && main_cams_publish(&cams, sim_render_model(s), sim_render_data(s), lcm,
                                          now_us, err, sizeof err) != 0) ||
         (threaded && main_render_submit(&rthread, s, now_us, err, sizeof err) != 0))) {
      fprintf(stderr, "autodrive-sim: %s\n", err);
      rc = 1;
      break;
    }
    if (threaded) { /* slow down while frames wait to be rendered */
      const long backlog_us = main_render_backlog_us(&rthread);
      if (backlog_us > 0) {
        const struct timespec ts = {0, backlog_us * 1000L};
        nanosleep(&ts, NULL);
      }
    }
    if ((lockstep || rtf_given) && step % MAIN_CLOCK_EVERY == 0) {
      const double since = main_wall_s() - t0; /* average rtf of the run so far */
      lcmpub_clock(pubq, now_us, since > 0 ? now_us * 1e-6 / since : 0.0, 0);
    }
    if (viewer.v && main_view_frame(&viewer, s, &t0) != 0) break;
    if (paired) { /* the bare block is not part of the run: its time moves the start on */
      const double bare_wall_s = bench_pairs_after_step(&pairs, step);
      t0 += bare_wall_s;
      next_progress += bare_wall_s;
    }
    /* free lockstep paces nothing: it reads the clock (for the LCM flush and progress) every
     * MAIN_FREE_CLOCK_EVERY steps only, as a read costs ~0.5 % of a 1-car step */
    if (free_lockstep && step % MAIN_FREE_CLOCK_EVERY != 0) continue;
    /* pacing: real time or rtf x real time; lockstep runs free */
    const double wall = main_wall_s();
    if (wall >= next_flush) { /* queued LCM messages leave within the flush period */
      lcmq_flush(pubq);
      next_flush = wall + (free_lockstep ? MAIN_FREE_LCM_FLUSH_S : MAIN_LCM_FLUSH_S);
    }
    /* --lockstep-client runs in real time until a client first writes, then in step with it */
    if (!lockstep || (client_sync && !sync.started)) {
      const double ahead = t0 + now_us * 1e-6 / rtf - wall;
      if (ahead < -MAIN_MAX_LAG_S) {
        /* Behind (a slow frame, the window, a loaded CPU): slip the schedule rather than burst
         * through the backlog. A burst would advance sim time with no bytes arriving on the
         * pty, and the emulated Nano's failsafe would trip on a client that is fine. */
        t0 -= ahead;
        slips++;
      } else if (ahead > 0.0005) {
        struct timespec ts = {(time_t)ahead, (long)((ahead - floor(ahead)) * 1e9)};
        nanosleep(&ts, NULL);
      }
    }
    if (wall >= next_progress) {
      rtf_now = (now_us - last_progress_us) * 1e-6 / (wall - next_progress + MAIN_PROGRESS_S);
      last_progress_us = now_us;
      next_progress = wall + MAIN_PROGRESS_S;
      if (!quiet)
        fprintf(stderr, "[autodrive-sim] t = %.1f s sim, rtf %.2f%s\n", now_us * 1e-6, rtf_now,
                slips ? " (fell behind: schedule slipped)" : "");
      slips = 0;
    }
  }
  /* the stepping thread alone: what bounds the rtf when the LCM worker has a core of its own */
  const double step_cpu_s =
      sim_clock_s(CLOCK_THREAD_CPUTIME_ID) - step_cpu0 - bench_pairs_bare_cpu_s(&pairs);
  const uint64_t lcm_failures = lcmq_failures(pubq);
  lcmq_destroy(pubq); /* sends what is still queued: part of the run's time */
  const double wall_s = main_wall_s() - t0,
               cpu_s = main_cpu_s() - cpu0 - bench_pairs_bare_cpu_s(&pairs);
  if (lcm_failures)
    fprintf(stderr, "autodrive-sim: LCM refused %llu ground-truth/clock message(s) on '%s'\n",
            (unsigned long long)lcm_failures, url);
  const double sim_s = sim_time_us(s) * 1e-6;
  if (bench) {
    printf(
        "{\"cars\": %d, \"sim_s\": %.3f, \"wall_s\": %.3f, \"cpu_s\": %.3f, \"rtf\": %.3f, "
        "\"rtf_cpu\": %.3f, \"rtf_step_thread_cpu\": %.3f, \"steps\": %ld",
        sim_cars(s), sim_s, wall_s, cpu_s, wall_s > 0 ? sim_s / wall_s : 0.0,
        cpu_s > 0 ? sim_s / cpu_s : 0.0, step_cpu_s > 0 ? sim_s / step_cpu_s : 0.0, step);
    if (pairs.n > 0) {
      bench_pairs_print_json(&pairs, stdout);
    } else { /* not paired (a short or paced run): one bare loop after the run */
      const int bare_steps = (int)fmin(sim_s * 1000.0, 20000.0);
      double bare_cpu_s = 0.0;
      const double bare_s = sim_bare_mj_step_s(s, bare_steps, &bare_cpu_s);
      printf(", \"bare_mj_step_rtf\": %.3f, \"bare_mj_step_rtf_cpu\": %.3f, \"bare_steps\": %d",
             bare_s > 0 ? bare_steps * 1e-3 / bare_s : 0.0,
             bare_cpu_s > 0 ? bare_steps * 1e-3 / bare_cpu_s : 0.0, bare_steps);
    }
    if (route) {
      double rms, max;
      const long n = route_driver_stats(route, &rms, &max);
      printf(
          ", \"route\": \"%s\", \"route_done\": %s, \"route_length_m\": %.3f, "
          "\"route_samples\": %ld, \"route_cross_track_rms_m\": %.5f, "
          "\"route_cross_track_max_m\": %.5f",
          route->name, route->st.done ? "true" : "false", route->path.length_m, n, rms, max);
    }
    long refused = 0;
    const long commands = tl_lcm_commands(lights, &refused);
    printf(", \"lights\": %d, \"light_commands\": %ld, \"light_commands_refused\": %ld}\n",
           sim_traffic_lights(s)->n, commands, refused);
  }
  bench_pairs_free(&pairs);
  tl_lcm_destroy(lights);
  teleport_lcm_destroy(teleport);
  main_view_close(&viewer);
  if (threaded) main_render_stop(&rthread);
  main_cams_close(&cams);
  sim_destroy(s); /* removes the ptys' symlinks */
  if (tlog) fclose(tlog);
  lcm_destroy(lcm);
  return rc;
}
