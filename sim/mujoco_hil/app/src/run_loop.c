/* The main loop of autodrive-sim (app.h): per 1 ms step, the client's pace (lockstep modes),
 * light commands and teleports, the step itself, then what it publishes (ground truth,
 * LIDAR, cameras, SIM_CLOCK), the window, and the pacing against the wall clock. */
#include "app.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>

#include <autodrive_channels.h>

#include "app_common.h"
#include "bench_pairs.h"
#include "client_sync.h"
#include "lcm_publish.h"
#include "route_driver.h"

#define LOOP_TRUTH_EVERY 10    /* steps between ground-truth messages: 100 Hz */
#define LOOP_CLOCK_EVERY 10    /* steps between SIM_CLOCK messages: 100 Hz */
#define LOOP_LCM_FLUSH_S 0.001 /* [s] wall: longest a queued LCM message waits */
/* [s] wall, free lockstep: nothing waits on its messages, and each flush wakes the LCM thread
 * (a system call, and with it the other core) */
#define LOOP_FREE_LCM_FLUSH_S 0.004
#define LOOP_FREE_CLOCK_EVERY 8 /* [steps] free lockstep: 8 ms of sim time, ~0.15 ms of wall */
#define LOOP_PROGRESS_S 5.0     /* [s] wall time between progress lines */
/* Largest lag behind the real-time schedule [s] before the schedule slips (see pacing). */
#define LOOP_MAX_LAG_S 0.02
/* A progress line says the run lags only when the slips of its interval add up to more than
 * this share of it: single 20 ms hiccups of a busy machine are normal, not news. */
#define LOOP_LAG_NOTE_SHARE 0.1

typedef struct loop {
  int64_t end_us; /* --duration in sim time, -1: none */
  double t0;      /* wall start, moved forward by pauses in the viewer and bare blocks */
  double next_progress, next_flush;
  int64_t last_progress_us;
  long step;
  double slipped_s; /* [s] wall the schedule slipped since the last progress line */
  int free_lockstep;
  client_sync_t sync;
  bench_pairs_t pairs; /* --bench in free lockstep: sim blocks paired with bare mj_step blocks */
  int paired;
} loop_t;

