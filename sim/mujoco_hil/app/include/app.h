/* The program autodrive-sim: the world and everything around it for one run (LCM, the truth
 * log, cameras, lights and teleport on LCM, the window, the publish queue). main() parses
 * the options, builds it, runs the loop and tears it down. */
#ifndef SIM_APP_APP_H
#define SIM_APP_APP_H

#include <stdint.h>
#include <stdio.h>

#include <lcm/lcm.h>

#include "bench_pairs.h"
#include "cameras.h"
#include "eye_sync.h"
#include "options.h"
#include "publish_queue.h"
#include "render_thread.h"
#include "run_recorder.h"
#include "sim.h"
#include "teleport_lcm.h"
#include "traffic_lights_lcm.h"
#include "viewer_window.h"

typedef struct app {
  const app_options_t *opt;
  lcm_t *lcm;
  FILE *truth_log; /* --truth-log, or NULL */
  sim_t *sim;
  cameras_t cams;          /* rendered on the stepping thread; empty when the thread has them */
  render_thread_t *render; /* the render thread (real time, --rtf, --lockstep-client) or NULL */
  int64_t cam_period_us;
  double camera_scale; /* the cars' cameras' render scale now: --camera-scale, then the View
                          section's Cam scale radio */
  traffic_lights_lcm_t *lights; /* the map's traffic lights on LCM, or NULL */
  teleport_lcm_t *teleport;     /* --allow-teleport, or NULL */
  eye_sync_t *eye_sync;         /* --eye-sync, or NULL */
  viewer_window_t viewer;
  run_recorder_t recorder; /* --video, --record, the window's Record button */
  publish_queue_t *pubq;   /* ground truth and SIM_CLOCK leave through its worker thread */
} app_t;

/* What the loop measured, for --bench. */
typedef struct app_run_stats {
  long steps;
  double wall_s, cpu_s, step_cpu_s; /* the run's wall, process CPU and stepping thread CPU */
} app_run_stats_t;

/* Builds the world and what surrounds it. Returns -1 on success, else the exit status (1 or 2,
 * the message on stderr); a is then partly built: app_close it. */
int app_build(app_t *a, const app_options_t *o);
/* Prints the ptys, the map, the mode, the route, the lights and the start pose on stdout. */
void app_print_setup(const app_t *a);
/* The main loop until --duration, the route's end, the window or a signal. Returns the exit
 * status (0 or 1). Flushes and closes the publish queue at the end; prints --bench. */
int app_run(app_t *a, app_run_stats_t *stats);
/* --bench: the run's JSON line on stdout (pairs: the bare blocks paired with the run's, else
 * a bare loop runs after it). */
void app_print_bench(const app_t *a, const app_run_stats_t *st, const bench_pairs_t *pairs);
/* Tears down whatever app_build made. */
void app_close(app_t *a);

#endif
