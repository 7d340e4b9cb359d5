/* LCM output of the simulator: <VEH>_GROUND_TRUTH (100 Hz), SIM_CLOCK, and the ground-truth
 * record file used to check determinism (encoded ground_truth_t, each prefixed by its size as
 * a 4-byte big-endian length). */
#ifndef SIM_LCMPUB_H
#define SIM_LCMPUB_H

#include <stdint.h>
#include <stdio.h>

#include <lcm/lcm.h>

#include "sim.h"

/* Publishes car's ground truth on NIGEL<car>_GROUND_TRUTH; appends it to log if non-NULL.
 * Returns 0, or -1 when LCM refused the message. */
int lcmpub_truth(lcm_t *lcm, const sim_t *s, int car, FILE *log);
int lcmpub_clock(lcm_t *lcm, int64_t utime, double rtf, int paused);

#endif
