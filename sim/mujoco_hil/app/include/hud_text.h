/* The window's HUD text (sim_viewer_set_hud): sim time, the real-time factor, the recording,
 * who drives the ego car, and for each car its mode (engaged, disarmed, failsafe), speed, throttle
 * and steering as commanded and as applied, encoder counts, IMU, battery, lamps and the holder of
 * its control lease, then the traffic lights' states. Read from the world and the emulated Nanos,
 * as the car's STATE frame would carry them. */
#ifndef SIM_APP_HUD_TEXT_H
#define SIM_APP_HUD_TEXT_H

#include <stddef.h>

#include "control_status_lcm.h"
#include "sim.h"

#define HUD_TEXT_MAX_CARS 4 /* cars listed; more are counted */

/* What the HUD shows beside the world: the recording (its folder or file, or NULL), who drives
 * the ego car (manual_drive_t's status), and the control leases (NULL: not listened to). */
typedef struct hud_extra {
  const char *recording;
  const char *driving;
  const control_status_lcm_t *lease;
  double now_s; /* [s] wall, for the lease's age */
} hud_extra_t;

/* titles and values: the two columns, lines split by '\n'. */
void hud_text_build(sim_t *s, double rtf, const hud_extra_t *x, char *titles, size_t titles_sz,
                    char *values, size_t values_sz);

#endif