/* One line on stdout per late box as it appears (scenario logs, tests). */
static void app_report_late_boxes(const sim_t *s) {
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

/* Lockstep modes: wait for the client's bytes (--lockstep-client) or frame (-frames). */
static void loop_wait_for_client(app_t *a, loop_t *l) {
  if (a->opt->frame_sync) {
    if (sim_time_us(a->sim) % CLIENT_SYNC_FRAME_TICK_US == 0) {
      publish_queue_flush(a->pubq); /* this tick's SIM_CLOCK: the client answers it with a frame */
      client_sync_wait_frame(a->sim, &l->sync);
    }
  } else if (a->opt->client_sync) {
    publish_queue_flush(a->pubq); /* the client may be waiting for the SIM_CLOCK we queued */
    client_sync_wait_bytes(a->sim, &l->sync);
  }
}

/* Ground truth at 100 Hz and every new LIDAR scan. */
static void loop_publish_sensors(app_t *a, const loop_t *l) {
  sim_t *s = a->sim;
  if (l->step % LOOP_TRUTH_EVERY == 0)
    for (int c = 1; c <= sim_cars(s); c++) publish_ground_truth(a->pubq, s, c, a->truth_log);
  for (int c = 1; c <= sim_cars(s); c++) {
    const sim_lidar_scan_t *scan = sim_lidar_new_scan(s, c);
    /* while the runtime's RPLIDAR driver scans on the pty it publishes <VEH>_LIDAR itself:
     * the sim then stays off the channel so that nobody sees every scan twice */
    viewer_window_lidar(&a->viewer, s, c, scan);
    if (scan && a->opt->lidar_lcm && !sim_lidar_pty_scanning(s, c)) {
      char ch[32];
      snprintf(ch, sizeof ch, AUTODRIVE_VEHICLE_PREFIX "%d" AUTODRIVE_CH_LIDAR_SUFFIX, c);
      publish_lidar_scan(a->pubq, ch, "laser", scan);
    }
  }
}

/* The View section's Cam scale radio changed the cars' cameras' render scale. The cameras
 * rendered here take it at once; the render thread's take it with the next snapshot queued
 * (render_thread_submit), in sim-time order: it alone touches its cameras, so the scale
 * crosses threads only inside the queue, under its lock. */
static void loop_camera_scale(app_t *a, int64_t now_us) {
  a->camera_scale = a->viewer.in.camera_scale;
  cameras_set_render_scale(&a->cams, a->camera_scale);
  printf("camera scale %.2f from t = %.3f s (the View section)\n", a->camera_scale, now_us * 1e-6);
  fflush(stdout);
}

/* The cameras at their frame times: rendered here, or queued for the render thread (which
 * slows the stepping down while frames wait); --eye-sync learns of each frame sent. Returns 0,
 * or -1 with the message in err. */
static int loop_cameras(app_t *a, int64_t now_us, char *err, size_t err_sz) {
  sim_t *s = a->sim;
  if (now_us % a->cam_period_us < SIM_STEP_US) {
    int sent = 0;
    if (a->eye_sync) eye_sync_before_frame(a->eye_sync);
    if (a->cams.n > 0) {
      if (cameras_publish(&a->cams, sim_render_model(s), sim_render_data(s), a->lcm, now_us, err,
                          err_sz) != 0)
        return -1;
      sent = 1;
    }
    if (a->render &&
        (sent = render_thread_submit(a->render, s, now_us, a->camera_scale, err, err_sz)) < 0)
      return -1;
    if (sent && a->eye_sync) eye_sync_frame_sent(a->eye_sync, now_us);
  }
  if (a->render) { /* slow down while frames wait to be rendered */
    const long backlog_us = render_thread_backlog_us(a->render);
    if (backlog_us > 0) {
      const struct timespec ts = {0, backlog_us * 1000L};
      nanosleep(&ts, NULL);
    }
  }
  return 0;
}

/* Pacing: real time or rtf x real time; lockstep runs free. Also flushes the queued LCM
 * messages within the flush period and prints the progress line. */
static void loop_pace(app_t *a, loop_t *l, int64_t now_us) {
  const app_options_t *o = a->opt;
  const double wall = app_wall_s();
  if (wall >= l->next_flush) { /* queued LCM messages leave within the flush period */
    publish_queue_flush(a->pubq);
    l->next_flush = wall + (l->free_lockstep ? LOOP_FREE_LCM_FLUSH_S : LOOP_LCM_FLUSH_S);
  }
  /* --lockstep-client runs in real time until a client first writes, then in step with it */
  if (!o->lockstep || (o->client_sync && !l->sync.started)) {
    const double ahead = l->t0 + now_us * 1e-6 / o->rtf - wall;
    if (ahead < -LOOP_MAX_LAG_S) {
      /* Behind (a slow frame, the window, a loaded CPU): slip the schedule rather than burst
       * through the backlog. A burst would advance sim time with no bytes arriving on the
       * pty, and the emulated Nano's failsafe would trip on a client that is fine. */
      l->t0 -= ahead;
      l->slipped_s -= ahead;
    } else if (ahead > 0.0005) {
      struct timespec ts = {(time_t)ahead, (long)((ahead - floor(ahead)) * 1e9)};
      nanosleep(&ts, NULL);
    }
  }
  if (wall >= l->next_progress) {
    const double interval_s = wall - l->next_progress + LOOP_PROGRESS_S;
    const double rtf_now = (now_us - l->last_progress_us) * 1e-6 / interval_s;
    l->last_progress_us = now_us;
    l->next_progress = wall + LOOP_PROGRESS_S;
    if (!o->quiet && l->slipped_s > LOOP_LAG_NOTE_SHARE * interval_s && !o->lockstep)
      fprintf(stderr,
              "[autodrive-sim] t = %.1f s sim, rtf %.2f (asked %.2f: this machine is too busy; "
              "%.1f s of the last %.1f s lost)\n",
              now_us * 1e-6, rtf_now, o->rtf, l->slipped_s, interval_s);
    else if (!o->quiet)
      fprintf(stderr, "[autodrive-sim] t = %.1f s sim, rtf %.2f\n", now_us * 1e-6, rtf_now);
    l->slipped_s = 0;
  }
}

/* SIM_CLOCK (lockstep modes and --rtf) with the run's average rtf so far. */
static void loop_publish_clock(app_t *a, const loop_t *l, int64_t now_us) {
  const double since = app_wall_s() - l->t0;
  publish_sim_clock(a->pubq, now_us, since > 0 ? now_us * 1e-6 / since : 0.0, 0);
}

/* --eye-sync: at the step that reaches a frame's capture time + the Eye's latency, SIM_CLOCK
 * goes out (the Eye releases the frame's poses on it) and the sim waits for EYE_FRAME_DONE.
 * --lockstep-frames sends no extra SIM_CLOCK (its clients answer each one with a frame): there
 * the sim waits at the next regular one. clock_sent: this step's SIM_CLOCK is out already. */
static void loop_wait_for_eye(app_t *a, const loop_t *l, int64_t now_us, int clock_sent) {
  eye_sync_t *e = a->eye_sync;
  if (!e) return;
  if (clock_sent) eye_sync_poll(e); /* an Eye's first answer, and those that came early */
  if (!eye_sync_due(e, now_us) || (!clock_sent && a->opt->frame_sync)) return;
  if (!clock_sent) loop_publish_clock(a, l, now_us);
  publish_queue_flush(a->pubq);
  eye_sync_wait(e, now_us);
}

/* The window's Record button: stops the recording, or starts one in recordings/<UTC time>/ of
 * the camera the window shows (the ego car's front camera for the views that follow no fixed
 * camera). Returns 0, or -1 with the message in err. */
static int loop_record_button(app_t *a, char *err, size_t err_sz) {
  const int toggles = a->viewer.record_toggles;
  a->viewer.record_toggles = 0;
  if (toggles % 2 == 0) return 0;
  run_recorder_t *r = &a->recorder;
  if (run_recorder_active(r)) {
    const long frames = r->next_frame;
    if (run_recorder_stop(r, err, err_sz) != 0) return -1;
    printf("recording stopped at t = %.3f s: %ld frame(s) in %s\n", sim_time_us(a->sim) * 1e-6,
           frames, r->dir[0] ? r->dir : r->video_path);
    fflush(stdout);
    return 0;
  }
  char dir[96], cam[64];
  const time_t now = time(NULL);
  struct tm utc;
  gmtime_r(&now, &utc);
  strftime(dir, sizeof dir, "recordings/%Y%m%d-%H%M%S", &utc);
  if (mkdir("recordings", 0775) != 0 && errno != EEXIST) {
    snprintf(err, err_sz, "Record: cannot make the folder 'recordings': %s", strerror(errno));
    return -1;
  }
  const int id = sim_viewer_camera_id(a->viewer.v);
  const char *name = id >= 0 ? mj_id2name(sim_render_model(a->sim), mjOBJ_CAMERA, id) : NULL;
  if (name)
    snprintf(cam, sizeof cam, "%s", name);
  else
    snprintf(cam, sizeof cam, "nigel%d/cam_front", a->viewer.in.car);
  if (run_recorder_start(r, a->sim, cam, NULL, dir, a->opt->url, err, err_sz) != 0) return -1;
  printf("recording %s from t = %.3f s into %s\n", cam, sim_time_us(a->sim) * 1e-6, dir);
  fflush(stdout);
  return 0;
}

/* One pass of the loop. Returns 1 to go on, 0 when the run is over, -1 on an error (message on
 * stderr). */
static int loop_once(app_t *a, loop_t *l) {
  const app_options_t *o = a->opt;
  sim_t *s = a->sim;
  char err[2048] = "";
  loop_wait_for_client(a, l);
  /* light commands: every step, but every host-I/O period in free lockstep (a system call) */
  if (a->lights && l->step % o->cfg.host_io_period_ms == 0)
    traffic_lights_lcm_poll(a->lights, sim_time_us(s));
  if (a->teleport && l->step % o->cfg.host_io_period_ms == 0) teleport_lcm_poll(a->teleport);
  if (sim_step(s, err, sizeof err) != 0) {
    fprintf(stderr, "autodrive-sim: %s\n", err);
    return -1;
  }
  l->step++;
  const int64_t now_us = sim_time_us(s);
  app_report_late_boxes(s);
  traffic_lights_lcm_publish(a->lights, now_us);
  const route_driver_t *route = sim_route(s);
  if (route && route->st.done) {
    printf("route %s done at t = %.3f s\n", route->name, now_us * 1e-6);
    return 0;
  }
  loop_publish_sensors(a, l);
  if (loop_cameras(a, now_us, err, sizeof err) != 0) {
    fprintf(stderr, "autodrive-sim: %s\n", err);
    return -1;
  }
  if (run_recorder_step(&a->recorder, s, err, sizeof err) != 0) {
    fprintf(stderr, "autodrive-sim: %s\n", err);
    return -1;
  }
  const int clock_now = (o->lockstep || o->rtf_given) && l->step % LOOP_CLOCK_EVERY == 0;
  if (clock_now) loop_publish_clock(a, l, now_us);
  loop_wait_for_eye(a, l, now_us, clock_now);
  if (a->viewer.v) {
    const char *rec = run_recorder_active(&a->recorder) ? a->recorder.video_path : NULL;
    if (viewer_window_frame(&a->viewer, s, &l->t0, rec) != 0) return 0;
    if (a->viewer.in.camera_scale != a->camera_scale) loop_camera_scale(a, now_us);
    if (a->viewer.record_toggles && loop_record_button(a, err, sizeof err) != 0) {
      fprintf(stderr, "autodrive-sim: %s\n", err);
      return -1;
    }
  }
  if (l->paired) { /* the bare block is not part of the run: its time moves the start on */
    const double bare_wall_s = bench_pairs_after_step(&l->pairs, l->step);
    l->t0 += bare_wall_s;
    l->next_progress += bare_wall_s;
  }
  /* free lockstep paces nothing: it reads the clock (for the LCM flush and progress) every
   * LOOP_FREE_CLOCK_EVERY steps only, as a read costs ~0.5 % of a 1-car step */
  if (!l->free_lockstep || l->step % LOOP_FREE_CLOCK_EVERY == 0) loop_pace(a, l, now_us);
  return 1;
}

int app_run(app_t *a, app_run_stats_t *st) {
  loop_t l = {0};
  const app_options_t *o = a->opt;
  sim_t *s = a->sim;
  l.end_us = o->duration_s > 0 ? (int64_t)llround(o->duration_s * 1e6) : -1;
  l.free_lockstep = app_options_free_lockstep(o);
  l.t0 = app_wall_s();
  const double cpu0 = app_cpu_s(), step_cpu0 = sim_clock_s(CLOCK_THREAD_CPUTIME_ID);
  l.next_progress = l.t0 + LOOP_PROGRESS_S;
  l.next_flush = l.t0;
  int rc = 0;
  l.paired = o->bench && !o->bench_unpaired && o->lockstep && !o->client_sync && !o->frame_sync &&
             !a->viewer.v;
  if (l.paired && bench_pairs_start(&l.pairs, s) != 0) {
    fprintf(stderr, "autodrive-sim: --bench: out of memory for the bare mj_step blocks\n");
    rc = 1;
  }
  if (o->frame_sync) publish_sim_clock(a->pubq, 0, 0.0, 0); /* the client's first tick */
  while (rc == 0 && !app_stop_requested() && (l.end_us < 0 || sim_time_us(s) < l.end_us)) {
    const int r = loop_once(a, &l);
    if (r < 0) rc = 1;
    if (r <= 0) break;
  }
  if (run_recorder_active(&a->recorder)) {
    char err[1024] = "";
    const long frames = a->recorder.next_frame;
    if (run_recorder_stop(&a->recorder, err, sizeof err) != 0) {
      fprintf(stderr, "autodrive-sim: %s\n", err);
      rc = 1;
    } else if (!o->quiet) {
      fprintf(stderr, "autodrive-sim: recorded %ld frame(s) to %s\n", frames,
              a->recorder.video_path);
    }
  }
  /* the stepping thread alone: what bounds the rtf when the LCM worker has a core of its own */
  st->step_cpu_s =
      sim_clock_s(CLOCK_THREAD_CPUTIME_ID) - step_cpu0 - bench_pairs_bare_cpu_s(&l.pairs);
  const uint64_t lcm_failures = publish_queue_failures(a->pubq);
  publish_queue_destroy(a->pubq); /* sends what is still queued: part of the run's time */
  a->pubq = NULL;
  st->wall_s = app_wall_s() - l.t0;
  viewer_window_stop(&a->viewer); /* after the run's time: the last frame is no part of it */
  st->cpu_s = app_cpu_s() - cpu0 - bench_pairs_bare_cpu_s(&l.pairs);
  st->steps = l.step;
  double eye_waited_s = 0.0;
  long eye_given_up = 0;
  const long eye_waits = eye_sync_stats(a->eye_sync, &eye_waited_s, &eye_given_up);
  if (a->eye_sync && !o->quiet)
    fprintf(stderr,
            "autodrive-sim: --eye-sync: waited for the Eye at %ld frame(s), %.1f s of wall time "
            "in all, gave it up %ld time(s)\n",
            eye_waits, eye_waited_s, eye_given_up);
  if (lcm_failures)
    fprintf(stderr, "autodrive-sim: LCM refused %llu ground-truth/clock message(s) on '%s'\n",
            (unsigned long long)lcm_failures, o->url);
  if (o->bench) app_print_bench(a, st, &l.pairs);
  bench_pairs_free(&l.pairs);
  return rc;
}
