// Planning for a car-like vehicle: Reeds-Shepp, grid A*, Hybrid A* into a parking slot.
#include <gtest/gtest.h>

#include <autodrive/autonomy/grid_search.hpp>
#include <autodrive/autonomy/hybrid_astar.hpp>
#include <autodrive/autonomy/reeds_shepp.hpp>
#include "synthetic_world.hpp"

using namespace autodrive::autonomy;

namespace {

const double kMaxCurvature = std::tan(AUTODRIVE_VEHICLE_STEER_LIMIT_RAD) /
                             AUTODRIVE_VEHICLE_WHEELBASE_M;  // Nigel's steering limit [1/m]

// Checks every sample's curvature and, numerically, the curvature traced between samples.
void expect_feasible(const Path &path) {
  ASSERT_GE(path.size(), 2u);
  for (size_t i = 0; i < path.size(); ++i) {
    ASSERT_LE(std::abs(path[i].curvature_1pm), kMaxCurvature + 1e-9) << "sample " << i;
    if (i + 1 < path.size()) {
      // Heading change over distance between consecutive samples of one direction.
      const double ds = std::hypot(path[i + 1].pose.x_m - path[i].pose.x_m,
                                   path[i + 1].pose.y_m - path[i].pose.y_m);
      if (ds > 1e-4) {
        const double k =
            std::abs(angle_wrap_rad(path[i + 1].pose.yaw_rad - path[i].pose.yaw_rad)) / ds;
        ASSERT_LE(k, kMaxCurvature * 1.01) << "traced curvature at sample " << i;
        ASSERT_LT(ds, 0.03) << "gap in the path at sample " << i;
      }
    }
  }
}

Footprint nigel() {
  return Footprint{};
}

}  // namespace

TEST(ReedsShepp, SolvesRandomQueriesExactlyWithinTheTurningRadius) {
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> xy(-2.0, 2.0), yaw(-kPi, kPi);
  const double R = 0.3;
  int solved = 0;
  for (int i = 0; i < 300; ++i) {
    const Pose2 a{xy(rng), xy(rng), yaw(rng)}, b{xy(rng), xy(rng), yaw(rng)};
    const auto paths = rs_paths(a, b, R);
    if (paths.empty()) continue;
    ++solved;
    const Path p = rs_sample(a, paths.front(), R, 0.01);
    const Pose2 e = p.back().pose;
    ASSERT_NEAR(e.x_m, b.x_m, 1e-6);
    ASSERT_NEAR(e.y_m, b.y_m, 1e-6);
    ASSERT_NEAR(angle_wrap_rad(e.yaw_rad - b.yaw_rad), 0.0, 1e-6);
    for (const auto &q : p) ASSERT_LE(std::abs(q.curvature_1pm), 1.0 / R + 1e-9);
    // Never longer than a known feasible path: L-turn there and back bounds aside, the
    // shortest must not exceed straight-line + 2 full circles.
    EXPECT_LE(paths.front().length_m(), std::hypot(a.x_m - b.x_m, a.y_m - b.y_m) + 4 * kPi * R);
  }
  EXPECT_EQ(solved, 300);
}

TEST(ReedsShepp, PureReverseIsAStraightBackwards) {
  const auto paths = rs_paths({0, 0, 0}, {-0.5, 0, 0}, 0.3);
  ASSERT_FALSE(paths.empty());
  EXPECT_NEAR(paths.front().length_m(), 0.5, 1e-9);
  const Path p = rs_sample({0, 0, 0}, paths.front(), 0.3, 0.05);
  for (const auto &q : p) EXPECT_EQ(q.direction, -1);
}

TEST(GridAStar, FindsARouteAroundABoxAndNoneIntoAClosedRoom) {
  const auto world = autodrive::synthetic_world::World::parking_lot();
  const GridMap map = world.rasterize(0.04);
  std::vector<uint8_t> passable(map.log_odds.size());
  for (int cy = 0; cy < map.height_cells; ++cy)
    for (int cx = 0; cx < map.width_cells; ++cx)
      passable[map.index(cx, cy)] = map.state(cx, cy) == CellState::kFree;
  const auto route = astar_route(map, passable, {0.5, 1.75}, {2.0, 1.75});
  ASSERT_FALSE(route.empty());
  double len = 0;
  for (size_t i = 1; i < route.size(); ++i) {
    len += (route[i] - route[i - 1]).norm();
    int cx, cy;
    ASSERT_TRUE(map.world_to_cell(route[i].x(), route[i].y(), cx, cy));
    ASSERT_TRUE(passable[map.index(cx, cy)]);
  }
  EXPECT_GT(len, 1.5 + 0.05);  // it had to go around the box at x 1.0-1.3
  EXPECT_TRUE(astar_route(map, passable, {0.5, 1.75}, {4.2, 1.75}).empty());  // outside the lot
}

