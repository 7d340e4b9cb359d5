/* autodrive-sim --bench in free lockstep: every block of the sim's own steps is followed by a
 * block of bare mj_step on the same model (sim_bare_t), and each pair's time ratio is kept.
 * On a shared, loaded machine both halves of a pair see the same load, so the median of the
 * per-block ratios is a steadier overhead figure than one sim run followed by one bare run. */
#ifndef SIM_BENCH_PAIRS_H
#define SIM_BENCH_PAIRS_H

#include <stdio.h>

#include "sim.h"

#ifdef __cplusplus
extern "C" {
#endif

#define BENCH_PAIRS_BLOCK_STEPS 1000 /* 1 s of sim time per block [1 ms steps] */

typedef struct bench_pairs {
  const sim_t *sim; /* whose state each bare block starts from */
  sim_bare_t *bare;
  double block_wall0_s, block_cpu0_s; /* start of the sim block in progress */
  double bare_wall_s, bare_cpu_s;     /* all bare blocks so far */
  long bare_steps;
  int n, cap;
  double *ratio_wall, *ratio_cpu; /* sim block / bare block, per pair */
} bench_pairs_t;

/* The median of v[0..n) (0 when n <= 0); v is not changed. */
double bench_median(const double *v, int n);

/* Starts pairing on s (the cars at their start poses). Returns 0, or -1 when out of memory. */
int bench_pairs_start(bench_pairs_t *bp, const sim_t *s);
/* Call after the sim's step number `step` (1-based). At the end of a block it runs the bare
 * block and returns its wall time [s], which the caller leaves out of the run's time; else 0. */
double bench_pairs_after_step(bench_pairs_t *bp, long step);
/* The stepping thread's CPU time [s] the bare blocks took (to leave out of the run's). */
double bench_pairs_bare_cpu_s(const bench_pairs_t *bp);
/* Prints the JSON members (with a leading comma): the bare rtf by wall and CPU time over all
 * bare blocks, and the medians of the per-pair ratios bare rtf / sim rtf (overhead). */
void bench_pairs_print_json(const bench_pairs_t *bp, FILE *out);
void bench_pairs_free(bench_pairs_t *bp);

#ifdef __cplusplus
}
#endif
#endif
