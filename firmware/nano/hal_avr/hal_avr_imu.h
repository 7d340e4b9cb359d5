/* MPU-9250 (0x68) with its AK8963 magnetometer (0x0C, reached through the MPU's I2C bypass)
 * on the non-blocking TWI driver. hal_avr_imu_poll() advances a small state machine and returns at
 * once; a transaction that has not finished within HAL_AVR_IMU_TXN_TIMEOUT_US is aborted, and the
 * IMU is re-initialised every HAL_AVR_IMU_RETRY_US while it is absent. */
#ifndef AUTODRIVE_HAL_AVR_IMU_H
#define AUTODRIVE_HAL_AVR_IMU_H
#include <stdint.h>

#include "nano_core_hal.h"
#ifdef __cplusplus
extern "C" {
#endif
#define HAL_AVR_IMU_TXN_TIMEOUT_US 2000ul /* a 14-byte read takes ~0.45 ms at 400 kHz */
#define HAL_AVR_IMU_RETRY_US 100000ul     /* [us] between re-initialisations of an absent IMU */
#define HAL_AVR_IMU_PERIOD_US 5000ul      /* [us] between samples: 200 Hz, above the 41 Hz DLPF */
#define HAL_AVR_IMU_STALE_US 20000ul      /* [us] a sample older than this counts as lost */

void hal_avr_imu_init(uint32_t now_us);
void hal_avr_imu_poll(uint32_t now_us);
/* Latest sample; returns 0 if it is fresh (< HAL_AVR_IMU_STALE_US old), nonzero otherwise. */
int hal_avr_imu_read(uint32_t now_us, nano_core_imu_raw_t *out);
#ifdef __cplusplus
}
#endif
#endif