TEST(HybridAStar, ReversesIntoASlotWithinTheTurningRadiusAndClearOfObstacles) {
  const auto world = autodrive::synthetic_world::World::parking_lot();
  const GridMap map = world.rasterize(0.02);
  const CollisionChecker cc(map, nigel());
  const Pose2 start{0.5, 1.0, 0.0};
  const Pose2 slot{2.45, 0.18,
                   kPi / 2};  // nose out, rear axle 0.18 m from the back wall (tail 0.13 m)
  const PlanResult r = hybrid_astar_plan(cc, start, slot);
  ASSERT_FALSE(r.failed) << r.detail;
  expect_feasible(r.path);
  EXPECT_TRUE(cc.path_free(r.path));
  for (const auto &q : r.path) ASSERT_GE(cc.clearance_m(q.pose), nigel().margin_m);
  const Pose2 e = r.path.back().pose;
  EXPECT_NEAR(e.x_m, slot.x_m, 1e-6);
  EXPECT_NEAR(e.y_m, slot.y_m, 1e-6);
  EXPECT_NEAR(angle_wrap_rad(e.yaw_rad - slot.yaw_rad), 0.0, 1e-6);
  EXPECT_EQ(r.path.back().direction, -1);  // it backs into the slot
  EXPECT_FALSE(r.route_m.empty());
  EXPECT_LT(path_length_m(r.path), 6.0);
}

TEST(HybridAStar, GoesAroundAnObstacleAcrossTheDirectWay) {
  auto world = autodrive::synthetic_world::World::parking_lot();
  world.add_box(1.4, 0.0, 1.6, 1.5);  // a wall of boxes across the lower lot
  const GridMap map = world.rasterize(0.02);
  const CollisionChecker cc(map, nigel());
  const Pose2 start{0.6, 0.8, 0.0}, goal{2.0 + 0.45, 0.9, 0.0};
  const PlanResult r = hybrid_astar_plan(cc, start, goal);
  ASSERT_FALSE(r.failed) << r.detail;
  expect_feasible(r.path);
  EXPECT_TRUE(cc.path_free(r.path));
  double max_y = 0;
  for (const auto &q : r.path) max_y = std::max(max_y, q.pose.y_m);
  EXPECT_GT(max_y, 1.5);  // over the top of the boxes
}

TEST(HybridAStar, FailsCleanlyOnAnUnreachableOrBlockedGoal) {
  auto world = autodrive::synthetic_world::World::parking_lot();
  world.add_box(2.31, 0.36, 2.59, 0.40);  // the slot's mouth is closed
  const GridMap map = world.rasterize(0.02);
  const CollisionChecker cc(map, nigel());
  HybridAStarConfig cfg;
  cfg.max_expansions = 3000;
  const PlanResult r = hybrid_astar_plan(cc, {0.5, 1.0, 0.0}, {2.45, 0.18, kPi / 2}, cfg);
  EXPECT_TRUE(r.failed);
  EXPECT_FALSE(r.detail.empty());
  const PlanResult r2 =
      hybrid_astar_plan(cc, {0.5, 1.0, 0.0}, {1.15, 1.75, 0.0}, cfg);  // inside a box
  EXPECT_TRUE(r2.failed);
  EXPECT_EQ(r2.detail, "goal pose is in collision");
}

TEST(Footprint, CollisionCheckMatchesTheCarsRectangle) {
  GridMap map(100, 100, 0.01, 0.0, 0.0);
  for (auto &l : map.log_odds) l = -5.0f;
  map.log_odds[map.index(50, 50)] = 5.0f;  // one obstacle cell at (0.505, 0.505)
  const CollisionChecker cc(map, nigel());
  // Car centred on the obstacle: collision. 0.2 m to the side: free.
  EXPECT_FALSE(cc.pose_free({0.505 - 0.0708, 0.505, 0.0}));
  EXPECT_TRUE(cc.pose_free({0.505 - 0.0708, 0.505 + 0.2, 0.0}));
  // Just beside the body (0.065 m half width) but within the margin: collision.
  EXPECT_FALSE(cc.pose_free({0.505 - 0.0708, 0.505 + 0.075, 0.0}));
}
