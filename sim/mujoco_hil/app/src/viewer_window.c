/* The optional window (viewer_window.h). */
#include "viewer_window.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <time.h>
#include <sys/syscall.h>
#include <unistd.h> /* syscall: _DEFAULT_SOURCE from the build */

#include "app_common.h"
#include "hud_text.h"

#define VIEWER_FRAME_S (1.0 / 30.0) /* [s] wall between frames */
#define VIEWER_RTF_WINDOW_S 1.0     /* [s] wall over which the HUD's rtf is measured */
#define VIEWER_LIDAR_HEIGHT_M 0.12  /* rays drawn this far above base_link (the RPLIDAR's deck) */

/* --hud-log: one line per drawn frame, sim time [us] then title=value fields (tab-separated). */
static void viewer_hud_log(FILE *f, const viewer_slot_t *slot) {
  fprintf(f, "%lld", (long long)llround(slot->d->time * 1e6));
  const char *t = slot->titles, *v = slot->values;
  while (*t) {
    const size_t tn = strcspn(t, "\n"), vn = strcspn(v, "\n");
    fprintf(f, "\t%.*s=%.*s", (int)tn, t, (int)vn, v);
    t += tn + (t[tn] != 0);
    v += vn + (v[vn] != 0);
  }
  fputc('\n', f);
  fflush(f);
}

/* The drawing thread: the latest snapshot, whenever one is new. */
static void *viewer_thread_run(void *arg) {
  viewer_window_t *w = arg;
  const mjModel *m = NULL;
  /* Linux: PRIO_PROCESS with a thread id sets that thread alone; raising nice is always allowed */
  setpriority(PRIO_PROCESS, (id_t)syscall(SYS_gettid), w->nice);
  pthread_mutex_lock(&w->mu);
  for (;;) {
    while (!w->fresh && !w->stop) pthread_cond_wait(&w->cv, &w->mu);
    if (w->stop) break;
    const int t = w->front;
    w->front = w->pending;
    w->pending = t;
    w->fresh = 0;
    m = w->model;
    pthread_mutex_unlock(&w->mu);
    const viewer_slot_t *slot = &w->slot[w->front];
    sim_viewer_set_hud(w->v, slot->titles, slot->values);
    sim_viewer_set_rays(w->v, slot->ray_origin, slot->ray_end, slot->nrays);
    const double t0_s = app_wall_s();
    const long steps0 = atomic_load_explicit(&w->passes, memory_order_relaxed);
    const int rc = sim_viewer_draw(w->v, m, slot->d);
    const long steps = atomic_load_explicit(&w->passes, memory_order_relaxed) - steps0;
    const double t1_s = app_wall_s();
    if (w->hud_log) viewer_hud_log(w->hud_log, slot);
    pthread_mutex_lock(&w->mu);
    /* the frames whose parts were timed (glFinish after each) are slower: not in the median */
    if (!sim_viewer_last_timed(w->v) && w->untimed < VIEWER_WINDOW_TIMED_FRAMES)
      w->draw_s[w->untimed++] = t1_s - t0_s;
    if (w->frames == 0) w->first_frame_s = t1_s;
    w->last_frame_s = t1_s;
    w->frames++;
    w->steps_while_drawing += steps;
    if (rc != 0) w->failed = 1;
  }
  pthread_mutex_unlock(&w->mu);
  sim_viewer_release(w->v); /* sim_viewer_destroy binds the context on the main thread */
  return NULL;
}

static int viewer_thread_start(viewer_window_t *w, const sim_t *s, char *err, size_t err_sz) {
  for (int i = 0; i < 3; i++)
    if (!(w->slot[i].d = mj_makeData(sim_render_model(s)))) {
      snprintf(err, err_sz, "cannot allocate the window's snapshots");
      return -1;
    }
  w->back = 0;
  w->pending = 1;
  w->front = 2;
  w->model = sim_render_model(s);
  if (pthread_mutex_init(&w->mu, NULL) != 0 || pthread_cond_init(&w->cv, NULL) != 0) {
    snprintf(err, err_sz, "cannot make the window's lock");
    return -1;
  }
  w->sync_made = 1;
  sim_viewer_detach(w->v);
  if (pthread_create(&w->th, NULL, viewer_thread_run, w) != 0) {
    snprintf(err, err_sz, "cannot start the window's drawing thread");
    return -1;
  }
  w->started = 1;
  return 0;
}

