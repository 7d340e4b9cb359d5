// Pure pursuit on a kinematic bicycle (speed lag, Nigel's steering rate limit).
#include <gtest/gtest.h>

#include <autodrive/autonomy/pure_pursuit.hpp>
#include <autodrive/autonomy/reeds_shepp.hpp>
#include "synthetic_world.hpp"

using namespace autodrive::autonomy;

namespace {

Path straight(const Pose2 &from, double length_m, int dir) {
  Path p;
  Pose2 q = from;
  for (double s = 0; s <= length_m + 1e-9; s += 0.01) {
    p.push_back({q, dir, 0.0});
    q = arc_step(q, dir * 0.01, 0.0);
  }
  return p;
}

Path arc(const Pose2 &from, double length_m, double k, int dir) {
  Path p;
  Pose2 q = from;
  for (double s = 0; s <= length_m + 1e-9; s += 0.01) {
    p.push_back({q, dir, k});
    q = arc_step(q, dir * 0.01, k);
  }
  return p;
}

struct RunResult {
  double max_cross_track_m = 0;
  double final_pos_err_m = 0;
  double final_yaw_err_rad = 0;
  double max_abs_throttle = 0, max_abs_steering = 0;
  bool done = false;
  double sim_s = 0;
  int reverse_commands = 0;
};

// Runs the tracker at 50 Hz until done (or 60 s) from start; cross-track error is measured
// after `settle_m` of travel.
RunResult run(const Path &path, const Pose2 &start, double settle_m = 0.0) {
  PurePursuit pp;
  pp.set_path(path);
  autodrive::synthetic_world::Bicycle car;
  car.pose = start;
  RunResult r;
  const double dt = 0.02;
  double travelled = 0;
  for (int i = 0; i < 3000; ++i) {
    const TrackerCommand c = pp.step(car.pose, dt);
    r.max_abs_throttle = std::max(r.max_abs_throttle, std::abs(c.throttle));
    r.max_abs_steering = std::max(r.max_abs_steering, std::abs(c.steering));
    r.reverse_commands += c.throttle < 0;
    if (c.done) {
      r.done = true;
      break;
    }
    // Throttle -> speed through the documented linear map (1.0 = 0.267 m/s).
    const Pose2 before = car.pose;
    car.step(c.throttle * 0.267, c.steering * AUTODRIVE_VEHICLE_STEER_LIMIT_RAD, dt);
    travelled += std::hypot(car.pose.x_m - before.x_m, car.pose.y_m - before.y_m);
    if (travelled > settle_m)
      r.max_cross_track_m = std::max(
          r.max_cross_track_m,
          autodrive::synthetic_world::distance_to_path_m(path, {car.pose.x_m, car.pose.y_m}));
    r.sim_s += dt;
  }
  const Pose2 g = path.back().pose;
  r.final_pos_err_m = std::hypot(car.pose.x_m - g.x_m, car.pose.y_m - g.y_m);
  r.final_yaw_err_rad = std::abs(angle_wrap_rad(car.pose.yaw_rad - g.yaw_rad));
  return r;
}

}  // namespace

TEST(PurePursuit, FollowsAStraightLineFromAnOffsetAndStopsAtTheEnd) {
  const Path p = straight({0, 0, 0}, 1.5, 1);
  const RunResult r = run(p, {0.0, 0.05, 0.0}, 0.5);
  ASSERT_TRUE(r.done);
  EXPECT_LT(r.max_cross_track_m, 0.01);
  EXPECT_LT(r.final_pos_err_m, 0.02);
  EXPECT_LT(r.final_yaw_err_rad, 0.035);
  EXPECT_LE(r.max_abs_throttle, 1.0);
  EXPECT_LE(r.max_abs_steering, 1.0);
}

TEST(PurePursuit, FollowsACurveWithinABound) {
  Path p = arc({0, 0, 0}, 1.2, 1.0 / 0.5, 1);  // radius 0.5 m
  const Path tail = straight(p.back().pose, 0.4, 1);
  p.insert(p.end(), tail.begin() + 1, tail.end());
  const RunResult r = run(p, {0, 0, 0});
  ASSERT_TRUE(r.done);
  EXPECT_LT(r.max_cross_track_m, 0.02);
  EXPECT_LT(r.final_pos_err_m, 0.02);
  EXPECT_LT(r.final_yaw_err_rad, 0.035);
}

TEST(PurePursuit, FollowsATightCurveAtTheSteeringLimit) {
  const double k = std::tan(0.8 * AUTODRIVE_VEHICLE_STEER_LIMIT_RAD) /
                   AUTODRIVE_VEHICLE_WHEELBASE_M;  // the planner's tightest arc
  Path p = arc({0, 0, 0}, 0.8, k, 1);
  const Path tail = straight(p.back().pose, 0.3, 1);
  p.insert(p.end(), tail.begin() + 1, tail.end());
  const RunResult r = run(p, {0, 0, 0});
  ASSERT_TRUE(r.done);
  EXPECT_LT(r.max_cross_track_m, 0.03);
  EXPECT_LT(r.final_pos_err_m, 0.02);
}

