/* What every part of the program autodrive-sim shares: the stop request (SIGINT, SIGTERM)
 * and the wall and CPU clocks it paces and measures with. */
#ifndef SIM_APP_COMMON_H
#define SIM_APP_COMMON_H

#include <time.h>

#include "sim.h"

/* SIGINT and SIGTERM ask the run to stop; SIGPIPE is ignored (a client hanging up). */
void app_stop_install(void);
int app_stop_requested(void);

/* Wall time now [s] (CLOCK_MONOTONIC). */
static inline double app_wall_s(void) {
  return sim_clock_s(CLOCK_MONOTONIC);
}
/* CPU time of this process [s]: on a shared, loaded machine it shows the cost without the
 * time spent waiting for a core */
static inline double app_cpu_s(void) {
  return sim_clock_s(CLOCK_PROCESS_CPUTIME_ID);
}

#endif
