/* Wheel speeds; see wheel_speed.h. */
#include "wheel_speed.h"

/* 2 pi / 1920 [rad/count] * 1e3 [mrad/rad] * 1e6 [us/s] = 3272492.3; times 16 for the filter
 * state would overflow, so the raw speed is formed first and scaled after. */
#define WHEEL_SPEED_MRAD_US_PER_COUNT 3272492L
/* [counts] per window: 0.3 rev in 10 ms, far above top speed */
#define WHEEL_SPEED_MAX_DELTA 600L

void wheel_speed_init(wheel_speed_t *w) {
  w->prev_counts[0] = w->prev_counts[1] = 0;
  w->speed_x16[0] = w->speed_x16[1] = 0;
  w->last_us = 0;
  w->have = 0;
}

static int32_t raw_speed(int32_t delta, uint32_t dt_us) {
  if (delta > WHEEL_SPEED_MAX_DELTA) delta = WHEEL_SPEED_MAX_DELTA;
  if (delta < -WHEEL_SPEED_MAX_DELTA) delta = -WHEEL_SPEED_MAX_DELTA;
  return delta * WHEEL_SPEED_MRAD_US_PER_COUNT / (int32_t)dt_us; /* [mrad/s] */
}

void wheel_speed_update(wheel_speed_t *w, int32_t left_counts, int32_t right_counts,
                        uint32_t now_us) {
  uint32_t dt_us;
  int32_t counts[2];
  uint8_t i;
  counts[0] = left_counts;
  counts[1] = right_counts;
  if (!w->have) {
    w->prev_counts[0] = left_counts;
    w->prev_counts[1] = right_counts;
    w->last_us = now_us;
    w->have = 1;
    return;
  }
  dt_us = (uint32_t)(now_us - w->last_us);
  if (dt_us < WHEEL_SPEED_PERIOD_US) return;
  if (dt_us > 10ul * WHEEL_SPEED_PERIOD_US) dt_us = 10ul * WHEEL_SPEED_PERIOD_US; /* stalled loop */
  for (i = 0; i < 2u; ++i) {
    int32_t v_x16 =
        raw_speed((int32_t)((uint32_t)counts[i] - (uint32_t)w->prev_counts[i]), dt_us) * 16L;
    /* arithmetic on the difference keeps the rounding symmetric for + and - speeds */
    int32_t d = v_x16 - w->speed_x16[i];
    w->speed_x16[i] += d / (1L << WHEEL_SPEED_FILTER_SHIFT);
    w->prev_counts[i] = counts[i];
  }
  w->last_us = now_us;
}

int16_t wheel_speed_mrad_s(const wheel_speed_t *w, uint8_t wheel) {
  int32_t v = w->speed_x16[wheel & 1u] / 16L;
  if (v > 32767L) v = 32767L;
  if (v < -32767L) v = -32767L;
  return (int16_t)v;
}
