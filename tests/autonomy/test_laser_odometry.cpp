// Laser odometry (lo_): keyframed ICP with the odometry as guess and fallback.
#include <gtest/gtest.h>

#include <cmath>

#include <autodrive/autonomy/laser_odometry.hpp>
#include "synthetic_world.hpp"

using namespace autodrive::autonomy;

namespace {
const Pose2 kLidar{AUTODRIVE_VEHICLE_LIDAR_POS_M_X, 0.0, 0.0};

LaserOdomConfig lo_config() {
  LaserOdomConfig c;
  c.lidar_in_base = kLidar;
  return c;
}

Pose2 scaled(const Pose2 &m, double k) {
  return {m.x_m * k, m.y_m * k, m.yaw_rad * k};
}
}  // namespace

// Wheel odometry 10 % long (a worn tyre, a wrong wheel radius): the laser odometry follows the
// true motion, not the guess, over a 1.2 m S-curve.
TEST(LaserOdometry, FollowsTheTruthWhenTheOdometryIsScaled) {
  const auto world = autodrive::synthetic_world::World::parking_lot();
  std::mt19937 rng(11);
  LaserOdometry lo(lo_config());
  const Pose2 start{0.8, 1.2, 0.0};
  Pose2 truth = start, wheel;
  lo.update(world.scan(truth, kLidar, 0.003, &rng), Pose2{});
  for (int i = 0; i < 40; ++i) {
    const Pose2 next = arc_step(truth, 0.03, i < 20 ? 1.2 : -1.2);  // 3 cm per scan
    const Pose2 motion = pose_between(truth, next);
    truth = next;
    wheel = pose_compose(wheel, scaled(motion, 1.1));
    lo.update(world.scan(truth, kLidar, 0.003, &rng), scaled(motion, 1.1));
  }
  const Pose2 want = pose_between(start, truth);
  const Pose2 err = pose_between(want, lo.pose());
  const Pose2 werr = pose_between(want, wheel);
  EXPECT_LT(std::hypot(err.x_m, err.y_m), 0.02);  // measured 0.57 cm
  EXPECT_LT(std::abs(err.yaw_rad), 0.02);
  EXPECT_GT(std::hypot(werr.x_m, werr.y_m), 0.08);  // the guess alone: 12 cm
  EXPECT_EQ(lo.rejected(), 0);
}

// 100 noisy scans standing still: registered on one keyframe, the noise does not add up.
TEST(LaserOdometry, StandingStillDoesNotDrift) {
  const auto world = autodrive::synthetic_world::World::parking_lot();
  std::mt19937 rng(3);
  LaserOdometry lo(lo_config());
  const Pose2 p{1.5, 1.0, 0.3};
  for (int i = 0; i < 100; ++i) lo.update(world.scan(p, kLidar, 0.005, &rng), Pose2{});
  EXPECT_LT(std::hypot(lo.pose().x_m, lo.pose().y_m), 0.003);
  EXPECT_LT(std::abs(lo.pose().yaw_rad), 0.003);
}

// A scan with no returns (a blinded LIDAR) cannot be registered: the odometry is used, counted.
TEST(LaserOdometry, FallsBackToTheOdometryWhenIcpCannotWork) {
  const auto world = autodrive::synthetic_world::World::parking_lot();
  LaserOdometry lo(lo_config());
  const Pose2 p{1.5, 1.0, 0.0};
  lo.update(world.scan(p, kLidar), Pose2{});
  Scan blind = world.scan(p, kLidar);
  for (auto &r : blind.ranges_m) r = 0.0f;
  const Pose2 guess{0.02, 0.0, 0.01};
  const LaserOdomStep s = lo.update(blind, guess);
  EXPECT_FALSE(s.from_icp);
  EXPECT_EQ(lo.rejected(), 1);
  EXPECT_NEAR(lo.pose().x_m, 0.02, 1e-9);
  EXPECT_NEAR(lo.pose().yaw_rad, 0.01, 1e-9);
  // Registration resumes on the next good scan, against the old keyframe.
  const LaserOdomStep s2 =
      lo.update(world.scan(pose_compose(p, Pose2{0.03, 0, 0}), kLidar), Pose2{0.01, 0, 0});
  EXPECT_TRUE(s2.from_icp);
  EXPECT_NEAR(lo.pose().x_m, 0.03, 0.003);
}
