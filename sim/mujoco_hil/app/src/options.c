/* autodrive-sim's command line (options.h). */
#include "options.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include <autodrive_channels.h>
#include <autodrive_instance_rule.h>

#include "camera_fx.h"
#include "cameras.h"
#include "sim_viewer.h"
#include "eye_sync.h"
#include "script.h"
#include "sim_instance.h"

#define OPTIONS_BAD 2        /* a bad option or value: the exit status */
#define OPTIONS_UNKNOWN -2   /* not an option of this group */
#define OPTIONS_VIEW_NICE 10 /* --view-nice's default */

/* --help, part 1: what the program is, and the world it builds (cars, map, starts, boxes). */
static void options_usage_world(FILE *f) {
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
      "  --distractors N     N (0..%d) static cones, boxes and parked-car-sized boxes placed\n"
      "                      from --seed beside the road: off every lane, clear of the cars'\n"
      "                      starts, the map's obstacles and each other (an error when the\n"
      "                      map has no room); cameras and LIDAR see them\n",
      SIM_MAX_CARS, AUTODRIVE_ROOT_DIR, SCN_LATE_BOX_HALF_DEFAULT_M, SCN_LATE_BOX_HEIGHT_M,
      SCN_MAX_LATE_BOXES, SIM_MAX_DISTRACTORS);
}

/* --help, part 2: how the run keeps time, its bus, run dir and driver. */
static void options_usage_run(FILE *f) {
  fprintf(
      f,
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
      "  --run-dir DIR       ptys' symlinks and the generated scene (default %s)\n"
      "  --instance N        this session's instance 0..%d (default: $%s, else 0):\n"
      "                      instance N > 0 moves the LCM URL on the default port to\n"
      "                      that port + %d N and the default run dir to <run dir>-N,\n"
      "                      so two users' sims, runtimes and SCMs never hear each other\n"
      "  --script SPEC       scripted driver instead of a client on the pty, for tests and\n"
      "                      benchmarks: constant:throttle=T,steering=S[,start=s][,stop_after=s]\n"
      "                      or route:NAME[,speed=F][,start=s][,lookahead=M][,laps=N]\n"
      "                      [,perturb=A]: pure pursuit on the map's route NAME at F of top\n"
      "                      speed (default %g), lookahead M [m] (default %g), from the\n"
      "                      route's start (--cars 1); the run ends when the route does (N\n"
      "                      laps of a loop, default 1); A > 0 adds seeded steering\n"
      "                      perturbations up to A (normalised) now and then (expert\n"
      "                      recordings with recoveries, tools/pilot)\n"
      "  --no-pty            do not open ptys (with --script)\n",
      OPTIONS_FREE_LOCKSTEP_IO_MS, AUTODRIVE_LCM_URL_DEFAULT, AUTODRIVE_SIM_RUN_DIR_DEFAULT,
      AUTODRIVE_INSTANCE_MAX, AUTODRIVE_INSTANCE_VARIABLE, AUTODRIVE_INSTANCE_PORT_STEP,
      SCRIPT_ROUTE_SPEED_DEFAULT, SCRIPT_ROUTE_LOOKAHEAD_DEFAULT_M);
}

