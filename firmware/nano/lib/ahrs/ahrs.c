/* Mahony complementary filter: the gyro integrates the attitude; the directions of gravity
 * (accelerometer) and of the horizontal magnetic field (magnetometer) pull it back through a
 * PI feedback on the gyro rate. See ahrs.h for axes. */
#include "ahrs.h"

#include <math.h>

#include "proto.h"

#define DEG_TO_RAD 0.017453293f

void ahrs_init(ahrs_t *a) {
  a->q[0] = 1.0f;
  a->q[1] = a->q[2] = a->q[3] = 0.0f;
  a->ei[0] = a->ei[1] = a->ei[2] = 0.0f;
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
  float acc[3], mg[3], g[3], e[3] = {0.0f, 0.0f, 0.0f};
  float w = a->q[0], x = a->q[1], y = a->q[2], z = a->q[3];
  float dt, kp, qn[4], inv;
  uint32_t dt_us;
  int i, have_acc, have_mag;

  if (!a->have) {
    a->have = 1;
    a->last_us = now_us;
    return; /* no dt yet */
  }
  dt_us = (uint32_t)(now_us - a->last_us);
  a->last_us = now_us;
  if (dt_us == 0u) return;
  if (dt_us > AHRS_MAX_DT_US) dt_us = AHRS_MAX_DT_US;
  dt = (float)dt_us * 1e-6f;
  kp = a->run_us < AHRS_SETTLE_US ? AHRS_KP_SETTLE : AHRS_KP;
  a->run_us = (a->run_us < AHRS_SETTLE_US) ? a->run_us + dt_us : AHRS_SETTLE_US;

  for (i = 0; i < 3; ++i) {
    acc[i] = (float)accel[i];
    mg[i] = (float)mag[i];
    g[i] = (float)gyro[i] * (float)(1.0 / PROTO_GYRO_LSB_PER_DPS) * DEG_TO_RAD;
  }
  have_acc = norm3(acc);
  have_mag = norm3(mg);

  if (have_acc) {
    /* gravity ("up") as the estimate sees it in body axes: third row of R(q) */
    float vx = 2.0f * (x * z - w * y), vy = 2.0f * (y * z + w * x);
    float vz = w * w - x * x - y * y + z * z;
    e[0] += acc[1] * vz - acc[2] * vy;
    e[1] += acc[2] * vx - acc[0] * vz;
    e[2] += acc[0] * vy - acc[1] * vx;
  }
  if (have_acc && have_mag) {
    /* the field in world axes, flattened onto north + down, then back into body axes */
    float r00 = 1.0f - 2.0f * (y * y + z * z), r01 = 2.0f * (x * y - w * z),
          r02 = 2.0f * (x * z + w * y);
    float r10 = 2.0f * (x * y + w * z), r11 = 1.0f - 2.0f * (x * x + z * z),
          r12 = 2.0f * (y * z - w * x);
    float r20 = 2.0f * (x * z - w * y), r21 = 2.0f * (y * z + w * x),
          r22 = 1.0f - 2.0f * (x * x + y * y);
    float hx = r00 * mg[0] + r01 * mg[1] + r02 * mg[2];
    float hy = r10 * mg[0] + r11 * mg[1] + r12 * mg[2];
    float hz = r20 * mg[0] + r21 * mg[1] + r22 * mg[2];
    float bx = sqrtf(hx * hx + hy * hy), bz = hz;
    float wx = bx * r00 + bz * r20, wy = bx * r01 + bz * r21, wz = bx * r02 + bz * r22;
    e[0] += mg[1] * wz - mg[2] * wy;
    e[1] += mg[2] * wx - mg[0] * wz;
    e[2] += mg[0] * wy - mg[1] * wx;
  }
  if (have_acc) {
    for (i = 0; i < 3; ++i) {
      a->ei[i] += AHRS_KI * e[i] * dt;
      g[i] += kp * e[i] + a->ei[i];
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
    float v = a->q[i] * (float)PROTO_QUAT_ONE;
    if (v > 32767.0f) v = 32767.0f;
    if (v < -32767.0f) v = -32767.0f;
    out[i] = (int16_t)(v < 0.0f ? v - 0.5f : v + 0.5f);
  }
}
