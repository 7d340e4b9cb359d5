#include <autodrive/autonomy/config.hpp>

#include <autodrive/strict_yaml.hpp>

#include <cmath>
#include <string>

namespace autodrive::autonomy {
namespace {

using autodrive::yaml::Section;

const char *const kCarFigure =
    "is a figure of the car: it comes from vehicle/nigel.params, not from a config";

// Every number has a range; a value outside (or NaN) is refused naming the key and the bound.
constexpr double kMaxCoordM = 1000.0;                 // |x|, |y| of any pose in the map [m]
constexpr double kMaxYawRad = 2.0 * M_PI;             // |yaw| of a pose [rad]
constexpr long long kMaxGridCells = 4096LL * 4096LL;  // the SLAM grid's finest level

void read_pose(const Section &s, Pose2 &p) {
  s.read_in_range("x_m", p.x_m, -kMaxCoordM, kMaxCoordM);
  s.read_in_range("y_m", p.y_m, -kMaxCoordM, kMaxCoordM);
  s.read_in_range("yaw_rad", p.yaw_rad, -kMaxYawRad, kMaxYawRad);
  s.reject_unknown();
}

void read_footprint(const Section &s, Footprint &f) {
  s.reject_keys({"length_m", "width_m", "center_ahead_m"}, kCarFigure);
  s.read_in_range("margin_m", f.margin_m, 0.0, 0.5);
  s.reject_unknown();
}

void read_slam(const Section &s, SlamConfig &c) {
  s.read_in_range("resolution_m", c.resolution_m, 0.001, 1.0);
  s.read_in_range("levels", c.levels, 1, 4);
  s.read_in_range("width_m", c.width_m, 0.1, kMaxCoordM);
  s.read_in_range("height_m", c.height_m, 0.1, kMaxCoordM);
  s.read_in_range("origin_x_m", c.origin_x_m, -kMaxCoordM, kMaxCoordM);
  s.read_in_range("origin_y_m", c.origin_y_m, -kMaxCoordM, kMaxCoordM);
  s.reject_unknown();
  // Checked before anything is allocated: a huge grid is a clear error, not a bad_alloc.
  const long long w = std::llround(c.width_m / c.resolution_m);
  const long long h = std::llround(c.height_m / c.resolution_m);
  if (w * h > kMaxGridCells)
    s.fail(s.path(), "a grid of " + std::to_string(w) + " x " + std::to_string(h) +
                         " cells (width_m / resolution_m x height_m / resolution_m) exceeds " +
                         std::to_string(kMaxGridCells) + " cells (4096 x 4096)");
}

void read_laser_odom(const Section &s, LaserOdomConfig &c) {
  s.read_in_range("max_rms_m", c.max_rms_m, 0.0, 1.0);
  s.read_in_range("min_inliers", c.min_inliers, 1, 100000);
  s.read_in_range("max_disagree_m", c.max_disagree_m, 0.0, 10.0);
  s.read_in_range("max_disagree_rad", c.max_disagree_rad, 0.0, M_PI);
  c.keyframe_dist_m = s.positive_up_to("keyframe_dist_m", 10.0, c.keyframe_dist_m);
  c.keyframe_angle_rad = s.positive_up_to("keyframe_angle_rad", M_PI, c.keyframe_angle_rad);
  s.reject_unknown();
}

void read_amcl(const Section &s, AmclConfig &c) {
  s.read_in_range("min_particles", c.min_particles, 1, 1000000);
  s.read_in_range("max_particles", c.max_particles, 1, 1000000);
  s.read_in_range("sigma_hit_m", c.sigma_hit_m, 0.001, 10.0);
  s.read_in_range("beams", c.beams, 1, 10000);
  s.read("seed", c.seed);
  s.reject_unknown();
  if (c.min_particles < 1 || c.max_particles < c.min_particles)
    s.fail(s.path(), "needs 1 <= min_particles <= max_particles");
}

void read_planner(const Section &s, HybridAStarConfig &c) {
  s.reject_keys({"wheelbase_m", "max_steer_rad"}, kCarFigure);
  s.read_in_range("steer_use_fraction", c.steer_use_fraction, 0.05, 1.0);
  s.read_in_range("max_expansions", c.max_expansions, 1, 100000000);
  s.reject_unknown();
}

void read_tracker(const Section &s, TrackerConfig &c) {
  c.top_speed_m_s = s.positive_up_to("top_speed_m_s", 5.0, c.top_speed_m_s);
  s.read_in_range("cruise_speed_m_s", c.cruise_speed_m_s, 0.01, 5.0);
  s.read_in_range("lookahead_min_m", c.lookahead_min_m, 0.0, 10.0);
  s.read_in_range("lookahead_time_s", c.lookahead_time_s, 0.0, 10.0);
  s.reject_unknown();
}

void read_mission(const Section &s, MissionConfig &c) {
  s.read_in_range("max_replans", c.max_replans, 0, 1000);
  s.read_in_range("timeout_mapping_s", c.timeout_mapping_s, 1.0, 3600.0);
  s.read_in_range("timeout_localising_s", c.timeout_localising_s, 1.0, 3600.0);
  s.read_in_range("timeout_planning_s", c.timeout_planning_s, 1.0, 3600.0);
  s.read_in_range("timeout_driving_s", c.timeout_driving_s, 1.0, 3600.0);
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
  c.command_rate_hz = root.positive_up_to("command_rate_hz", 500.0, c.command_rate_hz);
  root.read_in_range("exit_after_finish_s", c.exit_after_finish_s, 0.0, 3600.0);
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
  root.read_in_range("mapping_scans", n.mapping_scans, 0, 100000);
  if (root.has("mapping_route")) {
    const YAML::Node route =
        root.list("mapping_route", "must be a list of poses [{x_m, y_m, yaw_rad}, ...]");
    for (size_t i = 0; i < route.size(); ++i) {
      Pose2 p;
      read_pose(Section(route[i], root.key("mapping_route[" + std::to_string(i) + "]"), path), p);
      n.mapping_route.push_back(p);
    }
  }
  n.goal_tolerance_m = root.positive_up_to("goal_tolerance_m", 1.0, n.goal_tolerance_m);
  n.goal_tolerance_yaw_rad =
      root.positive_up_to("goal_tolerance_yaw_rad", M_PI, n.goal_tolerance_yaw_rad);
  root.read_in_range("obstacle_horizon_m", n.obstacle_horizon_m, 0.0, 20.0);
  root.read("unknown_is_obstacle", n.unknown_is_obstacle);
  root.read_in_range("obstacle_inflation_m", n.obstacle_inflation_m, 0.0, 2.0);
  root.read_in_range("obstacle_cluster_m", n.obstacle_cluster_m, 0.0, 5.0);
  root.read_in_range("settle_s", n.settle_s, 0.0, 10.0);
  root.read_in_range("retry_backoff_m", n.retry_backoff_m, 0.0, 2.0);
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

}  // namespace autodrive::autonomy
