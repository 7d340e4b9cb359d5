/* MuJoCo alone on the world's model (sim.h: sim_bare_*): the baseline the benchmarks compare
 * the sim's step with, and the clocks they read. */
#include <stdlib.h>
#include <time.h>

#include "sim_internal.h"

double sim_clock_s(clockid_t id) {
  struct timespec t;
  clock_gettime(id, &t);
  return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

struct sim_bare {
  const mjModel *m;
  mjData *d;
};

sim_bare_t *sim_bare_create(const sim_t *s) {
  sim_bare_t *b = calloc(1, sizeof *b);
  if (!b) return NULL;
  b->m = s->m;
  b->d = mj_makeData(s->m);
  if (!b->d) {
    free(b);
    return NULL;
  }
  sim_bare_sync(b, s);
  return b;
}

void sim_bare_sync(sim_bare_t *b, const sim_t *s) {
  const mjModel *m = s->m;
  const mjData *d = s->d;
  b->d->time = d->time;
  mju_copy(b->d->qpos, d->qpos, m->nq);
  mju_copy(b->d->qvel, d->qvel, m->nv);
  mju_copy(b->d->qacc_warmstart, d->qacc_warmstart, m->nv);
  mju_copy(b->d->act, d->act, m->na);
  mju_copy(b->d->ctrl, d->ctrl, m->nu);
  mju_copy(b->d->qfrc_applied, d->qfrc_applied, m->nv);
  mju_copy(b->d->xfrc_applied, d->xfrc_applied, 6 * m->nbody);
  mju_copy(b->d->mocap_pos, d->mocap_pos, 3 * m->nmocap);
  mju_copy(b->d->mocap_quat, d->mocap_quat, 4 * m->nmocap);
}

double sim_bare_run(sim_bare_t *b, int steps, double *cpu_s) {
  const double w0 = sim_clock_s(CLOCK_MONOTONIC), c0 = sim_clock_s(CLOCK_THREAD_CPUTIME_ID);
  for (int k = 0; k < steps; k++) mj_step(b->m, b->d);
  if (cpu_s) *cpu_s = sim_clock_s(CLOCK_THREAD_CPUTIME_ID) - c0;
  return sim_clock_s(CLOCK_MONOTONIC) - w0;
}

void sim_bare_destroy(sim_bare_t *b) {
  if (!b) return;
  mj_deleteData(b->d);
  free(b);
}

double sim_bare_mj_step_s(const sim_t *s, int steps, double *cpu_s) {
  sim_bare_t *b = sim_bare_create(s);
  if (!b) return -1.0;
  const double wall = sim_bare_run(b, steps, cpu_s);
  sim_bare_destroy(b);
  return wall;
}