/* --help, part 3: the sensors (LIDAR, cameras, the Eye), the late obstacles, the physics. */
static void options_usage_sensors(FILE *f) {
  fprintf(
      f,
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
      "  --eye-sync          (lockstep modes, with --eye) lockstep with the Eye: after a\n"
      "                      frame captured at t the sim does not step past t + L until\n"
      "                      autodrive-eye run --sim-latency-ms L has published its poses\n"
      "                      (EYE_FRAME_DONE); it publishes SIM_CLOCK at t + L, when the Eye\n"
      "                      releases them. Before the first frame it waits up to 60 s\n"
      "                      (wall) for the Eye to say it is ready; an Eye silent for 10 s\n"
      "                      (wall) while waited for is given up until it answers again.\n"
      "                      Each give-up is a stderr line with '" EYE_SYNC_GIVE_UP_MARK
      "'\n"
      "                      (the run then depended on wall time), counted at exit\n"
      "  --eye-sync-wait-s S (with --eye-sync) give a silent Eye up after S s of wall time\n"
      "                      (%g..%g; default %g; before the first frame max(S, %g))\n"
      "  --eye-render MODE   cached (default): an overhead camera renders the static world\n"
      "                      once and draws only what moves over it; full: every frame in\n"
      "                      full; compare: both, the cached one published (--bench reports\n"
      "                      their times and how their pixels differ)\n"
      "  --camera-fps F      camera frame rate in sim time (default 30)\n"
      "  --texture-dir DIR   the map's textures from DIR/textures/ instead of its own folder's\n"
      "                      (a road style: tools/pilot's domain randomisation)\n"
      "  --light-level X     scene light level 0..1 (1 = day) instead of the map's own\n"
      "  --camera-noise S    Gaussian noise on rendered frames, sigma S [8-bit levels, 0..%g]\n"
      "  --camera-blur PX    Gaussian blur on rendered frames, sigma PX [px, 0..%g]\n"
      "                      (noise and blur are seeded by --seed: a run repeats)\n"
      "  --light-rgb R,G,B   the lights' colour: a gain per channel (%g..%g) on every light's\n"
      "                      diffuse and specular colour (with --light-level too)\n"
      "  --camera-exposure EV\n"
      "                      the cars' camera frames x 2^EV (EV %g..%g), clipped at 255 as a\n"
      "                      sensor clips, before blur and noise (the Eye's cameras stay)\n"
      "  --camera-jitter MM,DEG\n"
      "                      each car's front camera mount moved by up to +-MM [mm, 0..%g] per\n"
      "                      axis and turned by up to +-DEG [deg, 0..%g] about each, drawn once\n"
      "                      from --seed and the car (printed at start; intrinsics stay)\n"
      "  --camera-scale S    render the cars' cameras at S x their size per side and stretch\n"
      "                      the frames back (%g..1, default 1: a slow machine's trade of\n"
      "                      sharpness for render time; the Eye's cameras stay full)\n"
      "  --tyre-model M      paper or mujoco (default: the parameter file's)\n"
      "  --truth-log FILE    also write every ground-truth message to FILE (determinism checks)\n",
      EYE_SYNC_WAIT_MIN_S, EYE_SYNC_WAIT_MAX_S, EYE_SYNC_LOST_S, EYE_SYNC_FIRST_S, CFX_MAX_NOISE,
      CFX_MAX_BLUR_PX, CFX_MIN_LIGHT_GAIN, CFX_MAX_LIGHT_GAIN, -CFX_MAX_EXPOSURE_EV,
      CFX_MAX_EXPOSURE_EV, CFX_MAX_JITTER_MM, CFX_MAX_JITTER_DEG, SIM_CAMERA_MIN_SCALE);
}

