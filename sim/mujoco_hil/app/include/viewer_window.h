/* The optional window of autodrive-sim --view (sensors library, EGL context). */
#ifndef SIM_APP_VIEWER_WINDOW_H
#define SIM_APP_VIEWER_WINDOW_H

#include "sim.h"
#include "sim_viewer.h"

/* Drawn at ~30 Hz of wall time. */
typedef struct viewer_window {
  sim_viewer_t *v; /* NULL when off */
  double next_frame_s;
} viewer_window_t;

/* Opens it when want (a display is needed); else leaves w->v NULL. */
int viewer_window_open(viewer_window_t *w, const sim_t *s, int want, char *err, size_t err_sz);
/* Draws a frame when one is due; blocks while paused (shifting *t0_s so pacing resumes
 * smoothly). Returns 1 when the user quit. */
int viewer_window_frame(viewer_window_t *w, sim_t *s, double *t0_s);
void viewer_window_close(viewer_window_t *w);

#endif
