// The whole mission in closed loop on the synthetic lot: AutonomyNode maps with Hector SLAM,
// saves and reloads the map, localises with AMCL on drifting odometry, plans with Hybrid A*,
// drives with pure pursuit on a kinematic bicycle, replans around an unmapped box, parks; and
// maps along a route while driving.
#include <filesystem>

#include <gtest/gtest.h>

#include <autodrive/autonomy/autonomy_node.hpp>
#include "synthetic_world.hpp"

using namespace autodrive::autonomy;
namespace fs = std::filesystem;

namespace {

struct Outcome {
  MissionState state = MissionState::kFailed;
  std::string history;
  double pos_err_m = 1e9, yaw_err_rad = 1e9;
  double min_clearance_m = 1e9;  // true footprint vs the true world (incl. the new box)
  int plans = 0;
  double sim_s = 0;
  double mapped_pose_err_m = -1;  // SLAM pose vs truth when the map was saved
  int laser_odom_scans = 0, laser_odom_rejected = 0;
  Path retry_path;              // the first plan made after a stop off the goal
  double max_progress[7] = {};  // per MissionState
  bool progress_in_range = true;
};

// Distance from the true car body (rectangle) to the nearest wall point [m]; 0 = touching.
double body_clearance_m(const autodrive::synthetic_world::World &w, const Pose2 &base,
                        const Footprint &fp) {
  const double c = std::cos(base.yaw_rad), s = std::sin(base.yaw_rad);
  double best = 1e9;
  for (const auto &seg : w.walls) {
    const Eigen::Vector2d e = seg.b - seg.a;
    const int n = std::max(1, static_cast<int>(e.norm() / 0.005));
    for (int i = 0; i <= n; ++i) {
      const Eigen::Vector2d q = seg.a + e * (static_cast<double>(i) / n);
      const double dx = q.x() - base.x_m, dy = q.y() - base.y_m;
      const double lx = std::abs(c * dx + s * dy - fp.center_ahead_m) - 0.5 * fp.length_m;
      const double ly = std::abs(-s * dx + c * dy) - 0.5 * fp.width_m;
      best = std::min(best, std::hypot(std::max(lx, 0.0), std::max(ly, 0.0)));
    }
  }
  return best;
}

Outcome run_mission(bool add_box, const std::string &tag, const std::vector<Pose2> &route = {},
                    double yaw_tolerance_rad = -1.0, double retry_backoff_m = 0.0) {
  autodrive::synthetic_world::World world = autodrive::synthetic_world::World::parking_lot();
  const Pose2 lidar{AUTODRIVE_VEHICLE_LIDAR_POS_M_X, 0.0, 0.0};
  NodeConfig cfg;
  const fs::path dir = fs::temp_directory_path() /
                       ("autonomy_closed_loop_" + tag + "_" + std::to_string(::getpid()));
  cfg.map_yaml_out = (dir / "map.yaml").string();
  cfg.slam.width_m = 5.0;
  cfg.slam.height_m = 4.0;
  cfg.slam.origin_x_m = -0.5;
  cfg.slam.origin_y_m = -0.5;
  cfg.start_pose = {1.8, 1.2, 0.0};
  cfg.goal = {2.45, 0.18, kPi / 2};
  cfg.mapping_scans = 10;
  cfg.amcl.max_particles = 2000;
  cfg.mapping_route = route;
  if (yaw_tolerance_rad >= 0) cfg.goal_tolerance_yaw_rad = yaw_tolerance_rad;
  cfg.retry_backoff_m = retry_backoff_m;
  AutonomyNode node(cfg);

  autodrive::synthetic_world::Bicycle car;
  car.pose = cfg.start_pose;
  Pose2 odom{0, 0, 0};
  std::mt19937 rng(9);
  Outcome out;
  const double dt = 0.01;
  int64_t t_us = 0;
  bool box_added = false;
  for (int i = 0; i < 20000 && !node.mission().finished(); ++i, t_us += 10000) {
    node.on_odom(odom, t_us);
    if (i % 14 == 0) {
      const bool mapping = node.mission().state() == MissionState::kMapping;
      node.on_scan(world.scan(car.pose, lidar, 0.005, &rng), t_us);
      if (mapping && node.mission().state() != MissionState::kMapping) {
        const Pose2 e = pose_between(car.pose, node.pose_map());
        out.mapped_pose_err_m = std::hypot(e.x_m, e.y_m);
      }
    }
    // Once the first path exists, drop a 10 cm box on it, 0.45 m from the car.
    if (add_box && !box_added && node.path().size() > 50) {
      for (const auto &q : node.path()) {
        if (std::hypot(q.pose.x_m - car.pose.x_m, q.pose.y_m - car.pose.y_m) >= 0.45) {
          world.add_box(q.pose.x_m - 0.05, q.pose.y_m - 0.05, q.pose.x_m + 0.05, q.pose.y_m + 0.05);
          break;
        }
      }
      box_added = true;
    }
    if (out.retry_path.empty() && node.mission().detail().find("staging") != std::string::npos)
      out.retry_path = node.path();
    const double pr = node.progress();
    out.progress_in_range = out.progress_in_range && pr >= 0.0 && pr <= 1.0;
    double &mp = out.max_progress[static_cast<int>(node.mission().state())];
    mp = std::max(mp, pr);
    const TrackerCommand &c = node.command();
    const Pose2 before = car.pose;
    car.step(c.throttle * 0.267, c.steering * AUTODRIVE_VEHICLE_STEER_LIMIT_RAD, dt);
    Pose2 d = pose_between(before, car.pose);
    d.x_m *= 1.02;      // wheel odometry scale error
    d.yaw_rad += 1e-5;  // gyro bias, 1 mrad/s
    odom = pose_compose(odom, d);
    if (i % 5 == 0)
      out.min_clearance_m =
          std::min(out.min_clearance_m, body_clearance_m(world, car.pose, cfg.footprint));
    out.sim_s = t_us * 1e-6;
  }
  out.state = node.mission().state();
  for (const auto &h : node.mission().history()) out.history += h + "\n";
  const Pose2 e = pose_between(cfg.goal, car.pose);
  out.pos_err_m = std::hypot(e.x_m, e.y_m);
  out.yaw_err_rad = std::abs(e.yaw_rad);
  out.plans = node.plans();
  out.laser_odom_scans = node.laser_odometry().scans();
  out.laser_odom_rejected = node.laser_odometry().rejected();
  fs::remove_all(dir);
  return out;
}

}  // namespace

