/* Lights logic; see lights.h. */
#include "lights.h"

#include "nano_core_hal.h"
#include "protocol.h"

void lights_init(lights_t *l, uint32_t now_us) {
  l->phase_us = now_us;
  l->blink_on = 0;
  l->ind_prev = 0;
  l->lamps = 0;
  l->state = 0;
}

uint8_t lights_update(lights_t *l, uint8_t headlights, uint8_t indicators, uint8_t braking,
                      uint8_t reversing, uint32_t now_us) {
  uint8_t lamps = 0, state;
  indicators &= 3u;
  if (indicators != l->ind_prev) {
    /* a new indicator mode starts with the lamps lit, as in a car */
    l->phase_us = now_us;
    l->blink_on = 1;
    l->ind_prev = indicators;
  } else if ((uint32_t)(now_us - l->phase_us) >= LIGHTS_BLINK_HALF_US) {
    l->phase_us += LIGHTS_BLINK_HALF_US;
    /* after a long gap, restart the phase rather than catching up */
    if ((uint32_t)(now_us - l->phase_us) >= LIGHTS_BLINK_HALF_US) l->phase_us = now_us;
    l->blink_on = (uint8_t)!l->blink_on;
  }
  if (headlights == 1u) lamps |= NANO_CORE_LAMP_HEAD_LOW;
  if (headlights >= 2u) lamps |= NANO_CORE_LAMP_HEAD_LOW | NANO_CORE_LAMP_HEAD_HIGH;
  if (braking) lamps |= NANO_CORE_LAMP_TAIL;
  if (reversing) lamps |= NANO_CORE_LAMP_REVERSE;
  state = (uint8_t)((headlights > 2u ? 2u : headlights) & PROTOCOL_LIGHTS_HEAD_MASK);
  state |= (uint8_t)(indicators << PROTOCOL_LIGHTS_IND_SHIFT);
  if (braking) state |= PROTOCOL_LIGHTS_TAIL;
  if (reversing) state |= PROTOCOL_LIGHTS_REVERSE;
  if (l->blink_on) {
    if (indicators & 1u) {
      lamps |= NANO_CORE_LAMP_IND_LEFT;
      state |= PROTOCOL_LIGHTS_BLINK_LEFT;
    }
    if (indicators & 2u) {
      lamps |= NANO_CORE_LAMP_IND_RIGHT;
      state |= PROTOCOL_LIGHTS_BLINK_RIGHT;
    }
  }
  l->lamps = lamps;
  l->state = state;
  return lamps;
}
