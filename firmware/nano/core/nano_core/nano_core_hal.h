/* The firmware core's only window onto hardware. Three implementations: the AVR board
 * (firmware/nano/hal_avr), host fakes (tests) and the simulator's emulated Nano (sim/mujoco_hil).
 * Time is never read through the HAL: the caller passes it in [us]. */
#ifndef AUTODRIVE_NANO_CORE_HAL_H
#define AUTODRIVE_NANO_CORE_HAL_H

#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/* Lamp outputs (bit set = lamp lit). */
#define NANO_CORE_LAMP_HEAD_LOW 0x01u
#define NANO_CORE_LAMP_HEAD_HIGH 0x02u
#define NANO_CORE_LAMP_TAIL 0x04u
#define NANO_CORE_LAMP_REVERSE 0x08u
#define NANO_CORE_LAMP_IND_LEFT 0x10u
#define NANO_CORE_LAMP_IND_RIGHT 0x20u

typedef struct nano_core_imu_raw {
  int16_t accel[3]; /* [LSB] at +-4 g, PROTOCOL_ACCEL_LSB_PER_G */
  int16_t gyro[3];  /* [LSB] at +-500 deg/s, PROTOCOL_GYRO_LSB_PER_DPS */
  int16_t mag[3];   /* [LSB], PROTOCOL_MAG_UT_PER_LSB, already in the accel/gyro axes */
} nano_core_imu_raw_t;

typedef struct nano_core_hal {
  void *ctx; /* passed back to every call */
  /* Drive motors (both rear motors share one driver channel). duty 0..255, reverse: 1 =
   * backwards, brake: 1 = short the motor (duty ignored). */
  void (*motor_set)(void *ctx, uint8_t duty, uint8_t reverse, uint8_t brake);
  /* Steering servo pulse width [us], 1000..2000 with 1500 straight ahead. */
  void (*servo_set_us)(void *ctx, uint16_t pulse_us);
  /* NANO_CORE_LAMP_* bits. */
  void (*lamps_set)(void *ctx, uint8_t lamps);
  /* Reads one IMU sample within bounded time; returns 0 on success, nonzero if the IMU is
   * absent or did not answer (the core then raises PROTOCOL_FAULT_IMU_LOST). */
  int (*imu_read)(void *ctx, nano_core_imu_raw_t *out);
  /* Battery pack voltage [mV]. */
  uint16_t (*battery_read_mv)(void *ctx);
  /* Queues bytes for the UART; must not block longer than the bytes' wire time. */
  void (*serial_write)(void *ctx, const uint8_t *data, uint8_t n);
} nano_core_hal_t;

#ifdef __cplusplus
}
#endif
#endif
