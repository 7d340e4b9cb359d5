/* The optional window (viewer_window.h). */
#include "viewer_window.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "app_common.h"
#include "hud_text.h"

#define VIEWER_FRAME_S (1.0 / 30.0) /* [s] wall between frames */
#define VIEWER_RTF_WINDOW_S 1.0     /* [s] wall over which the HUD's rtf is measured */
#define VIEWER_LIDAR_HEIGHT_M 0.12  /* rays drawn this far above base_link (the RPLIDAR's deck) */

int viewer_window_open(viewer_window_t *w, const sim_t *s, int want, int width_px, int height_px,
                       const char *map_name, const char *url, int ptys, const char *hud_log,
                       char *err, size_t err_sz) {
  memset(w, 0, sizeof *w);
  manual_drive_init(&w->manual);
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
  w->rtf_wall_s = app_wall_s();
  if (ptys && !(w->lease = control_status_lcm_create(url, sim_cars(s), err, err_sz))) return -1;
  if (hud_log && !(w->hud_log = fopen(hud_log, "w"))) {
    snprintf(err, err_sz, "--hud-log '%s': %s", hud_log, strerror(errno));
    return -1;
  }
  return 0;
}

/* The HUD's real-time factor, measured over the last VIEWER_RTF_WINDOW_S of wall time. */
static void viewer_rtf(viewer_window_t *w, const sim_t *s, double now_s) {
  if (now_s - w->rtf_wall_s < VIEWER_RTF_WINDOW_S) return;
  w->rtf = (sim_time_us(s) - w->rtf_sim_us) * 1e-6 / (now_s - w->rtf_wall_s);
  w->rtf_wall_s = now_s;
  w->rtf_sim_us = sim_time_us(s);
}

/* --hud-log: one line per frame, sim time [us] then title=value fields (tab-separated). */
static void viewer_hud_log(viewer_window_t *w, const sim_t *s, const char *titles,
                           const char *values) {
  if (!w->hud_log) return;
  fprintf(w->hud_log, "%lld", (long long)sim_time_us(s));
  const char *t = titles, *v = values;
  while (*t) {
    const size_t tn = strcspn(t, "\n"), vn = strcspn(v, "\n");
    fprintf(w->hud_log, "\t%.*s=%.*s", (int)tn, t, (int)vn, v);
    t += tn + (t[tn] != 0);
    v += vn + (v[vn] != 0);
  }
  fputc('\n', w->hud_log);
  fflush(w->hud_log);
}

int viewer_window_frame(viewer_window_t *w, sim_t *s, double *t0_s, const char *recording) {
  double now = app_wall_s();
  if (manual_drive_update(&w->manual, w->in.manual, w->in.car, w->in.drive_keys, w->url, now) < 0)
    sim_viewer_set_manual(w->v, 0); /* could not start: the radio back to Autonomous */
  /* ~30 Hz of wall time, but no more than one frame per 1/30 s of sim time: on a slow machine
   * the window must not take the time the stepping needs */
  if (now < w->next_frame_s || sim_time_us(s) < w->next_frame_us) return 0;
  w->next_frame_us = sim_time_us(s) + (int64_t)(VIEWER_FRAME_S * 1e6);
  sim_viewer_input_t *in = &w->in;
  do {
    w->next_frame_s = now + VIEWER_FRAME_S;
    viewer_rtf(w, s, now);
    char titles[2048], values[2048];
    control_status_lcm_poll(w->lease, now);
    const hud_extra_t x = {recording, w->manual.status, w->lease, now};
    hud_text_build(s, w->rtf, &x, titles, sizeof titles, values, sizeof values);
    viewer_hud_log(w, s, titles, values);
    sim_viewer_set_hud(w->v, titles, values);
    const double draw0_s = app_wall_s();
    if (sim_viewer_frame(w->v, sim_render_model(s), sim_render_data(s), in) != 0) return 1;
    if (w->frames < VIEWER_WINDOW_TIMED_FRAMES) w->draw_s[w->frames] = app_wall_s() - draw0_s;
    w->frames++;
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
  float ends[3 * 1024];
  sim_truth_t t;
  sim_get_truth(s, car, &t);
  const double o[3] = {t.pos_m[0], t.pos_m[1], t.pos_m[2] + VIEWER_LIDAR_HEIGHT_M};
  int n = 0;
  for (int i = 0; i < scan->num_rays && n < 1024; i++) {
    const float r = scan->ranges_m[i];
    if (!isfinite(r)) continue;
    const double a = t.yaw_rad + scan->angle_min_rad + i * scan->angle_increment_rad;
    ends[3 * n] = (float)(o[0] + r * cos(a));
    ends[3 * n + 1] = (float)(o[1] + r * sin(a));
    ends[3 * n + 2] = (float)o[2];
    n++;
  }
  sim_viewer_set_rays(w->v, o, ends, n);
}

static int viewer_cmp_double(const void *a, const void *b) {
  const double x = *(const double *)a, y = *(const double *)b;
  return (x > y) - (x < y);
}

double viewer_window_median_draw_s(const viewer_window_t *w) {
  const long n = w->frames < VIEWER_WINDOW_TIMED_FRAMES ? w->frames : VIEWER_WINDOW_TIMED_FRAMES;
  if (n == 0) return 0.0;
  static double sorted[VIEWER_WINDOW_TIMED_FRAMES];
  memcpy(sorted, w->draw_s, (size_t)n * sizeof *sorted);
  qsort(sorted, (size_t)n, sizeof *sorted, viewer_cmp_double);
  return n % 2 ? sorted[n / 2] : 0.5 * (sorted[n / 2 - 1] + sorted[n / 2]);
}

void viewer_window_close(viewer_window_t *w) {
  manual_drive_stop(&w->manual);
  control_status_lcm_destroy(w->lease);
  w->lease = NULL;
  if (w->hud_log) fclose(w->hud_log);
  w->hud_log = NULL;
  if (w->v) sim_viewer_destroy(w->v);
  w->v = NULL;
}
