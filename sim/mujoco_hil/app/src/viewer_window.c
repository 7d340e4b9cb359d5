/* The optional window (viewer_window.h). */
#include "viewer_window.h"

#include <stdio.h>
#include <string.h>
#include <time.h>

#include "app_common.h"

int viewer_window_open(viewer_window_t *w, const sim_t *s, int want, char *err, size_t err_sz) {
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

int viewer_window_frame(viewer_window_t *w, sim_t *s, double *t0_s) {
  sim_viewer_input_t in;
  double now = app_wall_s();
  if (now < w->next_frame_s) return 0;
  do {
    w->next_frame_s = now + 1.0 / 30.0;
    if (sim_viewer_frame(w->v, sim_render_model(s), sim_render_data(s), &in) != 0) return 1;
    if (in.quit || app_stop_requested()) return 1;
    if (in.reset_requested) {
      /* back to the start poses (qpos0, core/src/car_placement.c); late boxes that appeared come
       * back on the next step; encoder counts restart with the wheel angles, as when a car is
       * picked up and put back */
      mj_resetData(sim_model(s), sim_data(s));
      mj_forward(sim_model(s), sim_data(s));
    }
    if (in.paused) {
      struct timespec ts = {0, 30000000L};
      nanosleep(&ts, NULL);
      const double later = app_wall_s();
      *t0_s += later - now;
      now = later;
    }
  } while (in.paused);
  return 0;
}

void viewer_window_close(viewer_window_t *w) {
  if (w->v) sim_viewer_destroy(w->v);
  w->v = NULL;
}