/* --help, part 4: the outputs (bench, window, video, record), channels, exit status. */
static void options_usage_output(FILE *f) {
  fputs(
      "  --bench             print a JSON summary (sim_s, wall_s, rtf, bare_mj_step_rtf) at exit\n"
      "  --bench-unpaired    --bench without bare mj_step blocks paired into free lockstep (the\n"
      "                      headless baseline of a --view run, which is never paired)\n"
      "  --view              open a window (needs a display): 1/2/3 driver's, bird's, god's\n"
      "                      eye, 4 free; Tab next car; N day/night; Space pause; R reset;\n"
      "                      M the Menu Panel; H the HUD; T manual driving (arrows or WASD,\n"
      "                      through autodrive-teleop: signed, on the control lease); Esc quit\n"
      "  --view-size WxH     the window's size (default 1024x768 px)\n"
      "  --view-scale S      the window's scene drawn at S (0.25..1) of its pixels per side and\n"
      "                      stretched (default 1, and 0.5 on software GL such as llvmpipe)\n"
      "  --view-quality Q    low (default: no shadows, reflections, skybox), high (shadows)\n"
      "                      or ultra (shadows, reflections, skybox); the View section's boxes\n"
      "  --view-nice N       the nice of the window's drawing and software-rasteriser threads\n"
      "                      (0..19, default 10: the window takes the CPU the sim and the\n"
      "                      programs on its ptys leave; 0: the window competes with them)\n"
      "  --gamepad PATH      with --view: manual driving also reads this Linux joystick\n"
      "                      (e.g. /dev/input/js0; through autodrive-teleop: hold the dead-man\n"
      "                      button LB, left stick throttle, right stick steering); the keys\n"
      "                      still work beside it\n"
      "  --hud-log FILE      with --view: each drawn frame's HUD text as a line of FILE (sim\n"
      "                      time [us], then title=value fields, tab-separated)\n"
      "  --video FILE        write an MP4 of --video-camera, one frame per 1/30 s of sim\n"
      "                      time stamped with it, and FILE.frames.csv (frame, sim_time_us);\n"
      "                      needs Debian's ffmpeg\n"
      "  --record DIR        the same video as DIR/view.mp4 (+ view_frames.csv) and the LCM\n"
      "                      log of every channel, DIR/run.lcmlog (lcm-logger)\n"
      "  --video-camera NAME the camera recorded (default nigel1/cam_front; eye: the overhead)\n"
      "  --quiet             no progress lines\n"
      "  -h, --help          this text\n"
      "Publishes NIGEL<i>_GROUND_TRUTH (100 Hz), NIGEL<i>_LIDAR (when built with sensors),\n"
      "SIM_CLOCK (100 Hz, with --lockstep or --rtf) and, on maps with traffic lights,\n"
      "TRAFFIC_LIGHT_STATE (10 Hz per light and on each change); obeys TRAFFIC_LIGHT_COMMAND.\n"
      "Exit status: 0 done; 2 a bad option or value (also a --start or --late-box that does\n"
      "not fit the map); 1 any other error (files, map, LCM, physics).\n",
      f);
}

/* --help, in sections so that each stays short. */
static void options_usage(FILE *f) {
  options_usage_world(f);
  options_usage_run(f);
  options_usage_sensors(f);
  options_usage_output(f);
}

/* v as one of n names: *out = values[k] for names[k] and 1 (one value taken), or a message
 * naming opt, v and every name, and OPTIONS_BAD. */
static int options_pick(const char *opt, const char *v, const char *const *names, const int *values,
                        int n, int *out) {
  for (int k = 0; k < n; k++)
    if (!strcmp(v, names[k])) {
      *out = values[k];
      return 1;
    }
  fprintf(stderr, "autodrive-sim: %s '%s': expected ", opt, v);
  for (int k = 0; k < n; k++)
    fprintf(stderr, "%s%s", k == 0 ? "" : k == n - 1 ? " or " : ", ", names[k]);
  fputc('\n', stderr);
  return OPTIONS_BAD;
}

