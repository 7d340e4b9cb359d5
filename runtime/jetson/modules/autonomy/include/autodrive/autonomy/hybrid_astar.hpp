// ha_: Hybrid A* (Dolgov et al. 2010) for a car that may reverse. Nodes are continuous poses
// binned in (x, y, yaw); successors are arcs at a few steering angles within the limit,
// forward and reverse; the heuristic is the larger of the Reeds-Shepp length (ignores
// obstacles) and the grid Dijkstra distance (ignores kinematics); every few expansions a
// Reeds-Shepp shot to the goal is tried (analytic expansion) and accepted if collision-free,
// which lands the path exactly on the goal pose.
#pragma once

#include <autodrive_vehicle.h>
#include <string>
#include <vector>

#include <autodrive/autonomy/footprint.hpp>
#include <autodrive/autonomy/path.hpp>

namespace autodrive::autonomy {

struct HybridAStarConfig {
  double wheelbase_m = AUTODRIVE_VEHICLE_WHEELBASE_M;
  double max_steer_rad = AUTODRIVE_VEHICLE_STEER_LIMIT_RAD;
  double steer_use_fraction = 0.8;  // plan at 80% of the limit: tracking needs headroom
  int steer_samples = 5;            // odd, from -max to +max
  double step_m = 0.06;             // arc length of one expansion
  double sample_m = 0.01;           // path sample / collision check spacing
  double xy_bin_m = 0.04;
  int yaw_bins = 72;
  double reverse_cost = 1.5;          // multiplier on reversing length
  double switch_cost_m = 0.3;         // per change of direction
  double steer_cost_m = 0.02;         // per rad of steering, per step
  double steer_change_cost_m = 0.05;  // per rad of steering change
  int analytic_every = 2;             // expansions between Reeds-Shepp shots per metre to go
  int analytic_candidates = 8;        // shortest candidates tried per shot
  double final_straight_m = 0.15;     // preferred straight run into the goal
  double heuristic_weight = 1.5;      // > 1: weighted A*, far fewer expansions, paths a bit longer
  int max_expansions = 60000;
};

struct PlanResult {
  bool failed = true;  // false = a path was found
  Path path;
  std::vector<Eigen::Vector2d> route_m;  // grid A* route start -> goal (empty if none)
  int expansions = 0;
  std::string detail;
};

double ha_min_turn_radius_m(const HybridAStarConfig &cfg);
double ha_max_curvature_1pm(const HybridAStarConfig &cfg);

PlanResult hybrid_astar_plan(const CollisionChecker &cc, const Pose2 &start, const Pose2 &goal,
                             const HybridAStarConfig &cfg = HybridAStarConfig{});

}  // namespace autodrive::autonomy
