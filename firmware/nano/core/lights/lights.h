/* Lights logic: headlights off/low/high, taillights while braking, reverse lights while
 * reversing, indicators left/right/hazard blinking at 1.5 Hz. */
#ifndef AUTODRIVE_LIGHTS_H
#define AUTODRIVE_LIGHTS_H

#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

#define LIGHTS_BLINK_HALF_US 333333ul /* [us] on and off time: 1.5 Hz */

typedef struct lights {
  uint32_t phase_us; /* [us] start of the current blink half period */
  uint8_t blink_on;  /* indicator lamps lit in this half period */
  uint8_t ind_prev;  /* indicator mode of the last update (0..3) */
  uint8_t lamps;     /* NANO_CORE_LAMP_* of the last update */
  uint8_t state;     /* PROTOCOL_LIGHTS_* of the last update */
} lights_t;

void lights_init(lights_t *l, uint32_t now_us);
/* headlights 0..2, indicators 0..3 (3 hazard). braking/reversing: 0 or 1. Sets l->lamps
 * (for the HAL) and l->state (for STATE telemetry), and returns l->lamps. */
uint8_t lights_update(lights_t *l, uint8_t headlights, uint8_t indicators, uint8_t braking,
                      uint8_t reversing, uint32_t now_us);

#ifdef __cplusplus
}
#endif
#endif
