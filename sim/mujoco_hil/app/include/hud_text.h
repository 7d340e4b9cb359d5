/* The window's HUD text (sim_viewer_set_hud): sim time, the real-time factor, the recording,
 * and for each car its mode (engaged, disarmed, failsafe), speed, throttle and steering as
 * commanded and as applied, encoder counts, IMU, battery and lamps, then the traffic lights'
 * states. Read from the world and the emulated Nanos, as the car's STATE frame would carry
 * them. */
#ifndef SIM_APP_HUD_TEXT_H
#define SIM_APP_HUD_TEXT_H

#include <stddef.h>

#include "sim.h"

#define HUD_TEXT_MAX_CARS 4 /* cars listed; more are counted */

/* titles and values: the two columns, lines split by '\n'. recording: its folder or file, or
 * NULL. */
void hud_text_build(sim_t *s, double rtf, const char *recording, char *titles, size_t titles_sz,
                    char *values, size_t values_sz);

#endif
