/* Failsafe: the state machine that decides whether the car may drive (see PROTOCOL.md,
 * "Failsafe state machine").
 *
 * DISARMED at boot. ENGAGED only after a valid COMMAND with engaged=0 directly followed (within
 * the timeout) by one with engaged=1, so a host that was already streaming engaged=1 before a
 * reset cannot move the car. While ENGAGED, no valid COMMAND for timeout -> FAILSAFE with the
 * latched link_lost flag; leaving FAILSAFE needs the same engaged=0 -> engaged=1 sequence. */
#ifndef AUTODRIVE_FAILSAFE_H
#define AUTODRIVE_FAILSAFE_H

#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

#define FAILSAFE_DEFAULT_TIMEOUT_MS 100u

typedef struct failsafe {
  uint32_t last_cmd_us;    /* [us] time of the last valid COMMAND */
  uint32_t timeout_us;     /* [us] */
  uint8_t mode;            /* PROTOCOL_MODE_* */
  uint8_t fresh;           /* 1: a valid COMMAND arrived less than timeout ago */
  uint8_t prev_disengaged; /* 1: the last fresh valid COMMAND had engaged=0 (arming allowed) */
  uint8_t link_lost;       /* latched PROTOCOL_FAULT_LINK_LOST; cleared only by re-arming */
} failsafe_t;

void failsafe_init(failsafe_t *f, uint16_t timeout_ms);
/* timeout_ms must already be validated (protocol_config_valid). */
void failsafe_set_timeout_ms(failsafe_t *f, uint16_t timeout_ms);
/* A valid COMMAND arrived. Returns 1 when this command armed the car (DISARMED/FAILSAFE ->
 * ENGAGED): the caller then clears its own latched faults. */
uint8_t failsafe_on_command(failsafe_t *f, uint8_t engaged, uint32_t now_us);
/* Checks the timeout; call every loop pass (and it is called by failsafe_on_command first). */
void failsafe_update(failsafe_t *f, uint32_t now_us);
/* 1 when drive is allowed by the link (mode ENGAGED). */
static inline uint8_t failsafe_may_drive(const failsafe_t *f) {
  return (uint8_t)(f->mode == 1u);
}

#ifdef __cplusplus
}
#endif
#endif
