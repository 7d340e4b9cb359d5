// EKF on synthetic trajectories: straight line, circle, biased odometry corrected by Eye poses,
// late poses (replay), too-old poses, missing measurements, angle wrap.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include <autodrive/angles.hpp>

#include <autodrive/estimator/ekf.hpp>
#include <autodrive/estimator/estimator_node.hpp>

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
double run_loop(bool with_eye, double speed_scale, int64_t eye_delay_us,
                autodrive::estimator::EkfStats *stats) {
  autodrive::estimator::Ekf ekf;
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
  const autodrive::estimator::Estimate e = ekf.latest();
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
  autodrive::estimator::Ekf ekf;
  ekf.reset(0, 0, 0, 0, 1e-6, 1e-6);
  for (int k = 1; k <= 500; ++k) {
    ekf.add_wheel(k * 10000, 0.2, 0.0);
    ekf.add_gyro(k * 10000, 0.0);
  }
  const autodrive::estimator::Estimate e = ekf.latest();
  EXPECT_NEAR(e.x(0), 1.0, 0.01);  // 5 s at 0.2 m/s
  EXPECT_NEAR(e.x(1), 0.0, 1e-6);
  EXPECT_NEAR(e.x(3), 0.2, 1e-3);
}

TEST(Ekf, CircleMatchesAckermannGeometry) {
  autodrive::estimator::Ekf ekf;
  ekf.reset(0, 0, 0, 0, 1e-6, 1e-6);
  Truth t;
  const double v = 0.2, delta = 0.25;
  for (int k = 1; k <= 1000; ++k) {
    step(t, v, delta, 0.01);
    ekf.add_wheel(k * 10000, v, delta);
    ekf.add_gyro(k * 10000, v * std::tan(delta) / kL);
  }
  const autodrive::estimator::Estimate e = ekf.latest();
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
  autodrive::estimator::EkfStats late_stats;
  const double on_time = run_loop(true, 1.05, 0, nullptr);
  const double late = run_loop(true, 1.05, 150000, &late_stats);
  EXPECT_GT(late_stats.replays, 100u);
  EXPECT_EQ(late_stats.too_old, 0u);
  EXPECT_LT(late, 0.03);
  EXPECT_LT(std::fabs(late - on_time), 0.02);
}

TEST(Ekf, TooOldPoseDropped) {
  autodrive::estimator::EkfParams p;
  p.history_us = 200000;
  autodrive::estimator::Ekf ekf(p);
  ekf.reset(0, 0, 0, 0, 1e-6, 1e-6);
  for (int k = 1; k <= 100; ++k) ekf.add_wheel(k * 10000, 0.1, 0.0);
  ekf.add_pose(100000, 5.0, 5.0, 0.0, eye_cov(0.01, 0.01));  // 0.9 s late > 0.2 s history
  EXPECT_EQ(ekf.stats().too_old, 1u);
  EXPECT_NEAR(ekf.latest().x(1), 0.0, 1e-9);
}

TEST(Ekf, MissingMeasurementsGrowCovariance) {
  autodrive::estimator::Ekf ekf;
  ekf.reset(0, 0, 0, 0, 1e-6, 1e-6);
  ekf.add_wheel(10000, 0.2, 0.0);
  const autodrive::estimator::Estimate a = ekf.estimate_at(110000);
  const autodrive::estimator::Estimate b = ekf.estimate_at(1010000);
  EXPECT_GT(b.P(0, 0), a.P(0, 0));
  EXPECT_GT(b.x(0), a.x(0));  // keeps predicting with the last speed
}

TEST(Ekf, FirstPosePlacesUninitialisedFilter) {
  autodrive::estimator::Ekf ekf;  // no reset: the first Eye pose must place the car
  ekf.add_pose(0, 2.0, -1.0, 3.0, eye_cov(0.01, 0.02));
  EXPECT_NEAR(ekf.latest().x(0), 2.0, 1e-3);
  EXPECT_NEAR(ekf.latest().x(1), -1.0, 1e-3);
  EXPECT_NEAR(ekf.latest().x(2), 3.0, 1e-3);
}

TEST(Ekf, HeadingUpdateAcrossPi) {
  autodrive::estimator::Ekf ekf;
  ekf.reset(0, 0, 0, M_PI - 0.01, 1e-4, 0.01);
  ekf.add_pose(10000, 0, 0, -M_PI + 0.01, eye_cov(0.01, 0.01));
  // The innovation is +0.02 rad across the wrap, not -2 pi + 0.02.
  EXPECT_GT(std::fabs(ekf.latest().x(2)), M_PI - 0.011);
}

TEST(Ekf, NonFiniteRejected) {
  autodrive::estimator::Ekf ekf;
  ekf.reset(0, 0, 0, 0, 1e-6, 1e-6);
  ekf.add_wheel(10000, NAN, 0.0);
  EXPECT_EQ(ekf.stats().rejected, 1u);
  EXPECT_TRUE(ekf.latest().x.allFinite());
}

TEST(Ekf, WheelSpeedFromEncodersAcrossClockWrap) {
  double v = 0;
  // One wheel revolution on both wheels in 0.1 s, across the Nano's 32-bit clock wrap.
  ASSERT_TRUE(autodrive::estimator::wheel_speed_from_encoders(0, 0, 4294917296LL, 1920, 1920, 50000,
                                                              1920, 0.0325, &v));
  EXPECT_NEAR(v, 2 * M_PI * 0.0325 / 0.1, 1e-9);
  EXPECT_FALSE(
      autodrive::estimator::wheel_speed_from_encoders(0, 0, 5, 10, 10, 5, 1920, 0.0325, &v));
}

