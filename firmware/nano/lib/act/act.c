/* Actuator mapping; see act.h. */
#include "act.h"

static int32_t move_toward(int32_t cur, int32_t target, int32_t max_step) {
  if (target > cur) return (target - cur > max_step) ? cur + max_step : target;
  return (cur - target > max_step) ? cur - max_step : target;
}

static int32_t abs32(int32_t v) { return v < 0 ? -v : v; }

void act_init(act_t *a, uint32_t now_us) {
  a->throttle_u = 0;
  a->steering_u = 0;
  a->last_us = now_us;
  a->trim_us = 0;
  a->servo_us = ACT_SERVO_CENTER_US;
  a->duty = 0;
  a->reverse = 0;
  a->brake = 1;
  a->decelerating = 0;
}

void act_update(act_t *a, int16_t throttle_milli, int16_t steering_milli, uint8_t stop,
                uint32_t now_us) {
  uint32_t dt_us = (uint32_t)(now_us - a->last_us);
  int32_t thr_target = (int32_t)throttle_milli * 1000L;
  int32_t steer_target = (int32_t)steering_milli * 1000L;
  int32_t pulse;
  a->last_us = now_us;
  if (dt_us > ACT_MAX_DT_US) dt_us = ACT_MAX_DT_US;

  if (stop) thr_target = 0;
  /* taillights: the driver asks for less drive than is applied (or the other direction) */
  a->decelerating = (uint8_t)(stop || abs32(thr_target) < abs32(a->throttle_u) ||
                              (thr_target < 0 && a->throttle_u > 0) ||
                              (thr_target > 0 && a->throttle_u < 0));
  if (stop)
    a->throttle_u = 0; /* stopping is never slew-limited */
  else
    a->throttle_u =
        move_toward(a->throttle_u, thr_target, (int32_t)dt_us * (ACT_THROTTLE_SLEW_PER_S / 1000000L));
  a->steering_u =
      move_toward(a->steering_u, steer_target, (int32_t)((dt_us * (uint32_t)ACT_STEER_RATE_X1E4) / 10000ul));

  /* duty 0..255, rounded */
  a->duty = (uint8_t)((abs32(a->throttle_u) * 255L + ACT_FULL / 2) / ACT_FULL);
  a->reverse = (uint8_t)(a->throttle_u < 0);
  a->brake = (uint8_t)(stop || a->duty == 0u);
  if (a->brake) a->duty = 0;

  /* + steering (left) lengthens the pulse */
  pulse = ACT_SERVO_CENTER_US + a->trim_us +
          (a->steering_u / (ACT_FULL / 1000L)) * ACT_SERVO_HALF_RANGE_US / 1000L;
  if (pulse < ACT_SERVO_MIN_US) pulse = ACT_SERVO_MIN_US;
  if (pulse > ACT_SERVO_MAX_US) pulse = ACT_SERVO_MAX_US;
  a->servo_us = (uint16_t)pulse;
}

int16_t act_throttle_milli(const act_t *a) { return (int16_t)(a->throttle_u / 1000L); }
int16_t act_steering_milli(const act_t *a) { return (int16_t)(a->steering_u / 1000L); }
