/* Deterministic noise: splitmix64 with Box-Muller Gaussians. Same seed, same sequence. */
#ifndef SIM_RNG_H
#define SIM_RNG_H

#include <stdint.h>

typedef struct rng {
  uint64_t state;
} rng_t;

void rng_seed(rng_t *r, uint64_t seed);
double rng_uniform(rng_t *r);             /* [0, 1) */
double rng_gauss(rng_t *r, double sigma); /* N(0, sigma^2) */

#endif