TEST(ClosedLoop, MapsLocalisesPlansDrivesAndParks) {
  const Outcome o = run_mission(false, "plain");
  ASSERT_EQ(o.state, MissionState::kParked) << o.history;
  EXPECT_LT(o.pos_err_m, 0.03) << o.history;
  EXPECT_LT(o.yaw_err_rad, 3.0 * kPi / 180) << o.history;
  EXPECT_GT(o.min_clearance_m, 0.0) << "collision";
}

TEST(ClosedLoop, ReplansAroundAnUnmappedBoxAndStillParks) {
  const Outcome o = run_mission(true, "box");
  ASSERT_EQ(o.state, MissionState::kParked) << o.history;
  EXPECT_GE(o.plans, 2) << o.history;
  EXPECT_NE(o.history.find("unmapped obstacle"), std::string::npos) << o.history;
  EXPECT_LT(o.pos_err_m, 0.03) << o.history;
  EXPECT_GT(o.min_clearance_m, 0.0) << "collision";
}

// Mapping while driving: 0.5 m back and forth along the lot before parking. SLAM matches each
// moving scan from the laser odometry's guess; the map it saves is good enough to park on.
TEST(ClosedLoop, MapsAlongARouteThenParks) {
  const Outcome o = run_mission(false, "route", {{1.3, 1.2, 0.0}, {1.8, 1.35, 0.0}});
  ASSERT_EQ(o.state, MissionState::kParked) << o.history;
  EXPECT_NE(o.history.find("route leg 1/2"), std::string::npos) << o.history;
  EXPECT_NE(o.history.find("route leg 2/2"), std::string::npos) << o.history;
  EXPECT_GE(o.mapped_pose_err_m, 0.0);
  EXPECT_LT(o.mapped_pose_err_m, 0.02)
      << "SLAM pose off the truth at the end of the route";  // 0.5 cm
  EXPECT_GT(o.laser_odom_scans, 50);
  EXPECT_LT(o.laser_odom_rejected, o.laser_odom_scans / 10) << "ICP rejected too often";
  // mission_status_t.progress: through the route while mapping, along the path while driving.
  EXPECT_TRUE(o.progress_in_range);
  EXPECT_GT(o.max_progress[static_cast<int>(MissionState::kMapping)], 0.9);
  EXPECT_GT(o.max_progress[static_cast<int>(MissionState::kDriving)], 0.9);
  EXPECT_EQ(o.max_progress[static_cast<int>(MissionState::kParked)], 1.0);
  EXPECT_LT(o.pos_err_m, 0.03) << o.history;
  EXPECT_GT(o.min_clearance_m, 0.0) << "collision";
}

// A stop off the goal (here: any stop, with a 0.01 deg heading tolerance) is retried through a
// staging pose 0.2 m back along the approach, so the car runs the last 0.2 m straight in.
TEST(ClosedLoop, ARetryBacksOffToAStagingPoseAndRunsStraightIn) {
  const Outcome o = run_mission(false, "retry", {}, 0.0002, 0.2);
  EXPECT_NE(o.history.find("retry: stopped"), std::string::npos) << o.history;
  ASSERT_FALSE(o.retry_path.empty()) << o.history;
  const Pose2 goal{2.45, 0.18, kPi / 2};
  // The car reverses into this slot (nose out): the staging pose is 0.2 m ahead of the goal.
  const int dir = o.retry_path.back().direction;
  EXPECT_EQ(dir, -1);
  const Pose2 staging = pose_compose(goal, Pose2{-dir * 0.2, 0.0, 0.0});
  double to_staging = 1e9;
  for (const auto &q : o.retry_path)
    to_staging =
        std::min(to_staging, std::hypot(q.pose.x_m - staging.x_m, q.pose.y_m - staging.y_m));
  EXPECT_LT(to_staging, 1e-3) << "the retry does not pass the staging pose";
  EXPECT_GE(path_cusps(o.retry_path), 1);
  EXPECT_NEAR(o.retry_path.back().pose.x_m, goal.x_m, 1e-6);
  EXPECT_NEAR(o.retry_path.back().pose.y_m, goal.y_m, 1e-6);
  EXPECT_GT(o.min_clearance_m, 0.0) << "collision";
}
