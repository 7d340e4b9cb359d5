/* splitmix64 + Box-Muller (see rng.h). */
#include "rng.h"

#include <math.h>

void rng_seed(rng_t *r, uint64_t seed) {
  r->state = seed;
}

static uint64_t rng_next(rng_t *r) {
  uint64_t z = (r->state += 0x9E3779B97F4A7C15ull);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

double rng_uniform(rng_t *r) {
  return (rng_next(r) >> 11) * 0x1.0p-53;
}

double rng_gauss(rng_t *r, double sigma) {
  if (sigma <= 0.0) return 0.0;
  const double u1 = 1.0 - rng_uniform(r), u2 = rng_uniform(r);
  return sigma * sqrt(-2.0 * log(u1)) * cos(2.0 * M_PI * u2);
}
