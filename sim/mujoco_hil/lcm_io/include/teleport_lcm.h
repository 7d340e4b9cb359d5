/* SIM_TELEPORT on LCM (autodrive-sim --allow-teleport, lockstep modes only): a pose2d_t whose
 * `vehicle` names a car (NIGEL<i>) puts that car at (x_m, y_m, yaw_rad) of the world, standing
 * still (sim_teleport). For evaluations that put a car back on its lane after an intervention
 * (tools/demo --mission cloning); never subscribed otherwise, so nothing on a normal run can
 * move a car but its own Nano. Each teleport is logged on stdout, each refusal on stderr. */
#ifndef SIM_TELEPORT_LCM_H
#define SIM_TELEPORT_LCM_H

#include <lcm/lcm.h>

#include "sim.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct teleport_lcm teleport_lcm_t;

/* NULL on an LCM error (message in err). */
teleport_lcm_t *teleport_lcm_create(lcm_t *lcm, sim_t *s, char *err, size_t err_sz);
void teleport_lcm_destroy(teleport_lcm_t *k);
/* Handles the requests waiting on the socket (no wait), before the next step. */
void teleport_lcm_poll(teleport_lcm_t *k);
/* Teleports done so far, and how many were refused. */
long teleport_lcm_count(const teleport_lcm_t *k, long *refused);

#ifdef __cplusplus
}
#endif
#endif