static int options_number(const char *opt, const char *v, double lo, double hi, double *out) {
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

/* n comma-separated numbers, each in [lo[k], hi[k]] (what names them in the message). */
static int options_numbers(const char *opt, const char *v, int n, const double *lo,
                           const double *hi, const char *what, double *out) {
  const char *p = v;
  int k = 0;
  for (; p && k < n; k++) {
    char *end;
    errno = 0;
    const double x = strtod(p, &end);
    if (end == p || errno || !isfinite(x) || x < lo[k] || x > hi[k]) break;
    out[k] = x;
    if (k + 1 < n && *end != ',') break;
    if (k + 1 == n && *end) break;
    p = end + 1;
  }
  if (p && k == n) return 0;
  fprintf(stderr, "autodrive-sim: %s '%s': expected %s\n", opt, v ? v : "", what);
  return -1;
}

static void options_defaults(app_options_t *o) {
  memset(o, 0, sizeof *o);
  snprintf(o->params, sizeof o->params, "%s/vehicle/nigel.params", AUTODRIVE_ROOT_DIR);
  snprintf(o->map, sizeof o->map, "%s/parking_school.xml", AUTODRIVE_MAPS_DIR);
  o->cfg.params_path = o->params;
  o->cfg.map_path = o->map;
  o->cfg.run_dir = AUTODRIVE_SIM_RUN_DIR_DEFAULT;
  o->cfg.cars = 1;
  o->cfg.seed = 1;
  o->cfg.open_ptys = 1;
  o->cfg.lidar = 1;
  o->cfg.tyre_model = -1;
  o->url = AUTODRIVE_LCM_URL_DEFAULT;
  o->lidar_lcm = 1;
  o->video_camera = "nigel1/cam_front";
  o->view_w = 1024;
  o->view_h = 768;
  o->view_nice = OPTIONS_VIEW_NICE;
  o->camera_fps = 30.0;
  o->eye_sync_wait_s = EYE_SYNC_LOST_S;
  o->light_level = -1.0;
  o->light_rgb[0] = o->light_rgb[1] = o->light_rgb[2] = 1.0;
  o->camera_scale = 1.0;
  o->rtf = 1.0;
}

/* --start X,Y,YAW_DEG: once for car 1, or once per car. */
static int options_start(app_options_t *o, const char *v) {
  char perr[512];
  if (o->nstarts == SIM_MAX_CARS) {
    fprintf(stderr, "autodrive-sim: --start: more than %d given\n", SIM_MAX_CARS);
    return OPTIONS_BAD;
  }
  if (scn_parse_start(v, &o->starts[o->nstarts], perr, sizeof perr) != 0) {
    fprintf(stderr, "autodrive-sim: %s\n", perr);
    return OPTIONS_BAD;
  }
  o->cfg.start = &o->starts[0];
  o->nstarts++;
  return 1;
}

/* --car-start "I,X,Y,YAW_DEG": the car number, then what --start takes. */
static int options_car_start(app_options_t *o, const char *v) {
  char perr[512];
  char *rest = NULL;
  const long car = v ? strtol(v, &rest, 10) : 0;
  if (!v || rest == v || *rest != ',' || car < 1 || car > SIM_MAX_CARS ||
      scn_parse_start(rest + 1, &o->car_start[car - 1], perr, sizeof perr) != 0) {
    fprintf(stderr, "autodrive-sim: --car-start '%s': want I,X,Y,YAW_DEG (I = 1..%d)%s%s\n",
            v ? v : "", SIM_MAX_CARS, rest && *rest == ',' ? ": " : "",
            rest && *rest == ',' ? perr : "");
    return OPTIONS_BAD;
  }
  o->car_start_given[car - 1] = 1;
  return 1;
}

/* --late-box X,Y,T[,SX,SY[,R]] and --late-box-stay S (for the --late-box before it). */
static int options_late_box(app_options_t *o, const char *a, const char *v) {
  char perr[512];
  double x;
  if (!strcmp(a, "--late-box-stay")) {
    if (o->cfg.late_boxes == 0) {
      fprintf(stderr, "autodrive-sim: --late-box-stay: give it after the --late-box it is for\n");
      return OPTIONS_BAD;
    }
    if (options_number(a, v, 0.01, 1e6, &x)) return OPTIONS_BAD;
    o->late_box[o->cfg.late_boxes - 1].stay_s = x;
    return 1;
  }
  if (o->cfg.late_boxes == SCN_MAX_LATE_BOXES) {
    fprintf(stderr, "autodrive-sim: --late-box '%s': at most %d late boxes\n", v ? v : "",
            SCN_MAX_LATE_BOXES);
    return OPTIONS_BAD;
  }
  if (scn_parse_late_box(v, &o->late_box[o->cfg.late_boxes], perr, sizeof perr) != 0) {
    fprintf(stderr, "autodrive-sim: %s\n", perr);
    return OPTIONS_BAD;
  }
  o->cfg.late_boxes++;
  o->cfg.late_box = o->late_box;
  return 1;
}

/* The world: cars, map, vehicle, seed, start poses, late boxes, tyres, ptys, LIDAR, driver.
 * Returns how many values it took (0 or 1), OPTIONS_BAD or OPTIONS_UNKNOWN. */
static int options_world(app_options_t *o, const char *a, const char *v) {
  double x;
  if (!strcmp(a, "--cars")) {
    if (options_number(a, v, 1, SIM_MAX_CARS, &x)) return OPTIONS_BAD;
    o->cfg.cars = (int)x;
    return 1;
  } else if (!strcmp(a, "--map") && v) {
    if (strchr(v, '/') || strstr(v, ".xml"))
      snprintf(o->map, sizeof o->map, "%s", v);
    else
      snprintf(o->map, sizeof o->map, "%s/%s.xml", AUTODRIVE_MAPS_DIR, v);
    return 1;
  } else if (!strcmp(a, "--texture-dir") && v) {
    o->cfg.texture_dir = v;
    return 1;
  } else if (!strcmp(a, "--params") && v) {
    snprintf(o->params, sizeof o->params, "%s", v);
    return 1;
  } else if (!strcmp(a, "--seed")) {
    if (options_number(a, v, 0, 4e18, &x)) return OPTIONS_BAD;
    o->cfg.seed = (uint64_t)x;
    return 1;
  } else if (!strcmp(a, "--start")) {
    return options_start(o, v);
  } else if (!strcmp(a, "--car-start")) {
    return options_car_start(o, v);
  } else if (!strcmp(a, "--late-box") || !strcmp(a, "--late-box-stay")) {
    return options_late_box(o, a, v);
  } else if (!strcmp(a, "--script") && v) {
    o->cfg.script = v;
    return 1;
  } else if (!strcmp(a, "--no-pty")) {
    o->cfg.open_ptys = 0;
  } else if (!strcmp(a, "--no-lidar")) {
    o->cfg.lidar = 0;
  } else if (!strcmp(a, "--no-late-obstacles")) {
    o->cfg.no_map_late_boxes = 1;
  } else if (!strcmp(a, "--tyre-model") && v) {
    if (!strcmp(v, "paper")) {
      o->cfg.tyre_model = 1;
    } else if (!strcmp(v, "mujoco")) {
      o->cfg.tyre_model = 0;
    } else {
      fprintf(stderr, "autodrive-sim: --tyre-model '%s': expected paper or mujoco\n", v);
      return OPTIONS_BAD;
    }
    return 1;
  } else {
    return OPTIONS_UNKNOWN;
  }
  return 0;
}

/* The run: clock mode, duration, LCM, run dir, host I/O period, logs and reports. */
static int options_run(app_options_t *o, const char *a, const char *v) {
  double x;
  if (!strcmp(a, "--lockstep")) {
    o->lockstep = 1;
  } else if (!strcmp(a, "--lockstep-client")) {
    o->lockstep = o->client_sync = 1;
  } else if (!strcmp(a, "--allow-teleport")) {
    o->allow_teleport = 1;
  } else if (!strcmp(a, "--lockstep-frames")) {
    o->lockstep = o->client_sync = o->frame_sync = 1;
  } else if (!strcmp(a, "--rtf")) {
    if (options_number(a, v, 0.01, 1e6, &o->rtf)) return OPTIONS_BAD;
    o->rtf_given = 1;
    return 1;
  } else if (!strcmp(a, "--duration")) {
    return options_number(a, v, 0, 1e9, &o->duration_s) ? OPTIONS_BAD : 1;
  } else if (!strcmp(a, "--lcm-url") && v) {
    o->url = v;
    return 1;
  } else if (!strcmp(a, "--run-dir") && v) {
    o->cfg.run_dir = v;
    o->run_dir_given = 1;
    return 1;
  } else if (!strcmp(a, "--instance")) {
    if ((o->instance = sim_instance_parse(v)) < 0) {
      fprintf(stderr, "autodrive-sim: --instance '%s': expected a number in 0..%d\n", v ? v : "",
              AUTODRIVE_INSTANCE_MAX);
      return OPTIONS_BAD;
    }
    return 1;
  } else if (!strcmp(a, "--host-io-ms")) {
    if (options_number(a, v, 1, 100, &x)) return OPTIONS_BAD;
    o->host_io_ms = (int)x;
    return 1;
  } else if (!strcmp(a, "--truth-log") && v) {
    o->truth_log = v;
    return 1;
  } else if (!strcmp(a, "--hud-log") && v) {
    o->hud_log = v;
    return 1;
  } else if (!strcmp(a, "--bench")) {
    o->bench = 1;
  } else if (!strcmp(a, "--bench-unpaired")) {
    o->bench = o->bench_unpaired = 1;
  } else if (!strcmp(a, "--quiet")) {
    o->quiet = 1;
  } else if (!strcmp(a, "--video") && v) {
    o->video = v;
    return 1;
  } else if (!strcmp(a, "--record") && v) {
    o->record_dir = v;
    return 1;
  } else if (!strcmp(a, "--video-camera") && v) {
    o->video_camera = v;
    return 1;
  } else {
    return OPTIONS_UNKNOWN;
  }
  return 0;
}

static int options_randomise(app_options_t *o, const char *a, const char *v);

/* What is rendered and published: LIDAR on LCM, cameras, the Eye, the window, camera effects. */
static int options_output(app_options_t *o, const char *a, const char *v) {
  if (!strcmp(a, "--no-lidar-lcm")) {
    o->lidar_lcm = 0;
  } else if (!strcmp(a, "--cameras")) {
    o->cameras = CAMERAS_ALL;
  } else if (!strcmp(a, "--front-camera")) {
    o->cameras = CAMERAS_FRONT;
  } else if (!strcmp(a, "--eye")) {
    o->eye = 1;
  } else if (!strcmp(a, "--eye-sync")) {
    o->eye_sync = 1;
  } else if (!strcmp(a, "--eye-sync-wait-s")) {
    o->eye_sync_wait_given = 1;
    return options_number(a, v, EYE_SYNC_WAIT_MIN_S, EYE_SYNC_WAIT_MAX_S, &o->eye_sync_wait_s)
               ? OPTIONS_BAD
               : 1;
  } else if (!strcmp(a, "--eye-render") && v) {
    static const char *const names[] = {"cached", "full", "compare"};
    static const int modes[] = {CAMERAS_RENDER_CACHED, CAMERAS_RENDER_FULL, CAMERAS_RENDER_COMPARE};
    return options_pick(a, v, names, modes, 3, &o->eye_render);
  } else if (!strcmp(a, "--view")) {
    o->view = 1;
  } else if (!strcmp(a, "--gamepad") && v) {
    o->gamepad = v;
    return 1;
  } else if (!strcmp(a, "--view-quality") && v) {
    static const char *const names[] = {"low", "high", "ultra"};
    static const int levels[] = {SIM_VIEWER_QUALITY_LOW, SIM_VIEWER_QUALITY_HIGH,
                                 SIM_VIEWER_QUALITY_ULTRA};
    const int taken = options_pick(a, v, names, levels, 3, &o->view_quality);
    o->view_quality_given = taken == 1;
    return taken;
  } else if (!strcmp(a, "--view-nice")) {
    double n = 0;
    if (options_number(a, v, 0, 19, &n) || n != floor(n)) {
      if (n != floor(n))
        fprintf(stderr, "autodrive-sim: --view-nice '%s': expected a whole number in [0, 19]\n", v);
      return OPTIONS_BAD;
    }
    o->view_nice = (int)n;
    o->view_nice_given = 1;
    return 1;
  } else if (!strcmp(a, "--view-scale")) {
    return options_number(a, v, SIM_VIEWER_MIN_SCALE, 1.0, &o->view_scale) ? OPTIONS_BAD : 1;
  } else if (!strcmp(a, "--view-size")) {
    char tail = 0;
    if (!v || sscanf(v, "%dx%d%c", &o->view_w, &o->view_h, &tail) != 2 || o->view_w < 640 ||
        o->view_h < 600 || o->view_w > 7680 || o->view_h > 4320) {
      fprintf(stderr, "autodrive-sim: --view-size '%s': expected WxH, 640x600 to 7680x4320 px\n",
              v ? v : "");
      return OPTIONS_BAD;
    }
    return 1;
  } else if (!strcmp(a, "--camera-fps")) {
    return options_number(a, v, 0.1, 1000, &o->camera_fps) ? OPTIONS_BAD : 1;
  } else if (!strcmp(a, "--light-level")) {
    return options_number(a, v, 0, 1, &o->light_level) ? OPTIONS_BAD : 1;
  } else if (!strcmp(a, "--camera-noise")) {
    return options_number(a, v, 0, CFX_MAX_NOISE, &o->camera_noise) ? OPTIONS_BAD : 1;
  } else if (!strcmp(a, "--camera-blur")) {
    return options_number(a, v, 0, CFX_MAX_BLUR_PX, &o->camera_blur) ? OPTIONS_BAD : 1;
  } else if (!strcmp(a, "--camera-scale")) {
    return options_number(a, v, SIM_CAMERA_MIN_SCALE, 1, &o->camera_scale) ? OPTIONS_BAD : 1;
  } else {
    return options_randomise(o, a, v);
  }
  return 0;
}

/* Domain randomisation beyond noise and blur: light colour, exposure, mount jitter, distractors. */
static int options_randomise(app_options_t *o, const char *a, const char *v) {
  double x = 0;
  if (!strcmp(a, "--light-rgb")) {
    static const double lo[3] = {CFX_MIN_LIGHT_GAIN, CFX_MIN_LIGHT_GAIN, CFX_MIN_LIGHT_GAIN};
    static const double hi[3] = {CFX_MAX_LIGHT_GAIN, CFX_MAX_LIGHT_GAIN, CFX_MAX_LIGHT_GAIN};
    char what[96];
    snprintf(what, sizeof what, "R,G,B, each a gain in [%g, %g]", CFX_MIN_LIGHT_GAIN,
             CFX_MAX_LIGHT_GAIN);
    return options_numbers(a, v, 3, lo, hi, what, o->light_rgb) ? OPTIONS_BAD : 1;
  } else if (!strcmp(a, "--camera-exposure")) {
    return options_number(a, v, -CFX_MAX_EXPOSURE_EV, CFX_MAX_EXPOSURE_EV, &o->camera_exposure)
               ? OPTIONS_BAD
               : 1;
  } else if (!strcmp(a, "--camera-jitter")) {
    static const double lo[2] = {0, 0}, hi[2] = {CFX_MAX_JITTER_MM, CFX_MAX_JITTER_DEG};
    char what[96];
    snprintf(what, sizeof what, "MM,DEG with MM in [0, %g] mm and DEG in [0, %g] deg",
             CFX_MAX_JITTER_MM, CFX_MAX_JITTER_DEG);
    double mm_deg[2];
    if (options_numbers(a, v, 2, lo, hi, what, mm_deg)) return OPTIONS_BAD;
    o->jitter_mm = mm_deg[0];
    o->jitter_deg = mm_deg[1];
    return 1;
  } else if (!strcmp(a, "--distractors")) {
    if (options_number(a, v, 0, SIM_MAX_DISTRACTORS, &x) || x != floor(x)) {
      if (x != floor(x))
        fprintf(stderr, "autodrive-sim: --distractors '%s': expected a whole number in [0, %d]\n",
                v, SIM_MAX_DISTRACTORS);
      return OPTIONS_BAD;
    }
    o->cfg.distractors = (int)x;
    return 1;
  } else {
    return OPTIONS_UNKNOWN;
  }
  return 0;
}

/* --gamepad: a readable joystick device (or a FIFO carrying its events), checked now rather
 * than when Manual is first clicked. */
static int options_gamepad_check(const char *path) {
  struct stat st;
  const char *why = NULL;
  if (stat(path, &st) != 0 || access(path, R_OK) != 0)
    why = strerror(errno);
  else if (!S_ISCHR(st.st_mode) && !S_ISFIFO(st.st_mode))
    why = "not a character device (a gamepad is /dev/input/jsN)";
  if (!why) return 0;
  fprintf(stderr, "autodrive-sim: --gamepad '%s': %s\n", path, why);
  return -1;
}

/* Options that exclude or need each other. */
static int options_check(const app_options_t *o) {
  if (o->lockstep && o->rtf_given) {
    fprintf(stderr, "autodrive-sim: --lockstep%s and --rtf exclude each other\n",
            o->client_sync ? "-client" : "");
    return OPTIONS_BAD;
  }
  if (o->allow_teleport && !o->lockstep) {
    fprintf(stderr,
            "autodrive-sim: --allow-teleport needs --lockstep, --lockstep-client or "
            "--lockstep-frames (a car never jumps in a real-time run)\n");
    return OPTIONS_BAD;
  }
  if (o->eye_sync_wait_given && !o->eye_sync) {
    fprintf(stderr, "autodrive-sim: --eye-sync-wait-s needs --eye-sync (it is its give-up time)\n");
    return OPTIONS_BAD;
  }
  if (o->eye_sync && (!o->lockstep || !o->eye)) {
    fprintf(stderr,
            "autodrive-sim: --eye-sync needs --eye and --lockstep, --lockstep-client or "
            "--lockstep-frames (in real time the Eye keeps up or falls behind, as a real one)\n");
    return OPTIONS_BAD;
  }
  if ((o->view_scale > 0 || o->view_quality_given || o->view_nice_given) && !o->view) {
    fprintf(stderr,
            "autodrive-sim: --view-scale, --view-quality and --view-nice need --view "
            "(they set how the window draws)\n");
    return OPTIONS_BAD;
  }
  if (o->gamepad && !o->view) {
    fprintf(stderr, "autodrive-sim: --gamepad needs --view (it drives from the window)\n");
    return OPTIONS_BAD;
  }
  if (o->gamepad && options_gamepad_check(o->gamepad) != 0) return OPTIONS_BAD;
  if (o->hud_log && !o->view) {
    fprintf(stderr, "autodrive-sim: --hud-log needs --view (it logs the window's HUD)\n");
    return OPTIONS_BAD;
  }
  if (o->video && o->record_dir) {
    fprintf(stderr,
            "autodrive-sim: --video and --record exclude each other (--record DIR "
            "writes DIR/view.mp4)\n");
    return OPTIONS_BAD;
  }
  if (o->client_sync && !o->cfg.open_ptys) {
    fprintf(stderr, "autodrive-sim: --lockstep-client needs the ptys (drop --no-pty)\n");
    return OPTIONS_BAD;
  }
  return -1;
}

/* The start poses the program gives after sim_create (--start once per car, --car-start):
 * the distractors keep clear of them too. */
static void options_keep_clear(app_options_t *o) {
  int n = 0;
  for (int k = 0; k < o->nstarts; k++) o->keep_clear[n++] = o->starts[k];
  for (int i = 0; i < SIM_MAX_CARS; i++)
    if (o->car_start_given[i]) o->keep_clear[n++] = o->car_start[i];
  o->cfg.distractor_keep_clear = n;
  o->cfg.distractor_keep_clear_pose = o->keep_clear;
}

/* Moves the URL and, unless given, the run dir to the session's instance. */
static void options_instance(app_options_t *o) {
  o->url = sim_instance_url(o->instance, o->url, o->instance_url, sizeof o->instance_url);
  if (!o->run_dir_given)
    o->cfg.run_dir = sim_instance_run_dir(o->instance, o->run_dir, sizeof o->run_dir);
}

int app_options_parse(app_options_t *o, int argc, char **argv) {
  options_defaults(o);
  if ((o->instance = sim_instance_from_env()) < 0) return OPTIONS_BAD;
  for (int i = 1; i < argc; i++) {
    const char *a = argv[i], *v = (i + 1 < argc) ? argv[i + 1] : NULL;
    if (!strcmp(a, "-h") || !strcmp(a, "--help")) {
      options_usage(stdout);
      return 0;
    }
    int took = options_world(o, a, v);
    if (took == OPTIONS_UNKNOWN) took = options_run(o, a, v);
    if (took == OPTIONS_UNKNOWN) took = options_output(o, a, v);
    if (took == OPTIONS_BAD) return OPTIONS_BAD;
    if (took == OPTIONS_UNKNOWN) {
      fprintf(stderr, "autodrive-sim: unknown option or missing value: '%s' (see --help)\n", a);
      return OPTIONS_BAD;
    }
    i += took;
  }
  options_instance(o);
  options_keep_clear(o);
  const int free_lockstep = app_options_free_lockstep(o);
  o->cfg.host_io_period_ms = o->host_io_ms   ? o->host_io_ms
                             : free_lockstep ? OPTIONS_FREE_LOCKSTEP_IO_MS
                                             : 1;
  return options_check(o);
}

int app_options_free_lockstep(const app_options_t *o) {
  return o->lockstep && !o->client_sync;
}

const char *app_options_mode(const app_options_t *o) {
  return o->frame_sync    ? "lockstep with the client, frame by frame"
         : o->client_sync ? "lockstep with the client"
         : o->lockstep    ? "lockstep"
                          : (o->rtf_given ? "rtf" : "real time");
}
