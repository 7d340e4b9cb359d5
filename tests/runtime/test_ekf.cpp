// EKF on synthetic trajectories: straight line, circle, biased odometry corrected by Eye poses,
// late poses (replay), too-old poses, missing measurements, angle wrap.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include <autodrive/angles.hpp>

#include "estimator/ekf.hpp"
#include "estimator/estimator_node.hpp"

namespace {
constexpr double kL = AUTODRIVE_VEHICLE_WHEELBASE_M;  // wheelbase [m]

struct Truth {
  double x = 0, y = 0, yaw = 0;
};

// Drives a bicycle model at speed v [m/s] and steering delta [rad] for dt [s].
void step(Truth &t, double v, double delta, double dt) {
  const double w = v * std::tan(delta) / kL;
  t.yaw = autodrive::angle_wrap_rad(t.yaw + w * dt);
  t.x += v * std::cos(t.yaw) * dt;
  t.y += v * std::sin(t.yaw) * dt;
}

Eigen::Matrix3d eye_cov(double pos_std, double yaw_std) {
  Eigen::Matrix3d c = Eigen::Matrix3d::Zero();
  c(0, 0) = c(1, 1) = pos_std * pos_std;
  c(2, 2) = yaw_std * yaw_std;
  return c;
}

// Runs a 30 s loop (straight, left arc, right arc) with odometry speed scaled by
// `speed_scale` and a gyro bias; Eye poses every 100 ms delayed by `eye_delay_us` if
// `with_eye`. Returns the final position error [m].
double run_loop(bool with_eye, double speed_scale, int64_t eye_delay_us, est::EkfStats *stats) {
  est::Ekf ekf;
  ekf.reset(0, 0, 0, 0, 1e-6, 1e-6);
  std::mt19937 rng(7);
  std::normal_distribution<double> eye_noise(0.0, 0.005), gyro_noise(0.0, 0.01);
  Truth t;
  std::vector<std::pair<int64_t, Truth>> pending;  // Eye poses in flight
  const double dt = 0.01;
  for (int k = 1; k <= 3000; ++k) {
    const double s = k * dt;
    const double delta = s < 10 ? 0.0 : (s < 20 ? 0.3 : -0.2);
    const double v = 0.25;
    step(t, v, delta, dt);
    const int64_t t_us = k * 10000;
    ekf.add_wheel(t_us, v * speed_scale, delta);
    ekf.add_gyro(t_us, v * std::tan(delta) / kL + 0.01 + gyro_noise(rng));
    if (with_eye && k % 10 == 0) pending.push_back({t_us, t});
    while (!pending.empty() && pending.front().first + eye_delay_us <= t_us) {
      const Truth &p = pending.front().second;
      ekf.add_pose(pending.front().first, p.x + eye_noise(rng), p.y + eye_noise(rng),
                   p.yaw + 0.5 * eye_noise(rng), eye_cov(0.01, 0.02));
      pending.erase(pending.begin());
    }
  }
  if (stats) *stats = ekf.stats();
  const est::Estimate e = ekf.latest();
  return std::hypot(e.x(0) - t.x, e.x(1) - t.y);
}
}  // namespace

TEST(Ekf, WrapAngle) {
  EXPECT_NEAR(autodrive::angle_wrap_rad(3 * M_PI / 2), -M_PI / 2, 1e-12);
  EXPECT_NEAR(autodrive::angle_wrap_rad(-3 * M_PI / 2), M_PI / 2, 1e-12);
  EXPECT_NEAR(autodrive::angle_wrap_rad(M_PI), M_PI, 1e-12);
  EXPECT_NEAR(autodrive::angle_wrap_rad(0.1), 0.1, 1e-12);
}

TEST(Ekf, StraightLineFromOdometry) {
  est::Ekf ekf;
  ekf.reset(0, 0, 0, 0, 1e-6, 1e-6);
  for (int k = 1; k <= 500; ++k) {
    ekf.add_wheel(k * 10000, 0.2, 0.0);
    ekf.add_gyro(k * 10000, 0.0);
  }
  const est::Estimate e = ekf.latest();
  EXPECT_NEAR(e.x(0), 1.0, 0.01);  // 5 s at 0.2 m/s
  EXPECT_NEAR(e.x(1), 0.0, 1e-6);
  EXPECT_NEAR(e.x(3), 0.2, 1e-3);
}

