#include <autodrive/autonomy/grid_search.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <queue>

namespace autodrive::autonomy {
namespace {

constexpr int kDx[8] = {1, -1, 0, 0, 1, 1, -1, -1};
constexpr int kDy[8] = {0, 0, 1, -1, 1, -1, 1, -1};
constexpr double kStep[8] = {1, 1, 1, 1, 1.41421356, 1.41421356, 1.41421356, 1.41421356};

using QItem = std::pair<double, int>;  // (priority, cell index)

}  // namespace

std::vector<Eigen::Vector2d> astar_route(const GridMap &map, const std::vector<uint8_t> &passable,
                                         const Eigen::Vector2d &start_m,
                                         const Eigen::Vector2d &goal_m) {
  int sx, sy, gx, gy;
  if (!map.world_to_cell(start_m.x(), start_m.y(), sx, sy) ||
      !map.world_to_cell(goal_m.x(), goal_m.y(), gx, gy))
    return {};
  const int n = map.width_cells * map.height_cells;
  std::vector<double> g(static_cast<size_t>(n), std::numeric_limits<double>::infinity());
  std::vector<int> parent(static_cast<size_t>(n), -1);
  std::vector<uint8_t> closed(static_cast<size_t>(n), 0);
  std::priority_queue<QItem, std::vector<QItem>, std::greater<QItem>> open;
  const int s = map.index(sx, sy), goal = map.index(gx, gy);
  auto h = [&](int cx, int cy) { return std::hypot(cx - gx, cy - gy); };
  g[s] = 0;
  open.push({h(sx, sy), s});
  while (!open.empty()) {
    const int c = open.top().second;
    open.pop();
    if (c == goal) break;
    const int cx = c % map.width_cells, cy = c / map.width_cells;
    if (closed[c]) continue;  // stale entry
    closed[c] = 1;
    for (int k = 0; k < 8; ++k) {
      const int nx = cx + kDx[k], ny = cy + kDy[k];
      if (!map.in_bounds(nx, ny)) continue;
      const int ni = map.index(nx, ny);
      if (!passable[ni] || closed[ni]) continue;
      const double ng = g[c] + kStep[k];
      if (ng < g[ni]) {
        g[ni] = ng;
        parent[ni] = c;
        open.push({ng + h(nx, ny), ni});
      }
    }
  }
  if (!std::isfinite(g[goal])) return {};
  std::vector<Eigen::Vector2d> route;
  for (int c = goal; c != -1; c = parent[c])
    route.push_back(map.cell_center_m(c % map.width_cells, c / map.width_cells));
  std::reverse(route.begin(), route.end());
  return route;
}

std::vector<float> dijkstra_cost_to_goal_m(const GridMap &map, const std::vector<uint8_t> &passable,
                                           const Eigen::Vector2d &goal_m) {
  const int n = map.width_cells * map.height_cells;
  // Doubles inside: comparing against float-rounded costs could relax a cell forever.
  std::vector<double> d(static_cast<size_t>(n), std::numeric_limits<double>::infinity());
  std::vector<uint8_t> done(static_cast<size_t>(n), 0);
  int gx, gy;
  if (map.world_to_cell(goal_m.x(), goal_m.y(), gx, gy)) {
    std::priority_queue<QItem, std::vector<QItem>, std::greater<QItem>> open;
    d[map.index(gx, gy)] = 0;
    open.push({0.0, map.index(gx, gy)});
    while (!open.empty()) {
      const int c = open.top().second;
      open.pop();
      if (done[c]) continue;
      done[c] = 1;
      const int cx = c % map.width_cells, cy = c / map.width_cells;
      for (int k = 0; k < 8; ++k) {
        const int nx = cx + kDx[k], ny = cy + kDy[k];
        if (!map.in_bounds(nx, ny)) continue;
        const int ni = map.index(nx, ny);
        if (!passable[ni] || done[ni]) continue;
        const double nd = d[c] + kStep[k] * map.resolution_m;
        if (nd < d[ni]) {
          d[ni] = nd;
          open.push({nd, ni});
        }
      }
    }
  }
  return std::vector<float>(d.begin(), d.end());
}

}  // namespace autodrive::autonomy