TEST(PurePursuit, ReversesAlongACurve) {
  Path p = arc({0, 0, 0}, 0.6, -1.0 / 0.6, -1);
  const Path tail = straight(p.back().pose, 0.3, -1);
  p.insert(p.end(), tail.begin() + 1, tail.end());
  const RunResult r = run(p, {0, 0, 0});
  ASSERT_TRUE(r.done);
  EXPECT_GT(r.reverse_commands, 10);
  EXPECT_LT(r.max_cross_track_m, 0.02);
  EXPECT_LT(r.final_pos_err_m, 0.02);
  EXPECT_LT(r.final_yaw_err_rad, 0.035);
}

TEST(PurePursuit, DrivesAReedsSheppParkingManoeuvreWithCusps) {
  const double R =
      1.0 / (std::tan(0.8 * AUTODRIVE_VEHICLE_STEER_LIMIT_RAD) / AUTODRIVE_VEHICLE_WHEELBASE_M);
  const Pose2 start{0, 0, 0}, goal{0.3, -0.45, kPi / 2};
  const auto paths = rs_paths(start, goal, R);
  ASSERT_FALSE(paths.empty());
  const Path p = rs_sample(start, paths.front(), R, 0.01);
  ASSERT_GE(path_cusps(p), 1);
  const RunResult r = run(p, start);
  ASSERT_TRUE(r.done);
  EXPECT_LT(r.max_cross_track_m, 0.03);
  EXPECT_LT(r.final_pos_err_m, 0.02);
  EXPECT_LT(r.final_yaw_err_rad, 0.05);
}

TEST(PurePursuit, SpeedProfileSlowsToAStopAndRespectsTopSpeed) {
  const Path p = straight({0, 0, 0}, 1.5, 1);
  PurePursuit pp;
  pp.set_path(p);
  autodrive::synthetic_world::Bicycle car;
  double peak = 0;
  double last_speed_near_end = 1;
  for (int i = 0; i < 3000; ++i) {
    const TrackerCommand c = pp.step(car.pose, 0.02);
    if (c.done) break;
    peak = std::max(peak, c.speed_m_s);
    if (car.pose.x_m > 1.49) last_speed_near_end = std::min(last_speed_near_end, c.speed_m_s);
    EXPECT_NEAR(c.throttle, c.speed_m_s / 0.267, 1e-9);  // the documented linear map
    car.step(c.throttle * 0.267, c.steering * AUTODRIVE_VEHICLE_STEER_LIMIT_RAD, 0.02);
  }
  EXPECT_LE(peak, 0.267);
  EXPECT_GT(peak, 0.15);
  EXPECT_LT(last_speed_near_end, 0.05);
  EXPECT_TRUE(pp.done());
  EXPECT_EQ(pp.step(car.pose, 0.02).throttle, 0.0);  // clean stop: stays stopped
}

// A drivetrain that needs throttle 0.5 to move at all (friction, a sagging battery): open loop,
// the creep before the stop stalls the car short of the end; with the measured speed fed
// back, the stall boost gets it there.
TEST(PurePursuit, StallBoostGetsAStickyCarToTheEnd) {
  const Path p = straight({0, 0, 0}, 0.6, 1);
  auto drive = [&](bool feedback) {
    PurePursuit pp;
    pp.set_path(p);
    autodrive::synthetic_world::Bicycle car;
    double max_boost = 0;
    for (int i = 0; i < 3000; ++i) {  // 60 s at 50 Hz
      const TrackerCommand c = pp.step(car.pose, 0.02, feedback ? car.speed_m_s : std::nan(""));
      max_boost = std::max(max_boost, pp.boost());
      if (c.done) break;
      car.step(std::abs(c.throttle) < 0.5 ? 0.0 : c.throttle * 0.267,
               c.steering * AUTODRIVE_VEHICLE_STEER_LIMIT_RAD, 0.02);
    }
    return std::make_pair(pp.done(), std::make_pair(car.pose.x_m, max_boost));
  };
  const auto open_loop = drive(false);
  EXPECT_FALSE(open_loop.first) << "stalled short of the end, as expected open loop";
  EXPECT_LT(open_loop.second.first, 0.6 - 0.01);
  const auto closed = drive(true);
  ASSERT_TRUE(closed.first);
  EXPECT_NEAR(closed.second.first, 0.6, 0.02);
  EXPECT_GT(closed.second.second, 0.0);
}

// A car that keeps up never gets a boost (the boost must not change normal driving).
TEST(PurePursuit, NoBoostWhileTheCarKeepsUp) {
  const Path p = straight({0, 0, 0}, 0.8, 1);
  PurePursuit pp;
  pp.set_path(p);
  autodrive::synthetic_world::Bicycle car;
  for (int i = 0; i < 3000 && !pp.done(); ++i) {
    const TrackerCommand c = pp.step(car.pose, 0.02, car.speed_m_s);
    EXPECT_EQ(pp.boost(), 0.0) << "at step " << i;
    car.step(c.throttle * 0.267, c.steering * AUTODRIVE_VEHICLE_STEER_LIMIT_RAD, 0.02);
  }
  EXPECT_TRUE(pp.done());
}