TEST(Ekf, CircleMatchesAckermannGeometry) {
  est::Ekf ekf;
  ekf.reset(0, 0, 0, 0, 1e-6, 1e-6);
  Truth t;
  const double v = 0.2, delta = 0.25;
  for (int k = 1; k <= 1000; ++k) {
    step(t, v, delta, 0.01);
    ekf.add_wheel(k * 10000, v, delta);
    ekf.add_gyro(k * 10000, v * std::tan(delta) / kL);
  }
  const est::Estimate e = ekf.latest();
  EXPECT_NEAR(e.x(0), t.x, 0.01);
  EXPECT_NEAR(e.x(1), t.y, 0.01);
  EXPECT_NEAR(autodrive::angle_wrap_rad(e.x(2) - t.yaw), 0.0, 0.01);
  EXPECT_NEAR(e.x(4), v * std::tan(delta) / kL, 1e-3);
}

TEST(Ekf, EyePosesBoundBiasedOdometryDrift) {
  const double drift = run_loop(false, 1.05, 0, nullptr);
  const double fused = run_loop(true, 1.05, 0, nullptr);
  EXPECT_GT(drift, 0.2);  // 5 % speed error and a gyro bias over 7.5 m
  EXPECT_LT(fused, 0.03);
}

TEST(Ekf, LatePosesAreReplayed) {
  est::EkfStats late_stats;
  const double on_time = run_loop(true, 1.05, 0, nullptr);
  const double late = run_loop(true, 1.05, 150000, &late_stats);
  EXPECT_GT(late_stats.replays, 100u);
  EXPECT_EQ(late_stats.too_old, 0u);
  EXPECT_LT(late, 0.03);
  EXPECT_LT(std::fabs(late - on_time), 0.02);
}

TEST(Ekf, TooOldPoseDropped) {
  est::EkfParams p;
  p.history_us = 200000;
  est::Ekf ekf(p);
  ekf.reset(0, 0, 0, 0, 1e-6, 1e-6);
  for (int k = 1; k <= 100; ++k) ekf.add_wheel(k * 10000, 0.1, 0.0);
  ekf.add_pose(100000, 5.0, 5.0, 0.0, eye_cov(0.01, 0.01));  // 0.9 s late > 0.2 s history
  EXPECT_EQ(ekf.stats().too_old, 1u);
  EXPECT_NEAR(ekf.latest().x(1), 0.0, 1e-9);
}

TEST(Ekf, MissingMeasurementsGrowCovariance) {
  est::Ekf ekf;
  ekf.reset(0, 0, 0, 0, 1e-6, 1e-6);
  ekf.add_wheel(10000, 0.2, 0.0);
  const est::Estimate a = ekf.estimate_at(110000);
  const est::Estimate b = ekf.estimate_at(1010000);
  EXPECT_GT(b.P(0, 0), a.P(0, 0));
  EXPECT_GT(b.x(0), a.x(0));  // keeps predicting with the last speed
}

TEST(Ekf, FirstPosePlacesUninitialisedFilter) {
  est::Ekf ekf;  // no reset: the first Eye pose must place the car
  ekf.add_pose(0, 2.0, -1.0, 3.0, eye_cov(0.01, 0.02));
  EXPECT_NEAR(ekf.latest().x(0), 2.0, 1e-3);
  EXPECT_NEAR(ekf.latest().x(1), -1.0, 1e-3);
  EXPECT_NEAR(ekf.latest().x(2), 3.0, 1e-3);
}

TEST(Ekf, HeadingUpdateAcrossPi) {
  est::Ekf ekf;
  ekf.reset(0, 0, 0, M_PI - 0.01, 1e-4, 0.01);
  ekf.add_pose(10000, 0, 0, -M_PI + 0.01, eye_cov(0.01, 0.01));
  // The innovation is +0.02 rad across the wrap, not -2 pi + 0.02.
  EXPECT_GT(std::fabs(ekf.latest().x(2)), M_PI - 0.011);
}

TEST(Ekf, NonFiniteRejected) {
  est::Ekf ekf;
  ekf.reset(0, 0, 0, 0, 1e-6, 1e-6);
  ekf.add_wheel(10000, NAN, 0.0);
  EXPECT_EQ(ekf.stats().rejected, 1u);
  EXPECT_TRUE(ekf.latest().x.allFinite());
}

TEST(Ekf, WheelSpeedFromEncodersAcrossClockWrap) {
  double v = 0;
  // One wheel revolution on both wheels in 0.1 s, across the Nano's 32-bit clock wrap.
  ASSERT_TRUE(
      est::wheel_speed_from_encoders(0, 0, 4294917296LL, 1920, 1920, 50000, 1920, 0.0325, &v));
  EXPECT_NEAR(v, 2 * M_PI * 0.0325 / 0.1, 1e-9);
  EXPECT_FALSE(est::wheel_speed_from_encoders(0, 0, 5, 10, 10, 5, 1920, 0.0325, &v));
}
