#include <autodrive/autonomy/autonomy_node.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <sstream>

#include <autodrive/autonomy/local_planner.hpp>
#include <autodrive/autonomy/map_io.hpp>

namespace autodrive::autonomy {
namespace {

MissionConfig mission_cfg(const NodeConfig &cfg) {
  MissionConfig m = cfg.mission;
  m.start_with_map = !cfg.map_yaml_in.empty();
  return m;
}

// "path 1.28 m, 0 cusps, 1 expansions": what the terminal and mission_status_t show of a plan.
std::string describe_plan(const PlanResult &r) {
  std::ostringstream d;
  d.precision(3);
  d << "path " << path_length_m(r.path) << " m, " << path_cusps(r.path) << " cusps, "
    << r.expansions << " expansions";
  return d.str();
}

}  // namespace

AutonomyNode::AutonomyNode(const NodeConfig &cfg)
    : cfg_(cfg), mission_(mission_cfg(cfg)), tracker_(cfg.tracker), laser_odom_(cfg.laser_odom) {
  if (cfg_.map_yaml_in.empty()) {
    slam_ = std::make_unique<HectorSlam>(cfg_.slam, cfg_.start_pose);
  } else {
    try {
      map_ = std::make_unique<GridMap>(map_load(cfg_.map_yaml_in));
      after_map_ready(0.0);
    } catch (const std::exception &e) {
      mission_.fail(e.what(), 0.0);
    }
  }
}

const GridMap *AutonomyNode::map() const {
  if (map_) return map_.get();
  return slam_ ? &slam_->map() : nullptr;
}

double AutonomyNode::progress() const {
  const auto path_fraction = [this] {
    const size_t n = tracker_.path().size();
    if (n < 2) return 0.0;
    return tracker_.done() ? 1.0 : static_cast<double>(tracker_.progress_index()) / (n - 1);
  };
  switch (mission_.state()) {
    case MissionState::kMapping: {
      // The standstill scans count as one step, each route leg as another.
      const double steps = 1.0 + static_cast<double>(cfg_.mapping_route.size());
      const double scans = slam_ ? std::min(1.0, static_cast<double>(slam_->scans_processed()) /
                                                     std::max(1, cfg_.mapping_scans))
                                 : 0.0;
      const double legs = mapping_leg_index_ + (mapping_leg_ ? path_fraction() : 0.0);
      return std::clamp((scans + legs) / steps, 0.0, 1.0);
    }
    case MissionState::kLocalising:
      return std::min(
          1.0, static_cast<double>(localising_updates_) / std::max(1, cfg_.localising_min_updates));
    case MissionState::kDriving: return std::clamp(path_fraction(), 0.0, 1.0);
    case MissionState::kParked:
    case MissionState::kFailed: return 1.0;
    default: return 0.0;
  }
}

Pose2 AutonomyNode::pose_map() const {
  return pose_compose(map_from_odom_, odom_);
}

std::optional<Pose2> AutonomyNode::amcl_pose() const {
  if (!amcl_ || localising_updates_ == 0) return std::nullopt;
  return amcl_->estimate();
}

Eigen::Matrix3d AutonomyNode::amcl_covariance() const {
  return amcl_ ? amcl_->covariance() : Eigen::Matrix3d::Identity();
}

void AutonomyNode::after_map_ready(double) {
  plan_map_ = std::make_unique<GridMap>(*map_);
  checker_ =
      std::make_unique<CollisionChecker>(*plan_map_, cfg_.footprint, cfg_.unknown_is_obstacle);
  amcl_field_m_ = grid_distance_field_m(*map_, false);
  amcl_ = std::make_unique<Amcl>(*map_, cfg_.amcl);
  // From SLAM: its pose is on this very map; otherwise the configured start guess.
  const Pose2 guess = slam_ ? slam_->pose() : cfg_.start_pose;
  amcl_->init_gaussian(guess, cfg_.initial_sigma_xy_m, cfg_.initial_sigma_xy_m,
                       cfg_.initial_sigma_yaw_rad);
  localising_updates_ = 0;
}

void AutonomyNode::on_odom(const Pose2 &odom, int64_t utime_us) {
  const double dt_s = have_odom_ ? std::max(0.0, (utime_us - last_odom_us_) * 1e-6) : 0.0;
  odom_ = odom;
  odom_history_.add(utime_us, odom);
  last_odom_us_ = utime_us;
  have_odom_ = true;
  const double t = now_s(utime_us);
  mission_.tick(t);
  if (!engaged() || settling_) {
    command_ = TrackerCommand{};
    return;
  }
  command_ = tracker_.step(pose_map(), dt_s, measured_speed_m_s(utime_us));
  if (command_.done) {
    // Hold still; on_scan judges the stop on a scan that starts after the car has settled.
    settling_ = true;
    settled_at_us_ = utime_us + static_cast<int64_t>(cfg_.settle_s * 1e6);
    command_ = TrackerCommand{};
  }
}

double AutonomyNode::measured_speed_m_s(int64_t utime_us) const {
  // Over the last 0.2 s of odometry: long enough to average the encoder ticks.
  const int64_t window_us = 200000;
  const auto before = odom_history_.at(utime_us - window_us);
  if (!before) return std::nan("");
  const Pose2 d = pose_between(*before, odom_);
  return d.x_m / (window_us * 1e-6);
}

void AutonomyNode::judge_arrival(double t_s) {
  settling_ = false;
  const Pose2 e = pose_between(cfg_.goal, pose_map());
  const double pos_err_m = std::hypot(e.x_m, e.y_m), yaw_err_rad = std::abs(e.yaw_rad);
  std::ostringstream why;
  why.precision(3);
  why << "stopped " << pos_err_m << " m, " << yaw_err_rad * 180.0 / kPi << " deg from the goal";
  mission_.arrived(pos_err_m <= cfg_.goal_tolerance_m && yaw_err_rad <= cfg_.goal_tolerance_yaw_rad,
                   why.str(), t_s);
  if (mission_.state() == MissionState::kPlanning) plan(t_s, true);
}

PlanResult AutonomyNode::plan_via_staging(const Pose2 &from) {
  // Back off against the direction the last path arrived in, then run straight in.
  const int arrive_dir = tracker_.path().empty() ? 1 : tracker_.path().back().direction;
  const Pose2 staging =
      pose_compose(cfg_.goal, Pose2{-arrive_dir * cfg_.retry_backoff_m, 0.0, 0.0});
  PlanResult out;
  out.detail = "staging pose not reachable";
  if (!checker_->pose_free(staging)) return out;
  const PlanResult a = hybrid_astar_plan(*checker_, from, staging, cfg_.planner);
  if (a.failed) return out;
  const PlanResult b = hybrid_astar_plan(*checker_, staging, cfg_.goal, cfg_.planner);
  if (b.failed) return out;
  out = b;
  out.path = a.path;
  out.path.insert(out.path.end(), b.path.begin() + (b.path.empty() ? 0 : 1), b.path.end());
  out.expansions = a.expansions + b.expansions;
  out.route_m = a.route_m;
  out.route_m.insert(out.route_m.end(), b.route_m.begin(), b.route_m.end());
  return out;
}

void AutonomyNode::localise(const Pose2 &odom_scan, const Scan &scan, int64_t scan_mid_us) {
  Pose2 est = amcl_->estimate();
  if (cfg_.refine_scan_match) {
    const Pose2 refined =
        scan_match_level(*map_, scan_points_base(scan, cfg_.amcl.lidar_in_base), est, 10);
    const Pose2 d = pose_between(est, refined);
    if (std::hypot(d.x_m, d.y_m) <= cfg_.refine_max_m &&
        std::abs(d.yaw_rad) <= cfg_.refine_max_yaw_rad)
      est = refined;
  }
  map_from_odom_ = pose_compose(est, pose_inverse(odom_scan));
  have_map_odom_ = true;
  loc_pose_ = est;
  loc_utime_us_ = scan_mid_us;
}

void AutonomyNode::plan(double t_s, bool retry) {
  ++plans_;
  settling_ = false;
  bool staged = false;
  PlanResult r;
  if (retry && cfg_.retry_backoff_m > 0) {
    r = plan_via_staging(pose_map());
    staged = !r.failed;
  }
  if (!staged) r = hybrid_astar_plan(*checker_, pose_map(), cfg_.goal, cfg_.planner);
  route_m_ = r.route_m;
  if (r.failed) {
    mission_.planned(false, "planning failed: " + r.detail, t_s);
    return;
  }
  tracker_.set_path(r.path);
  std::ostringstream why;
  why.precision(3);
  why << describe_plan(r);
  if (staged) why << ", via a staging pose " << cfg_.retry_backoff_m << " m back";
  mission_.planned(true, why.str(), t_s);
}

void AutonomyNode::map_scan(const Scan &scan, const Pose2 &odom_scan, const Pose2 &odom_motion,
                            const Pose2 &lo_motion, int64_t utime_us, double t_s) {
  // Standing still (odometry moved < 2 mm and < 0.2 deg): the scan is taken from where the
  // last one was, so it is written there instead of drifting with scan matches. Moving: the
  // laser odometry's motion is the guess for the match (it falls back to the wheel/EKF
  // odometry by itself when ICP is not trusted).
  const bool still = std::hypot(odom_motion.x_m, odom_motion.y_m) < cfg_.still_m &&
                     std::abs(odom_motion.yaw_rad) < cfg_.still_yaw_rad;
  const Pose2 guess = scans_ <= 1 ? Pose2{} : still ? odom_motion : lo_motion;
  const Pose2 p = slam_->update(scan, guess, !(still && have_odom_));
  map_from_odom_ = pose_compose(p, pose_inverse(odom_scan));
  have_map_odom_ = true;
  if (slam_->scans_processed() < cfg_.mapping_scans) return;
  if (mapping_leg_) {
    // A leg ends like a parking drive: the car holds still, then the next leg starts from a
    // scan taken at standstill.
    if (!settling_ || utime_us < settled_at_us_) return;
    settling_ = mapping_leg_ = false;
    ++mapping_leg_index_;
  }
  if (mapping_leg_index_ < cfg_.mapping_route.size()) {
    plan_mapping_leg(t_s);
    return;
  }
  save_map(t_s);
}

void AutonomyNode::plan_mapping_leg(double t_s) {
  const Pose2 &to = cfg_.mapping_route[mapping_leg_index_];
  // A snapshot: the checker keeps a reference, and SLAM writes its map as the car moves.
  const GridMap snapshot = slam_->map();
  const CollisionChecker checker(snapshot, cfg_.footprint, cfg_.unknown_is_obstacle);
  const PlanResult r = hybrid_astar_plan(checker, pose_map(), to, cfg_.planner);
  std::ostringstream what;
  what.precision(3);
  what << "route leg " << mapping_leg_index_ + 1 << "/" << cfg_.mapping_route.size() << " to ("
       << to.x_m << ", " << to.y_m << ", " << to.yaw_rad * 180.0 / kPi << " deg)";
  if (r.failed) {
    mission_.fail(what.str() + ": planning failed: " + r.detail, t_s);
    return;
  }
  ++plans_;
  route_m_ = r.route_m;
  tracker_.set_path(r.path);
  mapping_leg_ = true;
  mission_.note(what.str() + ": " + describe_plan(r));
}

void AutonomyNode::save_map(double t_s) {
  mission_.mapping_done(t_s);
  // SAVING: write the map, then read it back so localisation runs on the saved file.
  try {
    const auto parent = std::filesystem::path(cfg_.map_yaml_out).parent_path();
    if (!parent.empty()) std::filesystem::create_directories(parent);
    map_save(slam_->map(), cfg_.map_yaml_out);
    map_ = std::make_unique<GridMap>(map_load(cfg_.map_yaml_out));
    after_map_ready(t_s);
    mission_.saved(true, "map saved to " + cfg_.map_yaml_out, t_s);
  } catch (const std::exception &e) {
    mission_.saved(false, e.what(), t_s);
  }
}

void AutonomyNode::on_scan(const Scan &scan, int64_t utime_us) {
  const double t = now_s(utime_us);
  mission_.tick(t);
  ++scans_;
  // Where the car was while the scan was measured: odometry at the scan's mid-time.
  const int64_t mid_us = utime_us + static_cast<int64_t>(scan.scan_time_s * 0.5e6);
  const Pose2 odom_scan = odom_history_.at(mid_us).value_or(odom_);
  const Pose2 odom_motion = pose_between(odom_at_last_scan_, odom_scan);
  odom_at_last_scan_ = odom_scan;
  const LaserOdomStep lo = laser_odom_.update(scan, scans_ > 1 ? odom_motion : Pose2{});
  lo_utime_us_ = mid_us;
  switch (mission_.state()) {
    case MissionState::kMapping:
      map_scan(scan, odom_scan, odom_motion, lo.motion, utime_us, t);
      break;
    case MissionState::kLocalising: {
      amcl_->update(odom_scan, scan, true);
      ++localising_updates_;
      localise(odom_scan, scan, mid_us);
      const Eigen::Matrix3d c = amcl_->covariance();
      if (localising_updates_ >= cfg_.localising_min_updates &&
          std::sqrt(std::max(c(0, 0), c(1, 1))) <= cfg_.localised_std_m &&
          std::sqrt(c(2, 2)) <= cfg_.localised_std_yaw_rad) {
        mission_.localised(t);
        plan(t);
      }
      break;
    }
    case MissionState::kDriving: {
      if (settling_) {
        if (utime_us >= settled_at_us_) {
          amcl_->update(odom_scan, scan, true);  // a standstill scan: always worth an update
          ++localising_updates_;
          localise(odom_scan, scan, mid_us);
          judge_arrival(t);
        }
        break;
      }
      if (amcl_->update(odom_scan, scan, false)) {
        ++localising_updates_;
        localise(odom_scan, scan, mid_us);
      }
      // Obstacles not on the map, in the map frame, seen from where the scan was taken.
      std::vector<Eigen::Vector2d> pts;
      const Pose2 base = pose_compose(map_from_odom_, odom_scan);
      for (const auto &q : scan_points_base(scan, cfg_.amcl.lidar_in_base))
        pts.push_back(pose_apply(base, q));
      const auto unmapped = lp_unmapped_points(*map_, amcl_field_m_, pts, cfg_.unmapped_min_dist_m);
      const LocalCheck lc = lp_check_path(tracker_.path(), tracker_.progress_index(),
                                          cfg_.obstacle_horizon_m, unmapped, cfg_.footprint);
      if (lc.blocked) {
        // Mark the obstacle that blocks the path, not every return the map lacks: a wall that
        // was in a LIDAR shadow while mapping, inflated, could wall off the goal itself.
        std::vector<Eigen::Vector2d> blocking;
        for (const auto &u : unmapped)
          if ((u - lc.obstacle_m).norm() <= cfg_.obstacle_cluster_m) blocking.push_back(u);
        grid_mark_occupied(*plan_map_, blocking, cfg_.obstacle_inflation_m);
        checker_ = std::make_unique<CollisionChecker>(*plan_map_, cfg_.footprint,
                                                      cfg_.unknown_is_obstacle);
        std::ostringstream why;
        why.precision(3);
        why << "unmapped obstacle at (" << lc.obstacle_m.x() << ", " << lc.obstacle_m.y() << ") "
            << lc.distance_ahead_m << " m ahead";
        command_ = TrackerCommand{};
        mission_.blocked(why.str(), t);
        if (mission_.state() == MissionState::kPlanning) plan(t);
      }
      break;
    }
    default: break;
  }
}

}  // namespace autodrive::autonomy
