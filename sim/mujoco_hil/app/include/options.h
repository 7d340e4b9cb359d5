/* autodrive-sim's command line: every option, its checks and --help (README.md's table). */
#ifndef SIM_APP_OPTIONS_H
#define SIM_APP_OPTIONS_H

#include "scenario.h"
#include "sim.h"

/* free lockstep serves the ptys every 10 ms of sim time: a client there sees the sim run
 * tens of times faster than real time anyway, and an idle pty then costs no system call in
 * nine steps of ten (tools/bench sim: overhead_ratio) */
#define OPTIONS_FREE_LOCKSTEP_IO_MS 10

typedef struct app_options {
  sim_config_t cfg; /* its paths point into this struct: parse in place, never copy */
  char params[1024], map[1024];
  const char *url, *truth_log;
  int instance;                          /* --instance or AUTODRIVE_INSTANCE (sim_instance.h) */
  int run_dir_given;                     /* --run-dir: the instance leaves it alone */
  char instance_url[512], run_dir[1024]; /* url and run dir moved to the instance */
  int lockstep, client_sync, frame_sync, allow_teleport, rtf_given;
  int host_io_ms; /* --host-io-ms; 0: the mode's default */
  double rtf, duration_s;
  int bench, quiet, lidar_lcm, view;
  int bench_unpaired; /* --bench-unpaired: no bare blocks paired into the run */
  int view_w, view_h; /* --view-size [px] */
  double view_scale;  /* --view-scale: the scene's render scale, 0: the renderer's default */
  int view_quality;   /* --view-quality: SIM_VIEWER_QUALITY_* (low) */
  int view_quality_given;
  int view_nice; /* --view-nice: of the window's drawing and rasteriser threads (10) */
  int view_nice_given;
  const char *hud_log; /* --hud-log FILE: each frame's HUD text, or NULL */
  const char *gamepad; /* --gamepad PATH: the joystick manual driving reads, or NULL */
  /* --video FILE, --record DIR (run_recorder.h), --video-camera NAME; NULL when not given */
  const char *video, *record_dir, *video_camera;
  int cameras, eye;       /* cameras: 0, CAMERAS_ALL or CAMERAS_FRONT (cameras.h) */
  int eye_sync;           /* --eye-sync: wait for the Eye's EYE_FRAME_DONE (eye_sync.h) */
  double eye_sync_wait_s; /* --eye-sync-wait-s [s wall]: a silent Eye is given up after it */
  int eye_sync_wait_given;
  int eye_render; /* --eye-render: CAMERAS_RENDER_CACHED, _FULL or _COMPARE (cameras.h) */
  double camera_fps, light_level, camera_noise, camera_blur;
  double light_rgb[3];          /* --light-rgb: gain per channel, 1 1 1 when not given */
  double camera_exposure;       /* --camera-exposure [EV], 0: none */
  double jitter_mm, jitter_deg; /* --camera-jitter: the front mounts' tolerance [mm], [deg] */
  double camera_scale; /* the cars' cameras' render scale per side, SIM_CAMERA_MIN_SCALE..1 */
  scn_pose_t starts[SIM_MAX_CARS]; /* --start, once for car 1 or once per car */
  int nstarts;
  scn_pose_t car_start[SIM_MAX_CARS]; /* --car-start I,...: car I alone */
  int car_start_given[SIM_MAX_CARS];
  scn_late_box_t late_box[SCN_MAX_LATE_BOXES];
  scn_pose_t keep_clear[2 * SIM_MAX_CARS]; /* the --start and --car-start poses, for
                                            * --distractors (cfg.distractor_keep_clear_pose) */
} app_options_t;

/* Parses argv into o (defaults first). Returns -1 to run, else the exit status: 0 after
 * --help, 2 for a bad option or value (the message is on stderr). */
int app_options_parse(app_options_t *o, int argc, char **argv);
/* Free lockstep: as fast as it can, nobody to wait for. */
int app_options_free_lockstep(const app_options_t *o);
/* The mode in words, for the start-up line. */
const char *app_options_mode(const app_options_t *o);

#endif
