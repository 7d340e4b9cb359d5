/* Wheel speeds from encoder counts: a difference over a fixed window, then a first-order
 * low-pass. Integer only. */
#ifndef AUTODRIVE_WHEEL_SPEED_H
#define AUTODRIVE_WHEEL_SPEED_H

#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

#define WHEEL_SPEED_PERIOD_US 10000ul /* [us] difference window */
#define WHEEL_SPEED_FILTER_SHIFT 2u   /* IIR weight 1/4 per window: ~35 ms time constant */

typedef struct wheel_speed {
  int32_t prev_counts[2]; /* [counts] at the start of the window */
  int32_t speed_x16[2];   /* filtered speed [mrad/s / 16] */
  uint32_t last_us;       /* [us] start of the window */
  uint8_t have;           /* prev_counts is valid */
} wheel_speed_t;

void wheel_speed_init(wheel_speed_t *w);
/* Call every loop pass; computes a new speed when a window has elapsed. */
void wheel_speed_update(wheel_speed_t *w, int32_t left_counts, int32_t right_counts,
                        uint32_t now_us);
int16_t wheel_speed_mrad_s(const wheel_speed_t *w, uint8_t wheel); /* 0 left, 1 right [mrad/s] */

#ifdef __cplusplus
}
#endif
#endif
