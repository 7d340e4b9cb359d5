/* Actuator mapping; see actuation.h. */
#include "actuation.h"

static int32_t move_toward(int32_t cur, int32_t target, int32_t max_step) {
  if (target > cur) return (target - cur > max_step) ? cur + max_step : target;
  return (cur - target > max_step) ? cur - max_step : target;
}

static int32_t abs32(int32_t v) {
  return v < 0 ? -v : v;
}

void actuation_init(actuation_t *a, uint32_t now_us) {
  a->throttle_u = 0;
  a->steering_u = 0;
  a->last_us = now_us;
  a->trim_us = 0;
  a->servo_us = ACTUATION_SERVO_CENTER_US;
  a->duty = 0;
  a->reverse = 0;
  a->brake = 1;
  a->decelerating = 0;
}

/* |u| [1e-6] -> duty 0..255, rounded: 255/1e6 as 4279 / 2^24 (|u| <= 1e6 keeps it in 32 bit). */
static uint8_t duty_of(int32_t u) {
  uint32_t m = (uint32_t)(u < 0 ? -u : u);
  return (uint8_t)((m * 4279ul + (1ul << 23)) >> 24);
}

/* steering [1e-6] -> pulse offset [us] = u * 500 / 1e6, as u * 2097 / 2^22, rounded. */
static int16_t pulse_offset_of(int32_t u) {
  uint32_t m = (uint32_t)(u < 0 ? -u : u);
  int16_t off = (int16_t)((m * 2097ul + (1ul << 21)) >> 22);
  return u < 0 ? (int16_t)-off : off;
}

void actuation_update(actuation_t *a, int16_t throttle_milli, int16_t steering_milli, uint8_t flags,
                      uint32_t now_us) {
  uint32_t dt_us = (uint32_t)(now_us - a->last_us);
  uint8_t stop = (uint8_t)(flags & ACTUATION_STOP);
  int32_t thr_target = (int32_t)throttle_milli * 1000L;
  int32_t steer_target =
      (flags & ACTUATION_HOLD_STEERING) ? a->steering_u : (int32_t)steering_milli * 1000L;
  int32_t pulse;
  a->last_us = now_us;
  if (dt_us > ACTUATION_MAX_DT_US) dt_us = ACTUATION_MAX_DT_US;

  if (stop) thr_target = 0;
  /* taillights: the driver asks for less drive than is applied (or the other direction) */
  a->decelerating =
      (uint8_t)(stop || abs32(thr_target) < abs32(a->throttle_u) ||
                (thr_target < 0 && a->throttle_u > 0) || (thr_target > 0 && a->throttle_u < 0));
  if (stop)
    a->throttle_u = 0; /* stopping is never slew-limited */
  else
    a->throttle_u = move_toward(a->throttle_u, thr_target,
                                (int32_t)dt_us * (ACTUATION_THROTTLE_SLEW_PER_S / 1000000L));
  a->steering_u = move_toward(a->steering_u, steer_target,
                              (int32_t)((dt_us * (uint32_t)ACTUATION_STEER_RATE_Q14) >> 14));

  a->duty = duty_of(a->throttle_u);
  a->reverse = (uint8_t)(a->throttle_u < 0);
  a->brake = (uint8_t)(stop || a->duty == 0u);
  if (a->brake) a->duty = 0;

  /* + steering (left) lengthens the pulse */
  pulse = (int32_t)ACTUATION_SERVO_CENTER_US + a->trim_us + pulse_offset_of(a->steering_u);
  if (pulse < ACTUATION_SERVO_MIN_US) pulse = ACTUATION_SERVO_MIN_US;
  if (pulse > ACTUATION_SERVO_MAX_US) pulse = ACTUATION_SERVO_MAX_US;
  a->servo_us = (uint16_t)pulse;
}

int16_t actuation_throttle_milli(const actuation_t *a) {
  return (int16_t)(a->throttle_u / 1000L);
}
int16_t actuation_steering_milli(const actuation_t *a) {
  return (int16_t)(a->steering_u / 1000L);
}
