/* Who holds each car's control lease, for the window's HUD: <VEH>_CONTROL (control_status_t,
 * the runtime's bridge, 5 Hz and on every change of holder) of the first cars, on an lcm_t of
 * its own so that the main bus keeps its kernel filter. Made only with the window and the ptys
 * open (without a runtime on a pty nobody publishes it). Polled, never waited on. */
#ifndef SIM_CONTROL_STATUS_LCM_H
#define SIM_CONTROL_STATUS_LCM_H

#include <stddef.h>

#ifdef __cplusplus
extern "C" {
#endif

#define CONTROL_STATUS_LCM_MAX_CARS 4
#define CONTROL_STATUS_LCM_STALE_S 1.0 /* [s] wall without a message: the runtime is gone */

typedef struct control_status_lcm control_status_lcm_t;

/* Listens to the first cars (up to CONTROL_STATUS_LCM_MAX_CARS) on url. NULL with err. */
control_status_lcm_t *control_status_lcm_create(const char *url, int cars, char *err,
                                                size_t err_sz);
void control_status_lcm_destroy(control_status_lcm_t *c);
/* Handles what arrived (no wait); now_s: wall time [s] it is stamped with. */
void control_status_lcm_poll(control_status_lcm_t *c, double now_s);
/* The lease of car (1-based) as text: "teleop (person)", "autonomy (machine)", "free", or "-"
 * when no CONTROL came in the last CONTROL_STATUS_LCM_STALE_S (c NULL: "-"). */
void control_status_lcm_holder(const control_status_lcm_t *c, int car, double now_s, char *out,
                               size_t n);

#ifdef __cplusplus
}
#endif
#endif
