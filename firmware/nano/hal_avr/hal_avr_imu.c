#include "hal_avr_imu.h"

#include <stdint.h>

#include "hal_avr_twi.h"

#define MPU_ADDR 0x68u
#define AK_ADDR 0x0Cu
#define MPU_WHO_AM_I 0x75u

/* Register writes of the bring-up, in order: clock from the gyro PLL, DLPF 41 Hz, gyro
 * +-500 deg/s, accel +-4 g, I2C bypass on (AK8963 visible), AK8963 16-bit continuous 100 Hz. */
static const uint8_t k_init[][3] = {
    {MPU_ADDR, 0x6Bu, 0x01u}, {MPU_ADDR, 0x1Au, 0x03u}, {MPU_ADDR, 0x1Bu, 0x08u},
    {MPU_ADDR, 0x1Cu, 0x08u}, {MPU_ADDR, 0x37u, 0x02u}, {AK_ADDR, 0x0Au, 0x16u},
};
#define INIT_STEPS (sizeof k_init / sizeof k_init[0])

enum { ST_PROBE, ST_INIT, ST_ACCEL, ST_MAG, ST_IDLE, ST_WAIT_RETRY };

static uint8_t s_state, s_step, s_reg;
static uint8_t s_buf[14];
static uint32_t s_txn_start_us, s_last_ok_us, s_retry_at_us, s_sample_start_us;
static uint8_t s_have_sample;
static nano_core_imu_raw_t s_sample;

static int16_t be16(const uint8_t *p) {
  return (int16_t)((uint16_t)p[0] << 8 | p[1]);
}
static int16_t le16(const uint8_t *p) {
  return (int16_t)((uint16_t)p[1] << 8 | p[0]);
}

static void begin(uint8_t state, uint32_t now_us) {
  s_state = state;
  s_txn_start_us = now_us;
  switch (state) {
    case ST_PROBE:
      s_reg = MPU_WHO_AM_I;
      hal_avr_twi_start(MPU_ADDR, &s_reg, 1, s_buf, 1);
      break;
    case ST_INIT: hal_avr_twi_start(k_init[s_step][0], &k_init[s_step][1], 2, 0, 0); break;
    case ST_ACCEL:
      s_sample_start_us = now_us;
      s_reg = 0x3Bu; /* ACCEL_XOUT_H .. GYRO_ZOUT_L, big-endian */
      hal_avr_twi_start(MPU_ADDR, &s_reg, 1, s_buf, 14);
      break;
    case ST_MAG:
      s_reg = 0x03u; /* HXL .. HZH, ST2 (reading ST2 releases the next sample) */
      hal_avr_twi_start(AK_ADDR, &s_reg, 1, s_buf, 7);
      break;
    default: break;
  }
}

static void fail(uint32_t now_us) {
  hal_avr_twi_abort();
  s_state = ST_WAIT_RETRY;
  s_retry_at_us = now_us + HAL_AVR_IMU_RETRY_US;
}

void hal_avr_imu_init(uint32_t now_us) {
  hal_avr_twi_init();
  s_have_sample = 0;
  begin(ST_PROBE, now_us);
}

void hal_avr_imu_poll(uint32_t now_us) {
  if (s_state == ST_IDLE) {
    if (now_us - s_sample_start_us >= HAL_AVR_IMU_PERIOD_US) begin(ST_ACCEL, now_us);
    return;
  }
  if (s_state == ST_WAIT_RETRY) {
    if ((int32_t)(now_us - s_retry_at_us) >= 0) begin(ST_PROBE, now_us);
    return;
  }
  uint8_t st = hal_avr_twi_status();
  if (st == HAL_AVR_TWI_BUSY) {
    if (now_us - s_txn_start_us > HAL_AVR_IMU_TXN_TIMEOUT_US) fail(now_us);
    return;
  }
  if (st == HAL_AVR_TWI_ERROR) {
    fail(now_us);
    return;
  }
  switch (s_state) {
    case ST_PROBE:
      if (s_buf[0] != 0x71u && s_buf[0] != 0x73u) { /* MPU-9250 / MPU-9255 */
        fail(now_us);
        return;
      }
      s_step = 0;
      begin(ST_INIT, now_us);
      break;
    case ST_INIT:
      if (++s_step < INIT_STEPS) {
        begin(ST_INIT, now_us);
      } else {
        begin(ST_ACCEL, now_us);
      }
      break;
    case ST_ACCEL:
      for (uint8_t i = 0; i < 3; i++) {
        s_sample.accel[i] = be16(&s_buf[2u * i]);
        s_sample.gyro[i] = be16(&s_buf[8u + 2u * i]);
      }
      begin(ST_MAG, now_us);
      break;
    case ST_MAG:
      /* AK8963 axes in the accel frame: x_acc = y_mag, y_acc = x_mag, z_acc = -z_mag */
      s_sample.mag[0] = le16(&s_buf[2]);
      s_sample.mag[1] = le16(&s_buf[0]);
      s_sample.mag[2] = (int16_t)(-(int32_t)le16(&s_buf[4])); /* -(-32768) saturates below */
      if (le16(&s_buf[4]) == INT16_MIN) s_sample.mag[2] = INT16_MAX;
      s_have_sample = 1;
      s_last_ok_us = now_us;
      s_state = ST_IDLE;
      break;
    default: break;
  }
}

int hal_avr_imu_read(uint32_t now_us, nano_core_imu_raw_t *out) {
  if (!s_have_sample || now_us - s_last_ok_us > HAL_AVR_IMU_STALE_US) return -1;
  *out = s_sample;
  return 0;
}
