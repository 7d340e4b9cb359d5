/* The optional window of autodrive-sim --view (sensors library, EGL context): the scene, the
 * Menu Panel and the HUD (hud_text.h), drawn on a thread of its own.
 *
 * Threads: the stepping (main) thread polls the window's events (GLFW wants them on the thread
 * that made the window), builds the HUD text and copies the state to draw into a snapshot at
 * each frame time; the drawing thread renders the latest snapshot (sim_viewer_draw). Snapshots
 * are triple-buffered (the stepping fills its own, then swaps it with the shared one under a
 * lock held for the swap alone): the stepping never waits on GL, and a slow frame only means
 * that the snapshots in between are never drawn. Sim time and lockstep are untouched: the
 * window reads the state, and its input acts on the stepping thread, between steps. */
#ifndef SIM_APP_VIEWER_WINDOW_H
#define SIM_APP_VIEWER_WINDOW_H

#include <pthread.h>
#include <stdatomic.h>
#include <stdint.h>
#include <stdio.h>

#include "control_status_lcm.h"
#include "manual_drive.h"
#include "sim.h"
#include "sim_lidar.h"
#include "sim_viewer.h"

#define VIEWER_WINDOW_TIMED_FRAMES 4096 /* frames whose drawing time --bench reports */
#define VIEWER_HUD_CHARS 2048
#define VIEWER_MAX_RAYS 1024

/* What one frame draws: the state, its HUD text and the LIDAR rays. */
typedef struct viewer_slot {
  mjData *d; /* sim_render_snapshot of the render model */
  char titles[VIEWER_HUD_CHARS], values[VIEWER_HUD_CHARS];
  double ray_origin[3]; /* [m] world */
  float ray_end[3 * VIEWER_MAX_RAYS];
  int nrays;
} viewer_slot_t;

/* Snapshots at ~30 Hz of wall time, at most one per 1/30 s of sim time (but while paused). */
typedef struct viewer_window {
  sim_viewer_t *v; /* NULL when off */
  double next_frame_s;
  int64_t next_frame_us;  /* [us] sim time */
  double rtf, rtf_wall_s; /* the real-time factor over the last second of wall time */
  int64_t rtf_sim_us;
  int record_toggles;          /* Record clicks not yet acted on (run_loop starts / stops) */
  sim_viewer_input_t in;       /* the input state, as last polled */
  manual_drive_t manual;       /* the Driving radio's Manual: keys into autodrive-teleop */
  control_status_lcm_t *lease; /* the cars' control leases for the HUD, or NULL (no ptys) */
  const char *url;             /* the sim's LCM URL, for teleop */
  /* the stepping thread's LIDAR rays of the ego car, copied into each snapshot */
  double ray_origin[3]; /* [m] */
  float ray_end[3 * VIEWER_MAX_RAYS];
  int nrays;
  /* the drawing thread; mu guards pending, fresh, stop, failed and the counters below */
  pthread_t th;
  pthread_mutex_t mu;
  pthread_cond_t cv;
  int started;          /* the thread runs (join it) */
  int sync_made;        /* mu and cv made */
  const mjModel *model; /* the render model */
  int nice;             /* the drawing thread's */
  viewer_slot_t slot[3];
  int back, pending, front; /* slot indices: the stepping's, the shared one, the drawing's */
  int fresh, stop, failed;  /* fresh: pending holds a snapshot not drawn yet */
  long submitted;           /* snapshots handed over */
  atomic_long passes;       /* the stepping's passes through viewer_window_frame: its steps */
  long steps_while_drawing; /* steps the stepping made while frames were drawn (--bench) */
  /* the drawing thread's own (read by others after it stopped) */
  FILE *hud_log;                             /* --hud-log, or NULL */
  long frames;                               /* drawn so far */
  double draw_s[VIEWER_WINDOW_TIMED_FRAMES]; /* [s] wall to draw each of the first frames whose
                                                parts were not timed (sim_viewer_last_timed) */
  long untimed;                              /* of those, in draw_s */
  double first_frame_s, last_frame_s;        /* [s] wall at the end of the first, last frame */
} viewer_window_t;

/* How the window draws: the render scale (0: the GL renderer's default, sim_viewer.h), the
 * graphics quality (SIM_VIEWER_QUALITY_*), timing of the frame's parts (--bench), the nice
 * of its drawing and rasteriser threads (--view-nice), and the cars' cameras' render scale
 * (--camera-scale: the View section's Cam scale radio starts there). */
typedef struct viewer_window_look {
  double scale;
  int quality, timing, nice;
  double camera_scale;
} viewer_window_look_t;

/* Opens a width_px x height_px window when want (a display is needed) and starts its drawing
 * thread; else leaves w->v NULL. map_name goes into the Simulation section. url: the LCM bus
 * (teleop's, and the leases', listened to when ptys: a runtime may be on them). hud_log: a
 * file for each drawn frame's HUD, or NULL. gamepad: --gamepad's joystick for manual driving,
 * or NULL. */
int viewer_window_open(viewer_window_t *w, const sim_t *s, int want, int width_px, int height_px,
                       const char *map_name, const char *url, int ptys, const char *hud_log,
                       const char *gamepad, viewer_window_look_t look, char *err, size_t err_sz);
/* Manual driving (every pass: the held keys repeat on wall time), then, when a frame is due,
 * the window's events and a snapshot for the drawing thread; blocks while paused (shifting
 * *t0_s so pacing resumes smoothly) until Step or Pause is clicked. recording: shown in the
 * HUD, or NULL. Returns 1 when the user quit or the drawing failed. */
int viewer_window_frame(viewer_window_t *w, sim_t *s, double *t0_s, const char *recording);
/* The ego car's new LIDAR scan, drawn as rays from its base_link while "LIDAR rays" is on. */
void viewer_window_lidar(viewer_window_t *w, const sim_t *s, int car, const sim_lidar_scan_t *scan);
/* Stops the drawing thread (after the frame it draws); idempotent. */
void viewer_window_stop(viewer_window_t *w);
/* --bench, after viewer_window_stop: the window's figures as JSON fields (", \"viewer_...\"")
 * on f: frames, the median wall time to draw one (scene, HUD, Menu Panel, swap) and its
 * inverse viewer_fps, the rate drawn, the snapshots handed over, the render scale and renderer,
 * and the median of each part of a frame. */
void viewer_window_print_bench(const viewer_window_t *w, FILE *f);
void viewer_window_close(viewer_window_t *w);

#endif
