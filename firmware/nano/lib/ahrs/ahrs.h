/* Mahony AHRS on MPU-9250 raw samples (accel, gyro, magnetometer already in the same axes).
 * Body axes x forward, y left, z up; the quaternion rotates body to world (z up, x towards
 * magnetic north when the magnetometer is present). Floats: runs at the IMU rate only. */
#ifndef AUTODRIVE_AHRS_H
#define AUTODRIVE_AHRS_H

#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

#define AHRS_KP 1.0f          /* proportional gain [1/s] */
#define AHRS_KI 0.02f         /* integral gain (gyro bias) [1/s^2] */
#define AHRS_KP_SETTLE 10.0f  /* proportional gain for the first AHRS_SETTLE_US */
#define AHRS_SETTLE_US 2000000ul
#define AHRS_MAX_DT_US 100000ul /* a longer gap between samples is treated as this [us] */

typedef struct ahrs {
  float q[4];        /* w x y z, unit */
  float ei[3];       /* integral of the error [rad/s] (gyro bias estimate) */
  uint32_t last_us;  /* [us] time of the last sample */
  uint32_t run_us;   /* [us] time since the first sample, saturating */
  uint8_t have;      /* last_us is valid */
} ahrs_t;

void ahrs_init(ahrs_t *a);
/* One sample in raw LSB (PROTO_ACCEL_LSB_PER_G, PROTO_GYRO_LSB_PER_DPS, mag any scale; an
 * all-zero mag means "no magnetometer"). */
void ahrs_update(ahrs_t *a, const int16_t accel[3], const int16_t gyro[3], const int16_t mag[3],
                 uint32_t now_us);
/* The quaternion in Q14 (PROTO_QUAT_ONE = 1.0). */
void ahrs_quat_q14(const ahrs_t *a, int16_t out[4]);

#ifdef __cplusplus
}
#endif
#endif
