// Hector-style multi-resolution scan matching and SLAM on simulated scans.
#include <gtest/gtest.h>

#include <autodrive/autonomy/slam.hpp>
#include "synthetic_world.hpp"

using namespace autodrive::autonomy;

namespace {

SlamConfig lot_config() {
  SlamConfig c;
  c.resolution_m = 0.02;
  c.levels = 3;
  c.width_m = 5.0;
  c.height_m = 4.0;
  c.origin_x_m = -0.5;
  c.origin_y_m = -0.5;
  return c;
}

}  // namespace

TEST(ScanMatch, RecoversAKnownOffset) {
  const auto world = autodrive::synthetic_world::World::parking_lot();
  const SlamConfig cfg = lot_config();
  const Pose2 truth{1.5, 1.0, 0.3};
  HectorSlam slam(cfg, truth);
  for (int i = 0; i < 3; ++i) slam.update(world.scan(truth, cfg.lidar_in_base));
  // The car has moved: a scan from the moved pose, matched from the old pose as the guess.
  const Pose2 offsets[] = {{0.08, -0.05, 0.05}, {-0.1, 0.06, -0.08}, {0.04, 0.1, 0.1}};
  for (const auto &off : offsets) {
    const Pose2 moved = pose_compose(truth, off);
    const auto pts = scan_points_base(world.scan(moved, cfg.lidar_in_base), cfg.lidar_in_base);
    const Pose2 m = scan_match(slam.levels(), pts, truth, cfg.iterations_per_level);
    EXPECT_NEAR(m.x_m, moved.x_m, 0.01);
    EXPECT_NEAR(m.y_m, moved.y_m, 0.01);
    EXPECT_NEAR(angle_wrap_rad(m.yaw_rad - moved.yaw_rad), 0.0, 0.01);
  }
}

TEST(ScanMatch, CoarseLevelsWidenTheBasin) {
  const auto world = autodrive::synthetic_world::World::parking_lot();
  const SlamConfig cfg = lot_config();
  const Pose2 truth{1.5, 1.0, 0.3};
  HectorSlam slam(cfg, truth);
  for (int i = 0; i < 3; ++i) slam.update(world.scan(truth, cfg.lidar_in_base));
  const Pose2 moved = pose_compose(truth, {0.06, -0.045, 0.0});  // 7.5 cm
  const auto pts = scan_points_base(world.scan(moved, cfg.lidar_in_base), cfg.lidar_in_base);
  const Pose2 multi = scan_match(slam.levels(), pts, truth, cfg.iterations_per_level);
  const Pose2 fine = scan_match_level(slam.levels()[0], pts, truth, cfg.iterations_per_level);
  const double e_multi = std::hypot(multi.x_m - moved.x_m, multi.y_m - moved.y_m);
  const double e_fine = std::hypot(fine.x_m - moved.x_m, fine.y_m - moved.y_m);
  EXPECT_LT(e_multi, 0.01);
  EXPECT_GT(e_fine, e_multi);
}

TEST(Slam, TracksADriveWithoutOdometryAndBuildsTheMap) {
  const auto world = autodrive::synthetic_world::World::parking_lot();
  const SlamConfig cfg = lot_config();
  std::mt19937 rng(3);
  Pose2 truth{0.6, 0.8, 0.0};
  HectorSlam slam(cfg, truth);
  double max_err = 0;
  for (int i = 0; i < 60; ++i) {
    // Forward along an arc, 0.03 m per scan (0.2 m/s at 7 Hz).
    truth = arc_step(truth, 0.03, 0.8);
    const Pose2 est = slam.update(world.scan(truth, cfg.lidar_in_base, 0.005, &rng));
    max_err = std::max(max_err, std::hypot(est.x_m - truth.x_m, est.y_m - truth.y_m));
  }
  EXPECT_LT(max_err, 0.05);  // measured 0.039 m over 1.8 m of arc, no odometry
  EXPECT_NEAR(angle_wrap_rad(slam.pose().yaw_rad - truth.yaw_rad), 0.0, 0.03);
  // The walls the car saw are occupied in the map, the middle of the lot is free.
  const auto &m = slam.map();
  int cx, cy;
  // The wall at y = 3 m is in the map within the drift (3 cells) of its true place.
  bool wall = false;
  for (double y = 2.94; y <= 3.06; y += 0.02) {
    ASSERT_TRUE(m.world_to_cell(2.0, y, cx, cy));
    wall = wall || m.state(cx, cy) == CellState::kOccupied;
  }
  EXPECT_TRUE(wall);
  ASSERT_TRUE(m.world_to_cell(2.0, 1.5, cx, cy));
  EXPECT_EQ(m.state(cx, cy), CellState::kFree);
}
