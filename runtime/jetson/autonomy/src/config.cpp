#include "config.hpp"

#include <autodrive/strict_yaml.hpp>

namespace autonomy {
namespace {

using autodrive::yaml::Section;

const char *const kCarFigure =
    "is a figure of the car: it comes from vehicle/nigel.params, not from a config";

void read_pose(const Section &s, Pose2 &p) {
  s.read("x_m", p.x_m);
  s.read("y_m", p.y_m);
  s.read("yaw_rad", p.yaw_rad);
  s.reject_unknown();
}

void read_footprint(const Section &s, Footprint &f) {
  s.reject_keys({"length_m", "width_m", "center_ahead_m"}, kCarFigure);
  s.read("margin_m", f.margin_m);
  s.reject_unknown();
}

void read_slam(const Section &s, SlamConfig &c) {
  s.read("resolution_m", c.resolution_m);
  s.read("levels", c.levels);
  s.read("width_m", c.width_m);
  s.read("height_m", c.height_m);
  s.read("origin_x_m", c.origin_x_m);
  s.read("origin_y_m", c.origin_y_m);
  s.reject_unknown();
  if (c.levels < 1 || c.levels > 4) s.fail_key("levels", "must be 1..4");
  if (!(c.resolution_m > 0)) s.fail_key("resolution_m", "must be > 0");
}

void read_laser_odom(const Section &s, LaserOdomConfig &c) {
  s.read("max_rms_m", c.max_rms_m);
  s.read("min_inliers", c.min_inliers);
  s.read("max_disagree_m", c.max_disagree_m);
  s.read("max_disagree_rad", c.max_disagree_rad);
  c.keyframe_dist_m = s.positive("keyframe_dist_m", c.keyframe_dist_m);
  c.keyframe_angle_rad = s.positive("keyframe_angle_rad", c.keyframe_angle_rad);
  s.reject_unknown();
}

void read_amcl(const Section &s, AmclConfig &c) {
  s.read("min_particles", c.min_particles);
  s.read("max_particles", c.max_particles);
  s.read("sigma_hit_m", c.sigma_hit_m);
  s.read("beams", c.beams);
  s.read("seed", c.seed);
  s.reject_unknown();
  if (c.min_particles < 1 || c.max_particles < c.min_particles)
    s.fail(s.path(), "needs 1 <= min_particles <= max_particles");
}

void read_planner(const Section &s, HybridAStarConfig &c) {
  s.reject_keys({"wheelbase_m", "max_steer_rad"}, kCarFigure);
  s.read("steer_use_fraction", c.steer_use_fraction);
  s.read("max_expansions", c.max_expansions);
  s.reject_unknown();
}

void read_tracker(const Section &s, TrackerConfig &c) {
  c.top_speed_m_s = s.positive("top_speed_m_s", c.top_speed_m_s);
  s.read("cruise_speed_m_s", c.cruise_speed_m_s);
  s.read("lookahead_min_m", c.lookahead_min_m);
  s.read("lookahead_time_s", c.lookahead_time_s);
  s.reject_unknown();
}

void read_mission(const Section &s, MissionConfig &c) {
  s.read("max_replans", c.max_replans);
  s.read("timeout_mapping_s", c.timeout_mapping_s);
  s.read("timeout_localising_s", c.timeout_localising_s);
  s.read("timeout_planning_s", c.timeout_planning_s);
  s.read("timeout_driving_s", c.timeout_driving_s);
  s.reject_unknown();
}

}  // namespace

ProgramConfig cfg_load(const std::string &path) {
  const Section root(autodrive::yaml::load_file(path), "", path);
  ProgramConfig c;
  NodeConfig &n = c.node;
  root.reject_keys({"lidar_in_base"}, kCarFigure);
  c.vehicle = root.get<std::string>("vehicle", c.vehicle);
  if (c.vehicle.empty()) root.fail_key("vehicle", "must not be empty");
  root.read("lcm_url", c.lcm_url);
  root.read("out_dir", c.out_dir);
  c.command_rate_hz = root.positive("command_rate_hz", c.command_rate_hz);
  root.read("exit_after_finish_s", c.exit_after_finish_s);
  if (root.has("map")) {
    const Section map = root.child("map");
    map.read("save_to", n.map_yaml_out);
    map.read("load_from", n.map_yaml_in);
    map.reject_unknown();
  }
  if (!root.has("goal"))
    root.fail_key("goal", "missing key (the parking pose {x_m, y_m, yaw_rad})");
  if (root.has("start")) read_pose(root.child("start"), n.start_pose);
  read_pose(root.child("goal"), n.goal);
  root.read("mapping_scans", n.mapping_scans);
  if (root.has("mapping_route")) {
    const YAML::Node route =
        root.list("mapping_route", "must be a list of poses [{x_m, y_m, yaw_rad}, ...]");
    for (size_t i = 0; i < route.size(); ++i) {
      Pose2 p;
      read_pose(Section(route[i], root.key("mapping_route[" + std::to_string(i) + "]"), path), p);
      n.mapping_route.push_back(p);
    }
  }
  root.read("goal_tolerance_m", n.goal_tolerance_m);
  root.read("goal_tolerance_yaw_rad", n.goal_tolerance_yaw_rad);
  root.read("obstacle_horizon_m", n.obstacle_horizon_m);
  root.read("unknown_is_obstacle", n.unknown_is_obstacle);
  root.read("obstacle_inflation_m", n.obstacle_inflation_m);
  root.read("obstacle_cluster_m", n.obstacle_cluster_m);
  root.read("settle_s", n.settle_s);
  if (n.settle_s < 0 || n.settle_s > 10) root.fail_key("settle_s", "must be 0..10 [s]");
  root.read("retry_backoff_m", n.retry_backoff_m);
  if (n.retry_backoff_m < 0 || n.retry_backoff_m > 2)
    root.fail_key("retry_backoff_m", "must be 0..2 [m]");
  root.read("refine_scan_match", n.refine_scan_match);
  read_footprint(root.child("footprint"), n.footprint);
  read_slam(root.child("slam"), n.slam);
  read_laser_odom(root.child("laser_odom"), n.laser_odom);
  read_amcl(root.child("amcl"), n.amcl);
  read_planner(root.child("planner"), n.planner);
  read_tracker(root.child("tracker"), n.tracker);
  read_mission(root.child("mission"), n.mission);
  root.reject_unknown();
  return c;
}

}  // namespace autonomy
