/* Mahony complementary filter: the gyro integrates the attitude; the directions of gravity
 * (accelerometer) and of the horizontal magnetic field (magnetometer) pull it back through a
 * PI feedback on the gyro rate. See ahrs.h for axes. */
#include "ahrs.h"

#include <math.h>

#include "protocol.h"

/* [rad/s per LSB]: pi/180 / PROTOCOL_GYRO_LSB_PER_DPS, one constant so it costs one multiply */
#define GYRO_RAD_S_PER_LSB ((float)(3.14159265358979 / 180.0 / PROTOCOL_GYRO_LSB_PER_DPS))

void ahrs_init(ahrs_t *a) {
  a->q[0] = 1.0f;
  a->q[1] = a->q[2] = a->q[3] = 0.0f;
  a->ei[0] = a->ei[1] = a->ei[2] = 0.0f;
  a->rate[0] = a->rate[1] = a->rate[2] = 0.0f;
  a->err[0] = a->err[1] = a->err[2] = 0.0f;
  a->dt = 0.0f;
  a->have_acc = 0;
  a->settled = 0;
  a->last_us = 0;
  a->run_us = 0;
  a->have = 0;
}

/* Normalises v[3] in place; returns 0 when it is (nearly) zero. */
static int norm3(float v[3]) {
  float n2 = v[0] * v[0] + v[1] * v[1] + v[2] * v[2];
  float inv;
  if (!(n2 > 1e-12f)) return 0;
  inv = 1.0f / sqrtf(n2);
  v[0] *= inv;
  v[1] *= inv;
  v[2] *= inv;
  return 1;
}

void ahrs_update(ahrs_t *a, const int16_t accel[3], const int16_t gyro[3], const int16_t mag[3],
                 uint32_t now_us) {
  ahrs_correct(a, accel, gyro, now_us);
  ahrs_correct_mag(a, mag);
  ahrs_integrate(a);
}

void ahrs_correct(ahrs_t *a, const int16_t accel[3], const int16_t gyro[3], uint32_t now_us) {
  float acc[3];
  float w = a->q[0], x = a->q[1], y = a->q[2], z = a->q[3];
  uint32_t dt_us;
  int i;

  a->dt = 0.0f; /* nothing to integrate unless this sample has a dt */
  a->have_acc = 0;
  if (!a->have) {
    a->have = 1;
    a->last_us = now_us;
    return; /* no dt yet */
  }
  dt_us = (uint32_t)(now_us - a->last_us);
  a->last_us = now_us;
  if (dt_us == 0u) return;
  if (dt_us > AHRS_MAX_DT_US) dt_us = AHRS_MAX_DT_US;
  a->dt = (float)dt_us * 1e-6f;
  a->settled = (uint8_t)(a->run_us >= AHRS_SETTLE_US);
  a->run_us = (a->run_us < AHRS_SETTLE_US) ? a->run_us + dt_us : AHRS_SETTLE_US;

  for (i = 0; i < 3; ++i) {
    acc[i] = (float)accel[i];
    a->rate[i] = (float)gyro[i] * GYRO_RAD_S_PER_LSB;
    a->err[i] = 0.0f;
  }
  a->have_acc = (uint8_t)norm3(acc);
  if (a->have_acc) {
    /* gravity ("up") as the estimate sees it in body axes: third row of R(q) */
    float vx = 2.0f * (x * z - w * y), vy = 2.0f * (y * z + w * x);
    float vz = w * w - x * x - y * y + z * z;
    a->err[0] = acc[1] * vz - acc[2] * vy;
    a->err[1] = acc[2] * vx - acc[0] * vz;
    a->err[2] = acc[0] * vy - acc[1] * vx;
  }
}

void ahrs_correct_mag(ahrs_t *a, const int16_t mag[3]) {
  float mg[3];
  float w = a->q[0], x = a->q[1], y = a->q[2], z = a->q[3];
  int i;
  /* heading needs gravity to define "horizontal" */
  if (!(a->dt > 0.0f) || !a->have_acc) return;
  for (i = 0; i < 3; ++i) mg[i] = (float)mag[i];
  if (!norm3(mg)) return; /* no magnetometer */
  {
    /* Rotation body->world from q. The field in world axes, flattened onto north + up, then
     * back into body axes: its direction error against the measured one corrects yaw. */
    float ww = w * w, xx = x * x, yy = y * y, zz = z * z;
    float xy = x * y, xz = x * z, yz = y * z, wx = w * x, wy = w * y, wz = w * z;
    float r00 = ww + xx - yy - zz, r01 = 2.0f * (xy - wz), r02 = 2.0f * (xz + wy);
    float r10 = 2.0f * (xy + wz), r11 = ww - xx + yy - zz, r12 = 2.0f * (yz - wx);
    float r20 = 2.0f * (xz - wy), r21 = 2.0f * (yz + wx), r22 = ww - xx - yy + zz;
    float hx = r00 * mg[0] + r01 * mg[1] + r02 * mg[2];
    float hy = r10 * mg[0] + r11 * mg[1] + r12 * mg[2];
    float hz = r20 * mg[0] + r21 * mg[1] + r22 * mg[2];
    float bx = sqrtf(hx * hx + hy * hy), bz = hz;
    float mx = bx * r00 + bz * r20, my = bx * r01 + bz * r21, mz = bx * r02 + bz * r22;
    a->err[0] += mg[1] * mz - mg[2] * my;
    a->err[1] += mg[2] * mx - mg[0] * mz;
    a->err[2] += mg[0] * my - mg[1] * mx;
  }
}

void ahrs_integrate(ahrs_t *a) {
  float *g = a->rate;
  float w = a->q[0], x = a->q[1], y = a->q[2], z = a->q[3];
  float dt = a->dt, qn[4], inv;
  int i;
  if (!(dt > 0.0f)) return;
  a->dt = 0.0f; /* integrate each sample once */
  if (a->have_acc) {
    float kp = a->settled ? AHRS_KP : AHRS_KP_SETTLE;
    for (i = 0; i < 3; ++i) {
      a->ei[i] += AHRS_KI * a->err[i] * dt;
      g[i] += kp * a->err[i] + a->ei[i];
    }
  }
  /* q += 0.5 * q (x) (0, g) * dt */
  qn[0] = w + 0.5f * dt * (-x * g[0] - y * g[1] - z * g[2]);
  qn[1] = x + 0.5f * dt * (w * g[0] + y * g[2] - z * g[1]);
  qn[2] = y + 0.5f * dt * (w * g[1] - x * g[2] + z * g[0]);
  qn[3] = z + 0.5f * dt * (w * g[2] + x * g[1] - y * g[0]);
  inv = qn[0] * qn[0] + qn[1] * qn[1] + qn[2] * qn[2] + qn[3] * qn[3];
  if (!(inv > 1e-12f) || inv != inv) {
    ahrs_init(a); /* numerically lost: restart level rather than emit garbage */
    return;
  }
  inv = 1.0f / sqrtf(inv);
  /* keep w >= 0 so the Q14 output is unambiguous */
  if (qn[0] < 0.0f) inv = -inv;
  for (i = 0; i < 4; ++i) a->q[i] = qn[i] * inv;
}

void ahrs_quat_q14(const ahrs_t *a, int16_t out[4]) {
  int i;
  for (i = 0; i < 4; ++i) {
    float v = a->q[i] * (float)PROTOCOL_QUAT_ONE;
    if (v > 32767.0f) v = 32767.0f;
    if (v < -32767.0f) v = -32767.0f;
    out[i] = (int16_t)(v < 0.0f ? v - 0.5f : v + 0.5f);
  }
}
