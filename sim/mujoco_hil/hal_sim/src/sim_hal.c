/* The firmware HAL (nano_core_hal.h) implemented on the sim: what the emulated Nano's firmware
 * core sees as hardware. Motor, servo and lamp outputs land in the car's state for
 * core/actuation.c; the IMU and battery are read from MuJoCo with the car's noise; serial
 * bytes go onto the Nano's TX wire (nano_link/). */
#include <math.h>

#include "encoder.h"
#include "sim_internal.h"

#define SIM_G_M_S2 9.80665

static void hal_motor_set(void *ctx, uint8_t duty, uint8_t reverse, uint8_t brake) {
  sim_car_t *c = ctx;
  c->duty = duty;
  c->reverse = reverse;
  c->brake = brake;
}

static void hal_servo_set_us(void *ctx, uint16_t pulse_us) {
  ((sim_car_t *)ctx)->servo_us = pulse_us;
}

static void hal_lamps_set(void *ctx, uint8_t lamps) {
  ((sim_car_t *)ctx)->lamps = lamps;
}

static int16_t sim_sat16(double v) {
  if (v > 32767.0) return 32767;
  if (v < -32768.0) return -32768;
  return (int16_t)lround(v);
}

/* MPU-9250 sample from MuJoCo's accelerometer/gyro/magnetometer at the IMU site (car axes:
 * x forward, y left, z up), plus the car's bias and white noise, in the chip's LSB. */
static int hal_imu_read(void *ctx, nano_core_imu_raw_t *out) {
  sim_car_t *c = ctx;
  const sim_t *s = c->sim;
  const mjtNum *sd = s->d->sensordata;
  for (int k = 0; k < 3; k++) {
    const double a =
        sd[c->accel_adr + k] + c->accel_bias[k] + rng_gauss(&c->rng, s->p.accel_noise_m_s2);
    const double w =
        sd[c->gyro_adr + k] + c->gyro_bias[k] + rng_gauss(&c->rng, s->p.gyro_noise_rad_s);
    const double b = sd[c->mag_adr + k] + rng_gauss(&c->rng, s->p.mag_noise_ut);
    out->accel[k] = sim_sat16(a / SIM_G_M_S2 * PROTOCOL_ACCEL_LSB_PER_G);
    out->gyro[k] = sim_sat16(w * (180.0 / M_PI) * PROTOCOL_GYRO_LSB_PER_DPS);
    out->mag[k] = sim_sat16(b / PROTOCOL_MAG_UT_PER_LSB);
  }
  return 0;
}

static uint16_t hal_battery_read_mv(void *ctx) {
  sim_car_t *c = ctx;
  const double v = c->sim->p.battery_v + rng_gauss(&c->rng, c->sim->p.battery_noise_v);
  return (uint16_t)lround(fmax(0.0, v) * 1000.0);
}

static void hal_serial_write(void *ctx, const uint8_t *data, uint8_t n) {
  uart_push(&((sim_car_t *)ctx)->tx, data, n);
}

void sim_hal_bind(sim_car_t *c) {
  c->hal.ctx = c;
  c->hal.motor_set = hal_motor_set;
  c->hal.servo_set_us = hal_servo_set_us;
  c->hal.lamps_set = hal_lamps_set;
  c->hal.imu_read = hal_imu_read;
  c->hal.battery_read_mv = hal_battery_read_mv;
  c->hal.serial_write = hal_serial_write;
}

/* The firmware's turn in a step: the bytes that finished crossing the RX wire during it, then
 * its loop with the rear wheels' encoder counts. */
void sim_nano_step(sim_t *s, sim_car_t *c) {
  uint8_t buf[255];
  const size_t n = uart_pop(&c->rx, SIM_STEP_US, buf, sizeof buf);
  if (n > 0) nano_core_rx(&c->nano, buf, (uint8_t)n, (uint32_t)s->time_us);
  const double k = (double)ENCODER_COUNTS_PER_REV / (2.0 * M_PI);
  const int32_t enc_l = (int32_t)floor(s->d->qpos[c->wheel_qpos[W_RL]] * k);
  const int32_t enc_r = (int32_t)floor(s->d->qpos[c->wheel_qpos[W_RR]] * k);
  nano_core_step(&c->nano, (uint32_t)s->time_us, enc_l, enc_r);
}
