#include <autodrive/autonomy/hybrid_astar.hpp>

#include <cmath>
#include <limits>
#include <queue>
#include <unordered_map>

#include <autodrive/autonomy/grid_search.hpp>
#include <autodrive/autonomy/reeds_shepp.hpp>

namespace autodrive::autonomy {
namespace {

struct Node {
  Pose2 pose;
  double g = 0;
  int parent = -1;
  int direction = 1;
  double steer_rad = 0;
  Path segment;  // samples from the parent to this node (parent excluded)
};

}  // namespace

double ha_max_curvature_1pm(const HybridAStarConfig &cfg) {
  return std::tan(cfg.max_steer_rad * cfg.steer_use_fraction) / cfg.wheelbase_m;
}
double ha_min_turn_radius_m(const HybridAStarConfig &cfg) {
  return 1.0 / ha_max_curvature_1pm(cfg);
}

PlanResult hybrid_astar_plan(const CollisionChecker &cc, const Pose2 &start, const Pose2 &goal,
                             const HybridAStarConfig &cfg) {
  PlanResult res;
  const GridMap &map = cc.map();
  if (!cc.pose_free(start)) {
    res.detail = "start pose is in collision";
    return res;
  }
  if (!cc.pose_free(goal)) {
    res.detail = "goal pose is in collision";
    return res;
  }
  const double R = ha_min_turn_radius_m(cfg);
  // Holonomic part: cells a narrow disc could cross.
  const double pass_m = 0.3 * cc.footprint().width_m;
  std::vector<uint8_t> passable(cc.field_m().size());
  for (size_t i = 0; i < passable.size(); ++i) passable[i] = cc.field_m()[i] >= pass_m;
  res.route_m = astar_route(map, passable, {start.x_m, start.y_m}, {goal.x_m, goal.y_m});
  const auto h_grid = dijkstra_cost_to_goal_m(map, passable, {goal.x_m, goal.y_m});
  auto heuristic = [&](const Pose2 &p) {
    double hg = std::hypot(p.x_m - goal.x_m, p.y_m - goal.y_m);
    int cx, cy;
    if (map.world_to_cell(p.x_m, p.y_m, cx, cy) && std::isfinite(h_grid[map.index(cx, cy)]))
      hg = std::max<double>(hg, h_grid[map.index(cx, cy)]);
    return cfg.heuristic_weight * std::max(hg, rs_shortest_length_m(p, goal, R));
  };
  auto key_of = [&](const Pose2 &p) -> long long {
    const long long ix =
        static_cast<long long>(std::floor((p.x_m - map.origin_x_m) / cfg.xy_bin_m));
    const long long iy =
        static_cast<long long>(std::floor((p.y_m - map.origin_y_m) / cfg.xy_bin_m));
    long long iyaw =
        static_cast<long long>(std::floor((p.yaw_rad + kPi) / (2 * kPi) * cfg.yaw_bins));
    iyaw = ((iyaw % cfg.yaw_bins) + cfg.yaw_bins) % cfg.yaw_bins;
    return (ix * 100000LL + iy) * 1000LL + iyaw;
  };

  // Collision check of a Reeds-Shepp candidate while walking it (stops at the first hit).
  auto rs_free = [&](const RsPath &path, const Pose2 &from) {
    Pose2 p = from;
    for (const auto &g : path.segments) {
      const double k = g.type == 'L' ? 1.0 / R : g.type == 'R' ? -1.0 / R : 0.0;
      const int n = std::max(1, static_cast<int>(std::ceil(std::abs(g.length_m) / cfg.sample_m)));
      for (int i = 0; i < n; ++i) {
        p = arc_step(p, g.length_m / n, k);
        if (!cc.pose_free(p)) return false;
      }
    }
    return true;
  };

  std::vector<Node> nodes;
  nodes.push_back({start, 0.0, -1, 1, 0.0, {}});
  using QItem = std::pair<double, int>;
  std::priority_queue<QItem, std::vector<QItem>, std::greater<QItem>> open;
  std::unordered_map<long long, int> best;  // bin -> node index with the lowest g
  std::unordered_map<long long, bool> closed;
  open.push({heuristic(start), 0});
  best[key_of(start)] = 0;

  Path tail;
  int reached = -1;
  while (!open.empty() && res.expansions < cfg.max_expansions) {
    const int ci = open.top().second;
    open.pop();
    const long long ck = key_of(nodes[ci].pose);
    if (closed[ck]) continue;
    closed[ck] = true;
    ++res.expansions;
    // Analytic expansion, more often as the goal gets closer (Dolgov et al.).
    const double h_rs = rs_shortest_length_m(nodes[ci].pose, goal, R);
    const int every = std::max(1, static_cast<int>(cfg.analytic_every * h_rs / 1.0));
    if (res.expansions % every == 0 || res.expansions == 1) {
      // Shots at the goal through a pre-goal pose final_straight_m before it (forward and
      // reverse approach), so the manoeuvre ends on a straight: the tracker settles the
      // heading there. Then a direct shot as the fallback.
      double best_len = 1e18;
      for (int approach : {-1, 1, 0}) {
        const double d = approach * cfg.final_straight_m;
        const Pose2 pre = approach == 0 ? goal : pose_compose(goal, {-d, 0.0, 0.0});
        if (approach != 0) {
          if (!rs_free(RsPath{{{'S', d}}}, pre)) continue;
        }
        const auto cands = rs_paths(nodes[ci].pose, pre, R);
        for (size_t k = 0; k < cands.size() && k < static_cast<size_t>(cfg.analytic_candidates);
             ++k) {
          const double len =
              cands[k].length_m() + std::abs(d) + (approach == 0 ? cfg.final_straight_m : 0.0);
          if (len >= best_len) break;
          if (!rs_free(cands[k], nodes[ci].pose)) continue;
          RsPath full = cands[k];
          if (approach != 0) full.segments.push_back({'S', d});
          tail = rs_sample(nodes[ci].pose, full, R, cfg.sample_m);
          best_len = len;
          reached = ci;
          break;
        }
      }
      if (reached >= 0) break;
    }
    for (int dir : {1, -1}) {
      for (int si = 0; si < cfg.steer_samples; ++si) {
        const double steer =
            cfg.max_steer_rad * cfg.steer_use_fraction *
            (cfg.steer_samples == 1 ? 0.0 : -1.0 + 2.0 * si / (cfg.steer_samples - 1));
        const double k = std::tan(steer) / cfg.wheelbase_m;
        Node n;
        n.parent = ci;
        n.direction = dir;
        n.steer_rad = steer;
        Pose2 p = nodes[ci].pose;
        const int subs = std::max(1, static_cast<int>(std::ceil(cfg.step_m / cfg.sample_m)));
        bool ok = true;
        for (int s = 0; s < subs; ++s) {
          n.segment.push_back({p, dir, k});
          p = arc_step(p, dir * cfg.step_m / subs, k);
          if (!cc.pose_free(p)) {
            ok = false;
            break;
          }
        }
        if (!ok) continue;
        n.pose = p;
        const long long nk = key_of(p);
        if (closed.count(nk) && closed[nk]) continue;
        const Node &par = nodes[ci];
        n.g = par.g + cfg.step_m * (dir < 0 ? cfg.reverse_cost : 1.0) +
              (ci != 0 && dir != par.direction ? cfg.switch_cost_m : 0.0) +
              cfg.steer_cost_m * std::abs(steer) +
              cfg.steer_change_cost_m * std::abs(steer - par.steer_rad);
        const auto it = best.find(nk);
        if (it != best.end() && nodes[it->second].g <= n.g) continue;
        const double f = n.g + heuristic(p);
        nodes.push_back(std::move(n));
        best[nk] = static_cast<int>(nodes.size()) - 1;
        open.push({f, static_cast<int>(nodes.size()) - 1});
      }
    }
  }
  if (reached < 0) {
    res.detail = open.empty() ? "no collision-free path (search space exhausted)"
                              : "no path within the expansion limit";
    return res;
  }
  std::vector<int> chain;
  for (int i = reached; i > 0; i = nodes[i].parent) chain.push_back(i);
  Path path;
  for (auto it = chain.rbegin(); it != chain.rend(); ++it)
    path.insert(path.end(), nodes[*it].segment.begin(), nodes[*it].segment.end());
  path.insert(path.end(), tail.begin(), tail.end());
  res.path = std::move(path);
  res.failed = false;
  res.detail = "ok";
  return res;
}

}  // namespace autodrive::autonomy
