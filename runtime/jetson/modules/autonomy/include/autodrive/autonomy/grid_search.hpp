// gs_: searches on the 8-connected grid. A* gives the route from start to goal (and tells
// quickly when the goal is unreachable); the Dijkstra cost-to-goal field is Hybrid A*'s
// obstacle-aware heuristic.
#pragma once
#include <vector>

#include <Eigen/Core>

#include <autodrive/autonomy/grid_map.hpp>

namespace autodrive::autonomy {

// passable[i]: cell i may be crossed (row-major like the map).
// Returns the route as cell-centre points [m], start to goal; empty when there is none.
std::vector<Eigen::Vector2d> astar_route(const GridMap &map, const std::vector<uint8_t> &passable,
                                         const Eigen::Vector2d &start_m,
                                         const Eigen::Vector2d &goal_m);

// Shortest 8-connected distance [m] from every cell to the goal; +inf where unreachable.
std::vector<float> dijkstra_cost_to_goal_m(const GridMap &map, const std::vector<uint8_t> &passable,
                                           const Eigen::Vector2d &goal_m);

}  // namespace autodrive::autonomy