int viewer_window_open(viewer_window_t *w, const sim_t *s, int want, int width_px, int height_px,
                       const char *map_name, const char *url, int ptys, const char *hud_log,
                       const char *gamepad, viewer_window_look_t look, char *err, size_t err_sz) {
  memset(w, 0, sizeof *w);
  atomic_init(&w->passes, 0);
  manual_drive_init(&w->manual, gamepad);
  w->url = url;
  if (!want) return 0;
  if (!sim_viewer_display_available()) {
    snprintf(err, err_sz, "no display (DISPLAY and WAYLAND_DISPLAY are unset); run headless");
    return -1;
  }
  w->v = sim_viewer_create(sim_render_model(s), sim_cars(s), "nigel%d/base_link",
                           "nigel%d/cam_front", width_px, height_px, err, err_sz);
  if (!w->v) return -1;
  const char *slash = map_name ? strrchr(map_name, '/') : NULL;
  sim_viewer_set_map_name(w->v, slash ? slash + 1 : map_name);
  if (look.scale > 0) sim_viewer_set_render_scale(w->v, look.scale);
  sim_viewer_set_quality(w->v, look.quality);
  sim_viewer_set_camera_scale(w->v, look.camera_scale);
  sim_viewer_time_parts(w->v, look.timing);
  /* never below the process's own nice (lowering it needs a privilege) */
  const int own = getpriority(PRIO_PROCESS, 0);
  w->nice = look.nice > own ? look.nice : own;
  sim_viewer_nice(w->v, w->nice);
  w->rtf_wall_s = app_wall_s();
  if (ptys && !(w->lease = control_status_lcm_create(url, sim_cars(s), err, err_sz))) return -1;
  if (hud_log && !(w->hud_log = fopen(hud_log, "w"))) {
    snprintf(err, err_sz, "--hud-log '%s': %s", hud_log, strerror(errno));
    return -1;
  }
  sim_viewer_poll(w->v, &w->in); /* the initial state (the ego car, the radios) */
  return viewer_thread_start(w, s, err, err_sz);
}

/* The HUD's real-time factor, measured over the last VIEWER_RTF_WINDOW_S of wall time. */
static void viewer_rtf(viewer_window_t *w, const sim_t *s, double now_s) {
  if (now_s - w->rtf_wall_s < VIEWER_RTF_WINDOW_S) return;
  w->rtf = (sim_time_us(s) - w->rtf_sim_us) * 1e-6 / (now_s - w->rtf_wall_s);
  w->rtf_wall_s = now_s;
  w->rtf_sim_us = sim_time_us(s);
}

/* The state, the HUD text and the rays into the stepping's slot, then handed over. Returns -1
 * when the drawing thread failed. */
static int viewer_submit(viewer_window_t *w, sim_t *s, const char *recording, double now_s) {
  viewer_slot_t *slot = &w->slot[w->back];
  sim_render_snapshot(s, slot->d);
  control_status_lcm_poll(w->lease, now_s);
  const hud_extra_t x = {recording, w->manual.status, w->lease, now_s};
  hud_text_build(s, w->rtf, &x, slot->titles, sizeof slot->titles, slot->values,
                 sizeof slot->values);
  slot->nrays = w->in.lidar_rays ? w->nrays : 0;
  memcpy(slot->ray_origin, w->ray_origin, sizeof slot->ray_origin);
  memcpy(slot->ray_end, w->ray_end, (size_t)slot->nrays * 3 * sizeof(float));
  pthread_mutex_lock(&w->mu);
  const int t = w->pending;
  w->pending = w->back;
  w->back = t;
  w->fresh = 1;
  w->submitted++;
  const int failed = w->failed;
  pthread_cond_signal(&w->cv);
  pthread_mutex_unlock(&w->mu);
  return failed ? -1 : 0;
}

int viewer_window_frame(viewer_window_t *w, sim_t *s, double *t0_s, const char *recording) {
  atomic_fetch_add_explicit(&w->passes, 1, memory_order_relaxed); /* one per step */
  double now = app_wall_s();
  if (manual_drive_update(&w->manual, w->in.manual, w->in.car, w->in.drive_keys, w->url, now) < 0)
    sim_viewer_set_manual(w->v, 0); /* could not start: the radio back to Autonomous */
  /* ~30 Hz of wall time, and no more than one frame per 1/30 s of sim time */
  if (now < w->next_frame_s || sim_time_us(s) < w->next_frame_us) return 0;
  w->next_frame_us = sim_time_us(s) + (int64_t)(VIEWER_FRAME_S * 1e6);
  sim_viewer_input_t *in = &w->in;
  do {
    w->next_frame_s = now + VIEWER_FRAME_S;
    viewer_rtf(w, s, now);
    sim_viewer_poll(w->v, in);
    if (viewer_submit(w, s, recording, now) != 0) return 1;
    w->record_toggles += in->record_toggled;
    if (in->quit || app_stop_requested()) return 1;
    if (in->reset_requested) {
      /* back to the start poses (qpos0, core/src/car_placement.c); late boxes that appeared come
       * back on the next step; encoder counts restart with the wheel angles, as when a car is
       * picked up and put back */
      const double t_s = sim_data(s)->time; /* the sim's clock runs on */
      mj_resetData(sim_model(s), sim_data(s));
      sim_data(s)->time = t_s;
      mj_forward(sim_model(s), sim_data(s));
    }
    if (in->paused && !in->step_requested) {
      struct timespec ts = {0, 30000000L};
      nanosleep(&ts, NULL);
      const double later = app_wall_s();
      *t0_s += later - now;
      w->rtf_wall_s += later - now; /* a pause is no slow-down */
      now = later;
    }
  } while (in->paused && !in->step_requested);
  return 0;
}

