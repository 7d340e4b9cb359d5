/* Failsafe state machine; see failsafe.h and PROTOCOL.md. */
#include "failsafe.h"

#include "protocol.h"

void failsafe_init(failsafe_t *f, uint16_t timeout_ms) {
  f->last_cmd_us = 0;
  f->mode = PROTOCOL_MODE_DISARMED;
  f->fresh = 0;
  f->prev_disengaged = 0;
  f->link_lost = 0;
  failsafe_set_timeout_ms(f, timeout_ms);
}

void failsafe_set_timeout_ms(failsafe_t *f, uint16_t timeout_ms) {
  f->timeout_us = (uint32_t)timeout_ms * 1000ul;
}

void failsafe_update(failsafe_t *f, uint32_t now_us) {
  if (!f->fresh) return;
  if ((uint32_t)(now_us - f->last_cmd_us) < f->timeout_us) return;
  /* The stream went stale: an arming sequence must start over. */
  f->fresh = 0;
  f->prev_disengaged = 0;
  if (f->mode == PROTOCOL_MODE_ENGAGED) {
    f->mode = PROTOCOL_MODE_FAILSAFE;
    f->link_lost = 1;
  }
}

uint8_t failsafe_on_command(failsafe_t *f, uint8_t engaged, uint32_t now_us) {
  /* A command that arrives after a silent gap must not hide that gap. */
  failsafe_update(f, now_us);
  f->last_cmd_us = now_us;
  f->fresh = 1;
  if (!engaged) {
    /* Disengaging is always honoured; FAILSAFE stays until re-armed (latched fault). */
    if (f->mode == PROTOCOL_MODE_ENGAGED) f->mode = PROTOCOL_MODE_DISARMED;
    f->prev_disengaged = 1;
    return 0;
  }
  if (f->mode == PROTOCOL_MODE_ENGAGED) return 0;
  if (!f->prev_disengaged) return 0; /* engaged=1 without a fresh engaged=0 first: ignored */
  f->mode = PROTOCOL_MODE_ENGAGED;
  f->prev_disengaged = 0;
  f->link_lost = 0;
  return 1;
}
