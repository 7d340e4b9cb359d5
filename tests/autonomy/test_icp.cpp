// Laser odometry: scan-to-scan ICP recovers a known motion.
#include <gtest/gtest.h>

#include <autodrive/autonomy/icp.hpp>
#include "synthetic_world.hpp"

using namespace autodrive::autonomy;

TEST(Icp, RecoversKnownMotions) {
  const auto world = autodrive::synthetic_world::World::parking_lot();
  const Pose2 lidar{0, 0, 0};  // points in the LIDAR frame
  std::mt19937 rng(5);
  const Pose2 a{1.6, 1.1, 0.4};
  const Pose2 motions[] = {{0.05, 0.02, 0.05}, {-0.04, 0.0, -0.03}, {0.1, -0.03, 0.12}};
  for (const auto &mv : motions) {
    const Pose2 b = pose_compose(a, mv);
    const auto ref = scan_points_base(world.scan(a, lidar, 0.003, &rng), lidar);
    const auto cur = scan_points_base(world.scan(b, lidar, 0.003, &rng), lidar);
    const IcpResult r = icp_match(ref, cur, Pose2{});
    ASSERT_FALSE(r.failed);
    EXPECT_NEAR(r.motion.x_m, mv.x_m, 0.005);
    EXPECT_NEAR(r.motion.y_m, mv.y_m, 0.005);
    EXPECT_NEAR(r.motion.yaw_rad, mv.yaw_rad, 0.005);
    EXPECT_LT(r.rms_m, 0.01);
  }
}

TEST(Icp, ChainedOdometryStaysCloseOverADrive) {
  const auto world = autodrive::synthetic_world::World::parking_lot();
  const Pose2 lidar{0, 0, 0};
  std::mt19937 rng(7);
  Pose2 truth{0.8, 1.2, 0.0}, est = truth;
  auto prev = scan_points_base(world.scan(truth, lidar, 0.003, &rng), lidar);
  for (int i = 0; i < 30; ++i) {
    truth = arc_step(truth, 0.03, 1.0);
    const auto cur = scan_points_base(world.scan(truth, lidar, 0.003, &rng), lidar);
    const IcpResult r = icp_match(prev, cur, Pose2{});
    ASSERT_FALSE(r.failed);
    est = pose_compose(est, r.motion);
    prev = cur;
  }
  EXPECT_LT(std::hypot(est.x_m - truth.x_m, est.y_m - truth.y_m), 0.03);  // over 0.9 m
  EXPECT_NEAR(angle_wrap_rad(est.yaw_rad - truth.yaw_rad), 0.0, 0.03);
}

TEST(Icp, TooFewPointsIsAFailureNotACrash) {
  std::vector<Eigen::Vector2d> few{{1, 0}, {0, 1}};
  EXPECT_TRUE(icp_match(few, few, Pose2{}).failed);
}