void viewer_window_lidar(viewer_window_t *w, const sim_t *s, int car,
                         const sim_lidar_scan_t *scan) {
  if (!w->v || !scan || car != w->in.car || !w->in.lidar_rays) return;
  sim_truth_t t;
  sim_get_truth(s, car, &t);
  const double o[3] = {t.pos_m[0], t.pos_m[1], t.pos_m[2] + VIEWER_LIDAR_HEIGHT_M};
  int n = 0;
  for (int i = 0; i < scan->num_rays && n < VIEWER_MAX_RAYS; i++) {
    const float r = scan->ranges_m[i];
    if (!isfinite(r)) continue;
    const double a = t.yaw_rad + scan->angle_min_rad + i * scan->angle_increment_rad;
    w->ray_end[3 * n] = (float)(o[0] + r * cos(a));
    w->ray_end[3 * n + 1] = (float)(o[1] + r * sin(a));
    w->ray_end[3 * n + 2] = (float)o[2];
    n++;
  }
  memcpy(w->ray_origin, o, sizeof o);
  w->nrays = n;
}

void viewer_window_stop(viewer_window_t *w) {
  if (!w->started) return;
  pthread_mutex_lock(&w->mu);
  w->stop = 1;
  pthread_cond_signal(&w->cv);
  pthread_mutex_unlock(&w->mu);
  pthread_join(w->th, NULL);
  w->started = 0;
}

static int viewer_cmp_double(const void *a, const void *b) {
  const double x = *(const double *)a, y = *(const double *)b;
  return (x > y) - (x < y);
}

static double viewer_median_draw_s(const viewer_window_t *w) {
  const long n = w->untimed;
  if (n == 0) return 0.0;
  static double sorted[VIEWER_WINDOW_TIMED_FRAMES];
  memcpy(sorted, w->draw_s, (size_t)n * sizeof *sorted);
  qsort(sorted, (size_t)n, sizeof *sorted, viewer_cmp_double);
  return n % 2 ? sorted[n / 2] : 0.5 * (sorted[n / 2 - 1] + sorted[n / 2]);
}

void viewer_window_print_bench(const viewer_window_t *w, FILE *f) {
  const double draw_s = viewer_median_draw_s(w);
  const double span_s = w->last_frame_s - w->first_frame_s;
  int software = 0;
  const char *renderer = sim_viewer_renderer(w->v, &software);
  fprintf(f,
          ", \"viewer_frames\": %ld, \"viewer_snapshots\": %ld, \"viewer_frame_ms_median\": %.3f, "
          "\"viewer_fps\": %.2f, \"viewer_fps_drawn\": %.2f, \"viewer_render_scale\": %.2f, "
          "\"viewer_software_gl\": %s, \"viewer_renderer\": \"",
          w->frames, w->submitted, draw_s * 1e3, draw_s > 0 ? 1.0 / draw_s : 0.0,
          w->frames > 1 && span_s > 0 ? (w->frames - 1) / span_s : 0.0, w->in.render_scale,
          software ? "true" : "false");
  for (const char *c = renderer; *c; c++) /* JSON: the name's quotes and backslashes escaped */
    fprintf(f, (*c == '"' || *c == '\\') ? "\\%c" : "%c", *c);
  fputc('"', f);
  double ms[SIM_VIEWER_PARTS];
  const char *names[SIM_VIEWER_PARTS];
  const long timed = sim_viewer_parts(w->v, ms, names);
  fprintf(f, ", \"viewer_steps_while_drawing\": %ld, \"viewer_parts_frames\": %ld",
          w->steps_while_drawing, timed);
  for (int p = 0; p < SIM_VIEWER_PARTS; p++)
    fprintf(f, ", \"viewer_%s_ms_median\": %.3f", names[p], ms[p]);
}

void viewer_window_close(viewer_window_t *w) {
  viewer_window_stop(w);
  manual_drive_stop(&w->manual);
  control_status_lcm_destroy(w->lease);
  w->lease = NULL;
  if (w->hud_log) fclose(w->hud_log);
  w->hud_log = NULL;
  if (w->v) sim_viewer_destroy(w->v);
  w->v = NULL;
  for (int i = 0; i < 3; i++) {
    if (w->slot[i].d) mj_deleteData(w->slot[i].d);
    w->slot[i].d = NULL;
  }
  if (w->sync_made) {
    pthread_cond_destroy(&w->cv);
    pthread_mutex_destroy(&w->mu);
  }
  w->sync_made = 0;
}
