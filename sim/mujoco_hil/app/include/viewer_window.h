/* The optional window of autodrive-sim --view (sensors library, EGL context): the scene, the
 * Menu Panel and the HUD (hud_text.h). */
#ifndef SIM_APP_VIEWER_WINDOW_H
#define SIM_APP_VIEWER_WINDOW_H

#include <stdint.h>
#include <stdio.h>

#include "control_status_lcm.h"
#include "manual_drive.h"
#include "sim.h"
#include "sim_lidar.h"
#include "sim_viewer.h"

#define VIEWER_WINDOW_TIMED_FRAMES 4096 /* frames whose drawing time --bench reports */

/* Drawn at ~30 Hz of wall time, at most once per 1/30 s of sim time (but while paused). */
typedef struct viewer_window {
  sim_viewer_t *v; /* NULL when off */
  double next_frame_s;
  int64_t next_frame_us;  /* [us] sim time */
  double rtf, rtf_wall_s; /* the real-time factor over the last second of wall time */
  int64_t rtf_sim_us;
  long frames;                               /* drawn so far */
  double draw_s[VIEWER_WINDOW_TIMED_FRAMES]; /* [s] wall to draw each of the first frames */
  int record_toggles;          /* Record clicks not yet acted on (run_loop starts / stops) */
  sim_viewer_input_t in;       /* the last frame's input */
  manual_drive_t manual;       /* the Driving radio's Manual: keys into autodrive-teleop */
  control_status_lcm_t *lease; /* the cars' control leases for the HUD, or NULL (no ptys) */
  const char *url;             /* the sim's LCM URL, for teleop */
  FILE *hud_log;               /* --hud-log, or NULL */
} viewer_window_t;

/* Opens a width_px x height_px window when want (a display is needed); else leaves w->v NULL.
 * map_name goes into the Simulation section. url: the LCM bus (teleop's, and the leases',
 * listened to when ptys: a runtime may be on them). hud_log: a file for each frame's HUD, or
 * NULL. */
int viewer_window_open(viewer_window_t *w, const sim_t *s, int want, int width_px, int height_px,
                       const char *map_name, const char *url, int ptys, const char *hud_log,
                       char *err, size_t err_sz);
/* Manual driving (every pass: the held keys repeat on wall time), then a frame when one is due;
 * blocks while paused (shifting *t0_s so pacing resumes smoothly) until Step or Pause is clicked.
 * recording: shown in the HUD, or NULL. Returns 1 when the user quit. */
int viewer_window_frame(viewer_window_t *w, sim_t *s, double *t0_s, const char *recording);
/* The ego car's new LIDAR scan, drawn as rays from its base_link while "LIDAR rays" is on. */
void viewer_window_lidar(viewer_window_t *w, const sim_t *s, int car, const sim_lidar_scan_t *scan);
/* --bench: the median wall time to draw a frame (scene, HUD, Menu Panel, swap) [s]; 0 before
 * the first. */
double viewer_window_median_draw_s(const viewer_window_t *w);
void viewer_window_close(viewer_window_t *w);

#endif
