/* MPU-9250 (0x68) with its AK8963 magnetometer (0x0C, reached through the MPU's I2C bypass)
 * on the non-blocking TWI driver. fw_imu_poll() advances a small state machine and returns at
 * once; a transaction that has not finished within FW_IMU_TXN_TIMEOUT_US is aborted, and the
 * IMU is re-initialised every FW_IMU_RETRY_US while it is absent. */
#ifndef NIGEL_FW_IMU_H
#define NIGEL_FW_IMU_H
#include <stdint.h>

#include "nigel_hal.h"
#ifdef __cplusplus
extern "C" {
#endif
#define FW_IMU_TXN_TIMEOUT_US 2000ul /* a 14-byte read takes ~0.45 ms at 400 kHz */
#define FW_IMU_RETRY_US 100000ul     /* [us] between re-initialisations of an absent IMU */
#define FW_IMU_PERIOD_US 5000ul      /* [us] between samples: 200 Hz, above the 41 Hz DLPF */
#define FW_IMU_STALE_US 20000ul      /* [us] a sample older than this counts as lost */

void fw_imu_init(uint32_t now_us);
void fw_imu_poll(uint32_t now_us);
/* Latest sample; returns 0 if it is fresh (< FW_IMU_STALE_US old), nonzero otherwise. */
int fw_imu_read(uint32_t now_us, nigel_imu_raw_t *out);
#ifdef __cplusplus
}
#endif
#endif
