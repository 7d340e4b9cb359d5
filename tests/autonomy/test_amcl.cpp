// AMCL with KLD sampling converges from a wrong start on the saved map.
#include <gtest/gtest.h>

#include <autodrive/autonomy/amcl.hpp>
#include "synthetic_world.hpp"

using namespace autodrive::autonomy;

namespace {

// Drives a loop in the lot; odometry drifts (scaled distance, biased yaw) like a real EKF.
struct Drive {
  Pose2 truth{0.8, 0.9, 0.2};
  Pose2 odom{0.0, 0.0, 0.0};
  void step(double ds_m, double k_1pm) {
    const Pose2 before = truth;
    truth = arc_step(truth, ds_m, k_1pm);
    Pose2 d = pose_between(before, truth);
    d.x_m *= 1.03;       // 3% odometry scale error
    d.yaw_rad += 0.002;  // gyro bias
    odom = pose_compose(odom, d);
  }
};

}  // namespace

TEST(Amcl, ConvergesFromAWrongStartAndAdaptsTheParticleCount) {
  const auto world = autodrive::synthetic_world::World::parking_lot();
  const GridMap map = world.rasterize(0.02);
  AmclConfig cfg;
  cfg.seed = 11;
  Amcl amcl(map, cfg);
  Drive d;
  // 0.3 m and 0.25 rad off, with a spread wide enough to contain the truth.
  amcl.init_gaussian({d.truth.x_m + 0.25, d.truth.y_m - 0.18, d.truth.yaw_rad + 0.25}, 0.25, 0.25,
                     0.3);
  const size_t n_start = amcl.particles().size();
  std::mt19937 rng(2);
  double err = 1e9;
  for (int i = 0; i < 80; ++i) {
    d.step(0.03, i < 40 ? 0.6 : -0.4);
    amcl.update(d.odom, world.scan(d.truth, cfg.lidar_in_base, 0.01, &rng));
    const Pose2 e = amcl.estimate();
    err = std::hypot(e.x_m - d.truth.x_m, e.y_m - d.truth.y_m);
  }
  const Pose2 e = amcl.estimate();
  EXPECT_LT(err, 0.03);
  EXPECT_NEAR(angle_wrap_rad(e.yaw_rad - d.truth.yaw_rad), 0.0, 0.03);
  EXPECT_EQ(n_start, static_cast<size_t>(cfg.max_particles));
  EXPECT_LT(amcl.particles().size(), n_start / 2);  // KLD shrank the set once converged
  EXPECT_GE(amcl.particles().size(), static_cast<size_t>(cfg.min_particles));
  EXPECT_LT(std::sqrt(amcl.covariance()(0, 0)), 0.05);
}

TEST(Amcl, DoesNotUpdateWithoutMotionUnlessForced) {
  const auto world = autodrive::synthetic_world::World::parking_lot();
  const GridMap map = world.rasterize(0.02);
  Amcl amcl(map, AmclConfig{});
  const Pose2 p{1.5, 1.0, 0.0};
  amcl.init_gaussian(p, 0.05, 0.05, 0.05);
  const auto scan = world.scan(p, AmclConfig{}.lidar_in_base);
  EXPECT_TRUE(amcl.update({0, 0, 0}, scan));  // the first one always runs
  EXPECT_FALSE(amcl.update({0.001, 0, 0}, scan));
  EXPECT_TRUE(amcl.update({0.001, 0, 0}, scan, true));
}

TEST(Amcl, LikelihoodPeaksAtTheTruePose) {
  const auto world = autodrive::synthetic_world::World::parking_lot();
  const GridMap map = world.rasterize(0.02);
  AmclConfig cfg;
  Amcl amcl(map, cfg);
  const Pose2 p{2.2, 1.4, 1.0};
  const auto pts = scan_points_base(world.scan(p, cfg.lidar_in_base), cfg.lidar_in_base);
  const double at = amcl.scan_log_likelihood(p, pts);
  EXPECT_GT(at, amcl.scan_log_likelihood({p.x_m + 0.05, p.y_m, p.yaw_rad}, pts));
  EXPECT_GT(at, amcl.scan_log_likelihood({p.x_m, p.y_m - 0.05, p.yaw_rad}, pts));
  EXPECT_GT(at, amcl.scan_log_likelihood({p.x_m, p.y_m, p.yaw_rad + 0.05}, pts));
}
