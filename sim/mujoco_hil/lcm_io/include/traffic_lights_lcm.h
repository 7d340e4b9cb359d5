/* The traffic lights on LCM (program side): TRAFFIC_LIGHT_COMMAND in, TRAFFIC_LIGHT_STATE out
 * for every light at 10 Hz of sim time and at once on each change (a command's effect is
 * published as soon as the command is handled). A refused command is logged on stderr
 * naming the light ids. Nothing is subscribed or published on a map without lights.
 * Signed (<autodrive_v2x/v2x_auth.h>): the states with the simulator's certificate SIM.cert
 * (role light-controller), and only commands signed by an scm and fresh on sim time count. */
#ifndef SIM_TRAFFIC_LIGHTS_LCM_H
#define SIM_TRAFFIC_LIGHTS_LCM_H

#include <stdint.h>

#include <lcm/lcm.h>

#include "traffic_lights.h"

#ifdef __cplusplus
extern "C" {
#endif

#define TRAFFIC_LIGHTS_LCM_STATE_PERIOD_US 100000 /* 10 Hz of sim time */

typedef struct traffic_lights_lcm traffic_lights_lcm_t;

/* NULL when the map has no lights (nothing to do) or on an LCM error (message in err). url:
 * the one lcm was made with. filter_bus: on udpm:// its receive socket then keeps only the
 * commands and also_keep's messages unless NULL (lcm_receive_filter.h), so lcm must subscribe
 * to nothing else; 0 when it does. */
traffic_lights_lcm_t *traffic_lights_lcm_create(lcm_t *lcm, const char *url, traffic_lights_t *t,
                                                int filter_bus, const char *also_keep, char *err,
                                                size_t err_sz);
void traffic_lights_lcm_destroy(traffic_lights_lcm_t *k);

/* Handles the commands waiting on the socket (no wait) at sim time now_us: accepted ones
 * change the light at once and its new state is published. */
void traffic_lights_lcm_poll(traffic_lights_lcm_t *k, int64_t now_us);

/* After a sim step at now_us: publishes the lights whose state changed in it, and every light
 * when the 10 Hz period is due. */
void traffic_lights_lcm_publish(traffic_lights_lcm_t *k, int64_t now_us);

/* Commands handled so far (signed by an scm), and how many of those were refused. */
long traffic_lights_lcm_commands(const traffic_lights_lcm_t *k, long *refused);
/* Commands dropped before that: unsigned, forged, stale, replayed, wrong role, revoked. */
long traffic_lights_lcm_unverified(const traffic_lights_lcm_t *k);

#ifdef __cplusplus
}
#endif
#endif
