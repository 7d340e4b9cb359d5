/* The overhead cameras' render cost per frame and, with --eye-render compare, how the cached
 * frames differ from full renders (autodrive-sim --bench; tools/bench sim). */
#ifndef SIM_APP_RENDER_STATS_H
#define SIM_APP_RENDER_STATS_H

#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#define RENDER_STATS_MAX_FRAMES 8192 /* samples kept per kind (a longer run keeps the first) */

enum { RENDER_STATS_CACHED = 0, RENDER_STATS_FULL, RENDER_STATS_KINDS };

typedef struct render_stats {
  double *cpu_ms[RENDER_STATS_KINDS];  /* process CPU per frame, llvmpipe's threads included */
  double *wall_ms[RENDER_STATS_KINDS]; /* wall time per frame */
  int n[RENDER_STATS_KINDS];
  long compared_px, differing_px; /* pixels compared, and those differing in any channel */
  int max_abs_diff;               /* largest channel difference [8-bit levels] */
} render_stats_t;

/* 0, or -1 out of memory. */
int render_stats_init(render_stats_t *st);
void render_stats_free(render_stats_t *st);
/* Process CPU and wall clock now [s]: a frame's cost is the difference of two of these. */
void render_stats_clock(double t[2]);
/* One frame of kind, rendered since t0 (render_stats_clock). */
void render_stats_add(render_stats_t *st, int kind, const double t0[2]);
/* Compares a cached frame with the full render of the same state (n bytes of RGB). */
void render_stats_compare(render_stats_t *st, const uint8_t *full, const uint8_t *cached, size_t n);
/* The figures as JSON members, each preceded by ", " (nothing when no frame was timed). */
void render_stats_print_json(const render_stats_t *st, FILE *f);

#endif