// ---- The pose gate (probe finding: one forged POSE_EYE stream moved the map pose 1,000 m) ----
namespace {
// A map filter as the estimator runs it: no reset, odometry from t = 0, the first Eye fix at
// `first_fix_s`, then honest Eye poses every 100 ms (when `eye_on(s)`), forged poses at 100 Hz
// at `forged_offset_m` from the truth (when `forged_on(s)`). Straight at 0.25 m/s for 30 s,
// odometry speed scaled by `speed_scale`. Returns the final position error [m].
template <class EyeOn, class ForgedOn>
double run_gate(EyeOn eye_on, ForgedOn forged_on, double forged_offset_m, double speed_scale,
                autodrive::estimator::EkfStats *stats, double duration_s = 30.0) {
  autodrive::estimator::Ekf ekf;
  std::mt19937 rng(3);
  std::normal_distribution<double> noise(0.0, 0.005);
  Truth t;
  t.x = 2.0;
  t.y = -1.0;
  t.yaw = 0.5;
  const int steps = static_cast<int>(duration_s * 100);
  for (int k = 1; k <= steps; ++k) {
    const double s = k * 0.01;
    const double delta = 0.15 * std::sin(0.3 * s);
    step(t, 0.25, delta, 0.01);
    const int64_t t_us = k * 10000;
    ekf.add_wheel(t_us, 0.25 * speed_scale, delta);
    ekf.add_gyro(t_us, 0.25 * std::tan(delta) / kL);
    if (k % 10 == 0 && eye_on(s))
      ekf.add_pose(t_us, t.x + noise(rng), t.y + noise(rng), t.yaw + 0.5 * noise(rng),
                   eye_cov(0.01, 0.02));
    if (forged_on(s))
      ekf.add_pose(t_us + 1, t.x + forged_offset_m, t.y, t.yaw, eye_cov(0.01, 0.02));
  }
  if (stats) *stats = ekf.stats();
  return std::hypot(ekf.latest().x(0) - t.x, ekf.latest().x(1) - t.y);
}
const auto always = [](double) { return true; };
const auto never = [](double) { return false; };
}  // namespace

TEST(EkfGate, HonestEyeIsNeverRejectedAndTheFirstFixPlacesTheCar) {
  autodrive::estimator::EkfStats st;
  // The car starts 2.2 m from the filter's origin: the first fix must pass the gate.
  EXPECT_LT(run_gate(always, never, 0.0, 1.1, &st), 0.02);
  EXPECT_EQ(st.gated, 0u);
  EXPECT_EQ(st.reacquired, 0u);
  EXPECT_EQ(st.fused, 3000u * 2 + 300u);
}

TEST(EkfGate, ForgedPoseStreamIsRejectedAndCounted) {
  for (double offset_m : {1000.0, 10.0, 1.0, 0.3}) {
    autodrive::estimator::EkfStats st;
    // Honest Eye all along; from 5 s on, a forged stream at 100 Hz (10x the Eye's rate).
    const double err = run_gate(
        always, [](double s) { return s > 5.0; }, offset_m, 1.0, &st);
    EXPECT_LT(err, 0.05) << "offset " << offset_m;
    EXPECT_GE(st.gated, 2400u) << "offset " << offset_m;
    EXPECT_EQ(st.reacquired, 0u) << "offset " << offset_m;
  }
}

TEST(EkfGate, ReacquiresTheRealEyeAfterALongGap) {
  autodrive::estimator::EkfStats st;
  // Eye lost from 3 s to 23 s while the odometry over-reads by 20 %: ~1 m of drift, far
  // outside the gate when the Eye comes back; a steady run of poses re-places the car.
  const double err = run_gate([](double s) { return s < 3.0 || s > 23.0; }, never, 0.0, 1.2, &st);
  EXPECT_LT(err, 0.05);
  EXPECT_EQ(st.reacquired, 1u);
}

TEST(EkfGate, AForgedPoseHeldStillWhileTheCarDrivesNeverReplacesIt) {
  autodrive::estimator::EkfStats st;
  // No real Eye after 3 s (the worst case): a forged stream 1 m off, not moving with the car.
  autodrive::estimator::Ekf ekf;
  Truth t;
  for (int k = 1; k <= 3000; ++k) {
    step(t, 0.25, 0.0, 0.01);
    const int64_t t_us = k * 10000;
    ekf.add_wheel(t_us, 0.25, 0.0);
    ekf.add_gyro(t_us, 0.0);
    if (k % 10 == 0 && k < 300) ekf.add_pose(t_us, t.x, t.y, t.yaw, eye_cov(0.01, 0.02));
    if (k >= 300) ekf.add_pose(t_us, 5.0, 1.0, 0.0, eye_cov(0.01, 0.02));
  }
  st = ekf.stats();
  EXPECT_EQ(st.reacquired, 0u);
  EXPECT_GE(st.gated, 2600u);
  EXPECT_LT(std::hypot(ekf.latest().x(0) - t.x, ekf.latest().x(1) - t.y), 0.1);
}

TEST(EkfGate, DistanceIsMahalanobis) {
  autodrive::estimator::Ekf ekf;
  ekf.reset(0, 0, 0, 0, 0.01 * 0.01, 1e-4);
  const Eigen::Matrix3d r = eye_cov(0.01, 0.01);
  // S = diag(2e-4, 2e-4, 2e-4): 0.02 m in x is 2 sigma -> d2 = 2.
  EXPECT_NEAR(ekf.pose_distance2(0, 0.02, 0, 0, r), 2.0, 1e-9);
}
