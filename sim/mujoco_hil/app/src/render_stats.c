/* The overhead cameras' render cost and the cached-vs-full check (render_stats.h). */
#include "render_stats.h"

#include <stdlib.h>
#include <string.h>

#include "app_common.h"
#include "bench_pairs.h"

int render_stats_init(render_stats_t *st) {
  memset(st, 0, sizeof *st);
  for (int k = 0; k < RENDER_STATS_KINDS; k++) {
    st->cpu_ms[k] = malloc(RENDER_STATS_MAX_FRAMES * sizeof(double));
    st->wall_ms[k] = malloc(RENDER_STATS_MAX_FRAMES * sizeof(double));
    if (!st->cpu_ms[k] || !st->wall_ms[k]) return -1;
  }
  return 0;
}

void render_stats_free(render_stats_t *st) {
  for (int k = 0; k < RENDER_STATS_KINDS; k++) {
    free(st->cpu_ms[k]);
    free(st->wall_ms[k]);
  }
  memset(st, 0, sizeof *st);
}

void render_stats_clock(double t[2]) {
  t[0] = app_cpu_s();
  t[1] = app_wall_s();
}

void render_stats_add(render_stats_t *st, int kind, const double t0[2]) {
  double t[2];
  render_stats_clock(t);
  if (!st->cpu_ms[kind] || st->n[kind] >= RENDER_STATS_MAX_FRAMES) return;
  st->cpu_ms[kind][st->n[kind]] = 1e3 * (t[0] - t0[0]);
  st->wall_ms[kind][st->n[kind]] = 1e3 * (t[1] - t0[1]);
  st->n[kind]++;
}

void render_stats_compare(render_stats_t *st, const uint8_t *full, const uint8_t *cached,
                          size_t n) {
  for (size_t i = 0; i + 2 < n; i += 3) {
    int d = 0;
    for (int c = 0; c < 3; c++) {
      const int e = abs((int)full[i + c] - (int)cached[i + c]);
      d = e > d ? e : d;
    }
    st->differing_px += d > 0;
    st->max_abs_diff = d > st->max_abs_diff ? d : st->max_abs_diff;
  }
  st->compared_px += (long)(n / 3);
}

void render_stats_print_json(const render_stats_t *st, FILE *f) {
  static const char *const name[RENDER_STATS_KINDS] = {"eye_render", "eye_render_full"};
  for (int k = 0; k < RENDER_STATS_KINDS; k++) {
    if (st->n[k] == 0) continue;
    fprintf(f, ", \"%s_frames\": %d, \"%s_cpu_ms_median\": %.3f, \"%s_wall_ms_median\": %.3f",
            name[k], st->n[k], name[k], bench_median(st->cpu_ms[k], st->n[k]), name[k],
            bench_median(st->wall_ms[k], st->n[k]));
  }
  if (st->compared_px > 0)
    fprintf(f,
            ", \"eye_render_compared_px\": %ld, \"eye_render_differing_px\": %ld, "
            "\"eye_render_differing_fraction\": %.3g, \"eye_render_max_abs_diff\": %d",
            st->compared_px, st->differing_px, (double)st->differing_px / (double)st->compared_px,
            st->max_abs_diff);
}
