/* Actuator mapping: throttle -> motor duty/direction/brake with a slew limit; steering ->
 * servo pulse with trim, saturation and the steering rate limit of the real servo.
 * Integer only (runs every loop pass on the AVR). */
#ifndef AUTODRIVE_ACTUATION_H
#define AUTODRIVE_ACTUATION_H

#include <stdint.h>

#include "actuation_vehicle.h" /* servo figures, generated from vehicle/nigel.params */

#ifdef __cplusplus
extern "C" {
#endif

#define ACTUATION_FULL 1000000L                /* internal full scale [1e-6 of 1.0] */
#define ACTUATION_THROTTLE_SLEW_PER_S 4000000L /* [1e-6/s]: 0 -> full throttle in 250 ms */
#define ACTUATION_MAX_DT_US 50000ul            /* a longer gap is treated as this [us] */

/* actuation_update flags */
#define ACTUATION_STOP 0x01u          /* throttle to 0 at once (no slew), brake on */
#define ACTUATION_HOLD_STEERING 0x02u /* ignore the steering target, keep the servo where it is */

typedef struct actuation {
  int32_t throttle_u; /* applied throttle [1e-6], + forward */
  int32_t steering_u; /* applied steering [1e-6], + left */
  uint32_t last_us;   /* [us] time of the last update */
  int16_t trim_us;    /* servo trim [us], validated by the caller */
  /* outputs of the last update */
  uint16_t servo_us;    /* [us] */
  uint8_t duty;         /* 0..255 */
  uint8_t reverse;      /* 1: backwards */
  uint8_t brake;        /* 1: motor shorted */
  uint8_t decelerating; /* 1: |target| < |applied| or target opposes applied (taillights) */
} actuation_t;

void actuation_init(actuation_t *a, uint32_t now_us);
/* Moves the applied values toward the targets [milli] at the rate limits and computes the
 * outputs. flags ACTUATION_STOP (disarmed, failsafe, battery cut-off): throttle goes to 0 at once
 * (no slew) and the brake is applied. ACTUATION_HOLD_STEERING (not engaged): the servo holds.
 * Integer multiply/shift only: no division per call (~1000 calls/s on the AVR). */
void actuation_update(actuation_t *a, int16_t throttle_milli, int16_t steering_milli, uint8_t flags,
                      uint32_t now_us);
int16_t actuation_throttle_milli(const actuation_t *a);
int16_t actuation_steering_milli(const actuation_t *a);

#ifdef __cplusplus
}
#endif
#endif
