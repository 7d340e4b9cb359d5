#include "bench_pairs.h"

#include <stdlib.h>
#include <string.h>

static int bp_cmp(const void *a, const void *b) {
  const double x = *(const double *)a, y = *(const double *)b;
  return (x > y) - (x < y);
}

double bench_median(const double *v, int n) {
  if (n <= 0) return 0.0;
  double *w = malloc(sizeof *w * (size_t)n);
  if (!w) return 0.0;
  memcpy(w, v, sizeof *w * (size_t)n);
  qsort(w, (size_t)n, sizeof *w, bp_cmp);
  const double m = n % 2 ? w[n / 2] : 0.5 * (w[n / 2 - 1] + w[n / 2]);
  free(w);
  return m;
}

int bench_pairs_start(bench_pairs_t *bp, const sim_t *s) {
  memset(bp, 0, sizeof *bp);
  bp->sim = s;
  bp->bare = sim_bare_create(s);
  if (!bp->bare) return -1;
  bp->block_wall0_s = sim_clock_s(CLOCK_MONOTONIC);
  bp->block_cpu0_s = sim_clock_s(CLOCK_THREAD_CPUTIME_ID);
  return 0;
}

double bench_pairs_after_step(bench_pairs_t *bp, long step) {
  if (!bp->bare || step % BENCH_PAIRS_BLOCK_STEPS != 0) return 0.0;
  const double sim_wall = sim_clock_s(CLOCK_MONOTONIC) - bp->block_wall0_s;
  const double sim_cpu = sim_clock_s(CLOCK_THREAD_CPUTIME_ID) - bp->block_cpu0_s;
  double bare_cpu = 0.0;
  sim_bare_sync(bp->bare, bp->sim);
  const double bare_wall = sim_bare_run(bp->bare, BENCH_PAIRS_BLOCK_STEPS, &bare_cpu);
  if (bp->n == bp->cap) {
    const int cap = bp->cap ? 2 * bp->cap : 64;
    double *w = realloc(bp->ratio_wall, sizeof *w * (size_t)cap);
    if (w) bp->ratio_wall = w;
    double *c = realloc(bp->ratio_cpu, sizeof *c * (size_t)cap);
    if (c) bp->ratio_cpu = c;
    if (w && c) bp->cap = cap;
  }
  if (bp->n < bp->cap && bare_wall > 0 && bare_cpu > 0) {
    bp->ratio_wall[bp->n] = sim_wall / bare_wall; /* = bare rtf / sim rtf: the same steps */
    bp->ratio_cpu[bp->n] = sim_cpu / bare_cpu;
    bp->n++;
  }
  bp->bare_wall_s += bare_wall;
  bp->bare_cpu_s += bare_cpu;
  bp->bare_steps += BENCH_PAIRS_BLOCK_STEPS;
  bp->block_wall0_s = sim_clock_s(CLOCK_MONOTONIC);
  bp->block_cpu0_s = sim_clock_s(CLOCK_THREAD_CPUTIME_ID);
  return bare_wall;
}

double bench_pairs_bare_cpu_s(const bench_pairs_t *bp) {
  return bp->bare_cpu_s;
}

void bench_pairs_print_json(const bench_pairs_t *bp, FILE *out) {
  const double sim_s = bp->bare_steps * 1e-3;
  fprintf(out,
          ", \"bare_mj_step_rtf\": %.3f, \"bare_mj_step_rtf_cpu\": %.3f, \"bare_steps\": %ld, "
          "\"bench_pairs\": %d, \"overhead_ratio_paired\": %.4f, "
          "\"overhead_ratio_paired_cpu\": %.4f",
          bp->bare_wall_s > 0 ? sim_s / bp->bare_wall_s : 0.0,
          bp->bare_cpu_s > 0 ? sim_s / bp->bare_cpu_s : 0.0, bp->bare_steps, bp->n,
          bench_median(bp->ratio_wall, bp->n), bench_median(bp->ratio_cpu, bp->n));
}

void bench_pairs_free(bench_pairs_t *bp) {
  sim_bare_destroy(bp->bare);
  free(bp->ratio_wall);
  free(bp->ratio_cpu);
  memset(bp, 0, sizeof *bp);
}
