#include "config.hpp"

#include <set>
#include <stdexcept>

#include <yaml-cpp/yaml.h>

namespace autonomy {
namespace {

struct Reader {
  std::string file;
  [[noreturn]] void fail(const std::string &what) const {
    throw std::runtime_error("config '" + file + "': " + what);
  }
  // Rejects keys of node (at path) that are not in allowed.
  void only(const YAML::Node &node, const std::string &path,
            const std::set<std::string> &allowed) const {
    if (!node.IsMap()) fail("'" + path + "' must be a mapping");
    for (const auto &kv : node) {
      const auto k = kv.first.as<std::string>();
      if (!allowed.count(k)) fail("unknown key '" + (path.empty() ? k : path + "." + k) + "'");
    }
  }
  template <typename T>
  void get(const YAML::Node &node, const std::string &path, const char *key, T &out) const {
    if (!node[key]) return;
    try {
      out = node[key].as<T>();
    } catch (const YAML::Exception &) {
      fail("key '" + (path.empty() ? std::string(key) : path + "." + key) + "' has the wrong type");
    }
  }
  void pose(const YAML::Node &node, const std::string &path, const char *key, Pose2 &p) const {
    if (!node[key]) return;
    pose_of(node[key], path.empty() ? key : path + "." + key, p);
  }
  void pose_of(const YAML::Node &n, const std::string &sub, Pose2 &p) const {
    only(n, sub, {"x_m", "y_m", "yaw_rad"});
    get(n, sub, "x_m", p.x_m);
    get(n, sub, "y_m", p.y_m);
    get(n, sub, "yaw_rad", p.yaw_rad);
  }
};

}  // namespace

ProgramConfig cfg_load(const std::string &path) {
  Reader r{path};
  YAML::Node root;
  try {
    root = YAML::LoadFile(path);
  } catch (const YAML::BadFile &) {
    r.fail("cannot be opened");
  } catch (const YAML::Exception &e) {
    r.fail(std::string("is not valid YAML: ") + e.what());
  }
  ProgramConfig c;
  NodeConfig &n = c.node;
  r.only(root, "",
         {"vehicle",
          "lcm_url",
          "out_dir",
          "command_rate_hz",
          "exit_after_finish_s",
          "map",
          "start",
          "goal",
          "lidar_in_base",
          "mapping_scans",
          "mapping_route",
          "goal_tolerance_m",
          "goal_tolerance_yaw_rad",
          "obstacle_horizon_m",
          "obstacle_inflation_m",
          "obstacle_cluster_m",
          "unknown_is_obstacle",
          "settle_s",
          "retry_backoff_m",
          "refine_scan_match",
          "footprint",
          "slam",
          "laser_odom",
          "amcl",
          "planner",
          "tracker",
          "mission"});
  r.get(root, "", "vehicle", c.vehicle);
  r.get(root, "", "lcm_url", c.lcm_url);
  r.get(root, "", "out_dir", c.out_dir);
  r.get(root, "", "command_rate_hz", c.command_rate_hz);
  r.get(root, "", "exit_after_finish_s", c.exit_after_finish_s);
  if (root["map"]) {
    r.only(root["map"], "map", {"save_to", "load_from"});
    r.get(root["map"], "map", "save_to", n.map_yaml_out);
    r.get(root["map"], "map", "load_from", n.map_yaml_in);
  }
  if (!root["goal"]) r.fail("missing key 'goal' (the parking pose {x_m, y_m, yaw_rad})");
  r.pose(root, "", "start", n.start_pose);
  r.pose(root, "", "goal", n.goal);
  Pose2 lidar = n.slam.lidar_in_base;
  r.pose(root, "", "lidar_in_base", lidar);
  n.slam.lidar_in_base = n.amcl.lidar_in_base = n.laser_odom.lidar_in_base = lidar;
  r.get(root, "", "mapping_scans", n.mapping_scans);
  if (const auto route = root["mapping_route"]) {
    if (!route.IsSequence())
      r.fail("'mapping_route' must be a list of poses [{x_m, y_m, yaw_rad}, ...]");
    for (size_t i = 0; i < route.size(); ++i) {
      Pose2 p;
      r.pose_of(route[i], "mapping_route[" + std::to_string(i) + "]", p);
      n.mapping_route.push_back(p);
    }
  }
  r.get(root, "", "goal_tolerance_m", n.goal_tolerance_m);
  r.get(root, "", "goal_tolerance_yaw_rad", n.goal_tolerance_yaw_rad);
  r.get(root, "", "obstacle_horizon_m", n.obstacle_horizon_m);
  r.get(root, "", "unknown_is_obstacle", n.unknown_is_obstacle);
  r.get(root, "", "obstacle_inflation_m", n.obstacle_inflation_m);
  r.get(root, "", "obstacle_cluster_m", n.obstacle_cluster_m);
  r.get(root, "", "settle_s", n.settle_s);
  r.get(root, "", "retry_backoff_m", n.retry_backoff_m);
  if (n.retry_backoff_m < 0 || n.retry_backoff_m > 2) r.fail("'retry_backoff_m' must be 0..2 [m]");
  r.get(root, "", "refine_scan_match", n.refine_scan_match);
  if (n.settle_s < 0 || n.settle_s > 10) r.fail("'settle_s' must be 0..10 [s]");
  if (const auto f = root["footprint"]) {
    r.only(f, "footprint", {"length_m", "width_m", "center_ahead_m", "margin_m"});
    r.get(f, "footprint", "length_m", n.footprint.length_m);
    r.get(f, "footprint", "width_m", n.footprint.width_m);
    r.get(f, "footprint", "center_ahead_m", n.footprint.center_ahead_m);
    r.get(f, "footprint", "margin_m", n.footprint.margin_m);
  }
  if (const auto s = root["slam"]) {
    r.only(s, "slam",
           {"resolution_m", "levels", "width_m", "height_m", "origin_x_m", "origin_y_m"});
    r.get(s, "slam", "resolution_m", n.slam.resolution_m);
    r.get(s, "slam", "levels", n.slam.levels);
    r.get(s, "slam", "width_m", n.slam.width_m);
    r.get(s, "slam", "height_m", n.slam.height_m);
    r.get(s, "slam", "origin_x_m", n.slam.origin_x_m);
    r.get(s, "slam", "origin_y_m", n.slam.origin_y_m);
  }
  if (const auto l = root["laser_odom"]) {
    r.only(l, "laser_odom",
           {"max_rms_m", "min_inliers", "max_disagree_m", "max_disagree_rad", "keyframe_dist_m",
            "keyframe_angle_rad"});
    r.get(l, "laser_odom", "max_rms_m", n.laser_odom.max_rms_m);
    r.get(l, "laser_odom", "min_inliers", n.laser_odom.min_inliers);
    r.get(l, "laser_odom", "max_disagree_m", n.laser_odom.max_disagree_m);
    r.get(l, "laser_odom", "max_disagree_rad", n.laser_odom.max_disagree_rad);
    r.get(l, "laser_odom", "keyframe_dist_m", n.laser_odom.keyframe_dist_m);
    r.get(l, "laser_odom", "keyframe_angle_rad", n.laser_odom.keyframe_angle_rad);
    if (!(n.laser_odom.keyframe_dist_m > 0) || !(n.laser_odom.keyframe_angle_rad > 0))
      r.fail("'laser_odom.keyframe_dist_m' and 'keyframe_angle_rad' must be > 0");
  }
  if (const auto a = root["amcl"]) {
    r.only(a, "amcl", {"min_particles", "max_particles", "sigma_hit_m", "beams", "seed"});
    r.get(a, "amcl", "min_particles", n.amcl.min_particles);
    r.get(a, "amcl", "max_particles", n.amcl.max_particles);
    r.get(a, "amcl", "sigma_hit_m", n.amcl.sigma_hit_m);
    r.get(a, "amcl", "beams", n.amcl.beams);
    r.get(a, "amcl", "seed", n.amcl.seed);
  }
  if (const auto p = root["planner"]) {
    r.only(p, "planner", {"wheelbase_m", "max_steer_rad", "steer_use_fraction", "max_expansions"});
    r.get(p, "planner", "wheelbase_m", n.planner.wheelbase_m);
    r.get(p, "planner", "max_steer_rad", n.planner.max_steer_rad);
    r.get(p, "planner", "steer_use_fraction", n.planner.steer_use_fraction);
    r.get(p, "planner", "max_expansions", n.planner.max_expansions);
  }
  n.tracker.wheelbase_m = n.planner.wheelbase_m;
  n.tracker.max_steer_rad = n.planner.max_steer_rad;
  if (const auto t = root["tracker"]) {
    r.only(t, "tracker",
           {"top_speed_m_s", "cruise_speed_m_s", "lookahead_min_m", "lookahead_time_s"});
    r.get(t, "tracker", "top_speed_m_s", n.tracker.top_speed_m_s);
    r.get(t, "tracker", "cruise_speed_m_s", n.tracker.cruise_speed_m_s);
    r.get(t, "tracker", "lookahead_min_m", n.tracker.lookahead_min_m);
    r.get(t, "tracker", "lookahead_time_s", n.tracker.lookahead_time_s);
  }
  if (const auto m = root["mission"]) {
    r.only(m, "mission",
           {"max_replans", "timeout_mapping_s", "timeout_localising_s", "timeout_planning_s",
            "timeout_driving_s"});
    r.get(m, "mission", "max_replans", n.mission.max_replans);
    r.get(m, "mission", "timeout_mapping_s", n.mission.timeout_mapping_s);
    r.get(m, "mission", "timeout_localising_s", n.mission.timeout_localising_s);
    r.get(m, "mission", "timeout_planning_s", n.mission.timeout_planning_s);
    r.get(m, "mission", "timeout_driving_s", n.mission.timeout_driving_s);
  }
  if (c.vehicle.empty()) r.fail("'vehicle' must not be empty");
  if (!(c.command_rate_hz > 0)) r.fail("'command_rate_hz' must be > 0");
  if (n.slam.levels < 1 || n.slam.levels > 4) r.fail("'slam.levels' must be 1..4");
  if (!(n.slam.resolution_m > 0)) r.fail("'slam.resolution_m' must be > 0");
  if (n.amcl.min_particles < 1 || n.amcl.max_particles < n.amcl.min_particles)
    r.fail("'amcl' needs 1 <= min_particles <= max_particles");
  if (!(n.tracker.top_speed_m_s > 0)) r.fail("'tracker.top_speed_m_s' must be > 0");
  return c;
}

}  // namespace autonomy
