/* Mahony AHRS on MPU-9250 raw samples (accel, gyro, magnetometer already in the same axes).
 * Body axes x forward, y left, z up; the quaternion rotates body to world (z up, x towards
 * magnetic north when the magnetometer is present). Floats: runs at the IMU rate only. */
#ifndef AUTODRIVE_AHRS_H
#define AUTODRIVE_AHRS_H

#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

#define AHRS_KP 1.0f         /* proportional gain [1/s] */
#define AHRS_KI 0.02f        /* integral gain (gyro bias) [1/s^2] */
#define AHRS_KP_SETTLE 10.0f /* proportional gain for the first AHRS_SETTLE_US */
#define AHRS_SETTLE_US 2000000ul
#define AHRS_MAX_DT_US 100000ul /* a longer gap between samples is treated as this [us] */

typedef struct ahrs {
  float q[4];       /* w x y z, unit */
  float ei[3];      /* integral of the error [rad/s] (gyro bias estimate) */
  float rate[3];    /* gyro rate of the pending sample [rad/s] */
  float err[3];     /* direction error of the pending sample (gravity + field) */
  float dt;         /* [s] to integrate; 0 when nothing is pending */
  uint32_t last_us; /* [us] time of the last sample */
  uint32_t run_us;  /* [us] time since the first sample, saturating */
  uint8_t have;     /* last_us is valid */
  uint8_t have_acc; /* the pending sample had a usable accelerometer reading */
  uint8_t settled;  /* past AHRS_SETTLE_US: normal gain */
} ahrs_t;

void ahrs_init(ahrs_t *a);
/* One sample in raw LSB (PROTOCOL_ACCEL_LSB_PER_G, PROTOCOL_GYRO_LSB_PER_DPS, mag any scale; an
 * all-zero mag means "no magnetometer"). */
void ahrs_update(ahrs_t *a, const int16_t accel[3], const int16_t gyro[3], const int16_t mag[3],
                 uint32_t now_us);
/* ahrs_update in three steps of similar cost, so the firmware can spread one update over
 * three loop passes (software floats on the AVR): the gravity error, the magnetic-field error
 * (skipped when mag is all zero), and the PI feedback + integration of q. ahrs_correct_mag and
 * ahrs_integrate do nothing unless ahrs_correct started a sample. */
void ahrs_correct(ahrs_t *a, const int16_t accel[3], const int16_t gyro[3], uint32_t now_us);
void ahrs_correct_mag(ahrs_t *a, const int16_t mag[3]);
void ahrs_integrate(ahrs_t *a);
/* The quaternion in Q14 (PROTOCOL_QUAT_ONE = 1.0). */
void ahrs_quat_q14(const ahrs_t *a, int16_t out[4]);

#ifdef __cplusplus
}
#endif
#endif
