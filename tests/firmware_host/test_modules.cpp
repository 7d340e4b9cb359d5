// The core's small modules on their own: quadrature decoder, wheel speed, AHRS, failsafe
// state machine edge cases, actuator mapping.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>

#include "actuation.h"
#include "ahrs.h"
#include "encoder.h"
#include "failsafe.h"
#include "protocol.h"
#include "wheel_speed.h"

namespace {

// Drives a quadrature pair: one A cycle = 4 phase steps, A leads B when forward.
struct Quad {
  int phase = 0;  // 0..3: (A,B) = 00, 10, 11, 01
  uint8_t a() const { return (phase == 1 || phase == 2) ? 1 : 0; }
  uint8_t b() const { return (phase == 2 || phase == 3) ? 1 : 0; }
  // Steps one phase; calls the decoder on A edges only (like the AVR ISR on INT0 CHANGE).
  void Step(encoder_t *e, int dir) {
    uint8_t a0 = a();
    phase = (phase + (dir > 0 ? 1 : 3)) % 4;
    if (a() != a0) encoder_edge_a(e, a(), b());
  }
};

TEST(Encoder, ForwardBackwardAndCountsPerRev) {
  encoder_t e;
  encoder_init(&e, 0);
  Quad q;
  // 1920 counts = 960 A cycles = 3840 phase steps
  for (int i = 0; i < 3840; ++i) q.Step(&e, +1);
  EXPECT_EQ(e.counts, ENCODER_COUNTS_PER_REV);
  for (int i = 0; i < 3840; ++i) q.Step(&e, -1);
  EXPECT_EQ(e.counts, 0);
  for (int i = 0; i < 10; ++i) q.Step(&e, -1);
  EXPECT_EQ(e.counts, -5);
}

TEST(Encoder, InvertedSideAndJitterCancels) {
  encoder_t e;
  encoder_init(&e, 1);
  Quad q;
  for (int i = 0; i < 400; ++i) q.Step(&e, +1);
  EXPECT_EQ(e.counts, -200);
  // a wheel rocking on an A edge: every + is undone by the matching -
  encoder_init(&e, 0);
  for (int i = 0; i < 100; ++i) {
    q.Step(&e, +1);
    q.Step(&e, -1);
  }
  EXPECT_EQ(e.counts, 0);
}

TEST(WheelSpeed, ConstantSpeedConverges) {
  wheel_speed_t w;
  wheel_speed_init(&w);
  int32_t c = 0;
  for (uint32_t t = 0; t <= 500000; t += 1000) {
    wheel_speed_update(&w, c, -c, t);
    c += 4;  // 4000 counts/s = 13.09 rad/s (about top speed)
  }
  EXPECT_NEAR(wheel_speed_mrad_s(&w, 0), 13090, 30);
  EXPECT_NEAR(wheel_speed_mrad_s(&w, 1), -13090, 30);
  // stops: decays to zero
  for (uint32_t t = 501000; t <= 1000000; t += 1000) wheel_speed_update(&w, c, -c, t);
  EXPECT_EQ(wheel_speed_mrad_s(&w, 0), 0);
  EXPECT_EQ(wheel_speed_mrad_s(&w, 1), 0);
}

TEST(WheelSpeed, SlowWheelIsNotLostToQuantisation) {
  wheel_speed_t w;
  wheel_speed_init(&w);
  int64_t c_milli = 0;
  for (uint32_t t = 0; t <= 2000000; t += 1000) {
    wheel_speed_update(&w, static_cast<int32_t>(c_milli / 1000), 0, t);
    c_milli += 150;  // 150 counts/s = 0.491 rad/s: 1.5 counts per window
  }
  EXPECT_NEAR(wheel_speed_mrad_s(&w, 0), 491, 120);
}

float Angle(const float a[4], const float b[4]) {
  float d = std::fabs(a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + a[3] * b[3]);
  return 2.0f * std::acos(std::fmin(1.0f, d));
}

TEST(Ahrs, LevelAndStillStaysIdentityWithUnitNorm) {
  ahrs_t a;
  ahrs_init(&a);
  const int16_t acc[3] = {0, 0, 8192}, gyr[3] = {0, 0, 0}, mag[3] = {200, 0, -300};
  for (uint32_t t = 0; t < 5000000; t += 10000) ahrs_update(&a, acc, gyr, mag, t);
  const float id[4] = {1, 0, 0, 0};
  EXPECT_LT(Angle(a.q, id), 0.01f);
  int16_t q14[4];
  ahrs_quat_q14(&a, q14);
  EXPECT_NEAR(q14[0], PROTOCOL_QUAT_ONE, 2);
}

TEST(Ahrs, ConvergesToRollFromGravity) {
  ahrs_t a;
  ahrs_init(&a);
  // rolled +20 deg about x: gravity ("up") seen in body axes is (0, sin, cos)
  const float r = 20.0f * 3.14159265f / 180.0f;
  const int16_t acc[3] = {0, static_cast<int16_t>(8192 * std::sin(r)),
                          static_cast<int16_t>(8192 * std::cos(r))};
  const int16_t gyr[3] = {0, 0, 0}, mag[3] = {0, 0, 0};
  for (uint32_t t = 0; t < 5000000; t += 10000) ahrs_update(&a, acc, gyr, mag, t);
  const float expect[4] = {std::cos(r / 2), std::sin(r / 2), 0, 0};
  EXPECT_LT(Angle(a.q, expect), 0.02f) << a.q[0] << " " << a.q[1] << " " << a.q[2] << " " << a.q[3];
}

TEST(Ahrs, YawFollowsGyroWithoutMagnetometer) {
  ahrs_t a;
  ahrs_init(&a);
  const int16_t acc[3] = {0, 0, 8192}, mag[3] = {0, 0, 0};
  const int16_t gyr[3] = {0, 0, static_cast<int16_t>(90 * PROTOCOL_GYRO_LSB_PER_DPS)};  // 90 deg/s
  for (uint32_t t = 0; t <= 1000000; t += 10000) ahrs_update(&a, acc, gyr, mag, t);
  // 1 s at 90 deg/s about z
  const float yaw = 2.0f * std::atan2(a.q[3], a.q[0]);
  EXPECT_NEAR(yaw * 180.0f / 3.14159265f, 90.0f, 2.0f);
}

TEST(Ahrs, HeadingFromMagnetometer) {
  ahrs_t a;
  ahrs_init(&a);
  // the car points 30 deg left of north: north is seen at -30 deg in body axes
  const float h = 30.0f * 3.14159265f / 180.0f;
  const int16_t acc[3] = {0, 0, 8192}, gyr[3] = {0, 0, 0};
  const int16_t mag[3] = {static_cast<int16_t>(200 * std::cos(h)),
                          static_cast<int16_t>(-200 * std::sin(h)), -300};
  for (uint32_t t = 0; t < 5000000; t += 10000) ahrs_update(&a, acc, gyr, mag, t);
  const float yaw = 2.0f * std::atan2(a.q[3], a.q[0]);
  EXPECT_NEAR(yaw * 180.0f / 3.14159265f, 30.0f, 1.0f);
}

TEST(Ahrs, GarbageInputNeverBreaksTheQuaternion) {
  ahrs_t a;
  ahrs_init(&a);
  const int16_t acc[3] = {32767, -32768, 32767}, gyr[3] = {32767, 32767, -32768},
                mag[3] = {-32768, 32767, 0};
  for (uint32_t t = 0; t < 1000000; t += 10000) ahrs_update(&a, acc, gyr, mag, t);
  float n2 = a.q[0] * a.q[0] + a.q[1] * a.q[1] + a.q[2] * a.q[2] + a.q[3] * a.q[3];
  EXPECT_NEAR(n2, 1.0f, 1e-3f);
  const int16_t zero[3] = {0, 0, 0};
  ahrs_update(&a, zero, zero, zero, 1010000);  // free fall / absent data: gyro only
  n2 = a.q[0] * a.q[0] + a.q[1] * a.q[1] + a.q[2] * a.q[2] + a.q[3] * a.q[3];
  EXPECT_NEAR(n2, 1.0f, 1e-3f);
}

TEST(Failsafe, StateMachineEdges) {
  failsafe_t f;
  failsafe_init(&f, 100);
  EXPECT_EQ(f.mode, PROTOCOL_MODE_DISARMED);
  EXPECT_FALSE(failsafe_may_drive(&f));
  EXPECT_EQ(failsafe_on_command(&f, 1, 0), 0);  // engaged without disengaged first
  EXPECT_EQ(f.mode, PROTOCOL_MODE_DISARMED);
  EXPECT_EQ(failsafe_on_command(&f, 0, 10000), 0);
  EXPECT_EQ(failsafe_on_command(&f, 1, 20000), 1);
  EXPECT_TRUE(failsafe_may_drive(&f));
  EXPECT_EQ(failsafe_on_command(&f, 1, 30000), 0);  // already engaged: not a new arming
  failsafe_update(&f, 129999);
  EXPECT_EQ(f.mode, PROTOCOL_MODE_ENGAGED);
  failsafe_update(&f, 130000);
  EXPECT_EQ(f.mode, PROTOCOL_MODE_FAILSAFE);
  EXPECT_EQ(f.link_lost, 1);
  failsafe_update(&f, 5000000);  // stays
  EXPECT_EQ(f.mode, PROTOCOL_MODE_FAILSAFE);
  EXPECT_EQ(failsafe_on_command(&f, 0, 5000000), 0);
  EXPECT_EQ(f.mode, PROTOCOL_MODE_FAILSAFE);
  EXPECT_EQ(failsafe_on_command(&f, 1, 5010000), 1);
  EXPECT_EQ(f.link_lost, 0);
  failsafe_set_timeout_ms(&f, 20);
  EXPECT_EQ(f.timeout_us, 20000u);
}

TEST(Actuation, DutyRoundingBrakeAndStop) {
  actuation_t a;
  actuation_init(&a, 0);
  EXPECT_EQ(a.brake, 1);
  uint32_t t = 0;
  for (int i = 0; i < 1000; ++i) actuation_update(&a, 500, 0, 0, t += 1000);
  EXPECT_EQ(a.duty, 128);  // 0.5 * 255 = 127.5 -> 128
  EXPECT_EQ(a.brake, 0);
  EXPECT_EQ(a.decelerating, 0);
  actuation_update(&a, 500, 0, 1, t += 1000);  // stop: immediate
  EXPECT_EQ(a.duty, 0);
  EXPECT_EQ(a.brake, 1);
  EXPECT_EQ(actuation_throttle_milli(&a), 0);
  // a long gap is clamped: at most 50 ms worth of slew (0.2) in one update
  actuation_update(&a, 1000, 0, 0, t += 1000000);
  EXPECT_EQ(actuation_throttle_milli(&a), 200);
}

}  // namespace
