// autodrive-autonomy: the parking mission on LCM. Subscribes <VEH>_LIDAR and <VEH>_ODOM,
// publishes <VEH>_COMMAND, <VEH>_POSE_AMCL, <VEH>_LASER_ODOM, <VEH>_PATH and <VEH>_MISSION, and
// prints each mission state change. Writes path.csv, route.csv and trajectory.csv into out_dir for
// tools/plot-parking. With --replay LOG it reads <VEH>_LIDAR and <VEH>_ODOM from a recorded LCM
// log instead (file://, as fast as it goes) and writes what it publishes to --replay-out: its
// only clock is the messages' stamps, so a replay computes what the run did.
#include <autodrive/instance.hpp>
#include <autodrive_channels.h>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <optional>

#include <CLI/CLI.hpp>
#include <lcm/lcm-cpp.hpp>
#include <autodrive_lcm/pose2d.hpp>
#include <autodrive_lcm/subscribe.hpp>

#include <autodrive/lidar_scan_t.hpp>
#include <autodrive/mission_status_t.hpp>
#include <autodrive/odometry_t.hpp>
#include <autodrive/path2d_t.hpp>
#include <autodrive/pose2d_t.hpp>
#include <autodrive/command_auth.hpp>
#include <autodrive/vehicle_command_t.hpp>

#include <autodrive/autonomy/config.hpp>

namespace {

volatile std::sig_atomic_t g_stop = 0;
void on_signal(int) {
  g_stop = 1;
}

using namespace autodrive::autonomy;

class App {
 public:
  // signer: signs every command (none in --replay: nothing drives a car there).
  App(const ProgramConfig &cfg, lcm::LCM &lcm, std::optional<autodrive::auth::Signer> signer)
      : cfg_(cfg), lcm_(lcm), node_(cfg.node), signer_(std::move(signer)) {
    std::filesystem::create_directories(cfg_.out_dir);
    traj_.open(std::filesystem::path(cfg_.out_dir) / "trajectory.csv");
    traj_ << "t_s,x_m,y_m,yaw_rad,state\n";
    report_state(0);
  }

  void on_scan(const lcm::ReceiveBuffer *, const std::string &, const autodrive::lidar_scan_t *m) {
    Scan s;
    s.angle_min_rad = m->angle_min_rad;
    s.angle_increment_rad = m->angle_increment_rad;
    s.range_min_m = m->range_min_m;
    s.range_max_m = m->range_max_m;
    s.scan_time_s = std::isfinite(m->scan_time_s) && m->scan_time_s > 0 ? m->scan_time_s : 0.0;
    s.ranges_m = m->ranges_m;
    const int plans_before = node_.plans();
    node_.on_scan(s, m->utime);
    if (node_.plans() != plans_before) write_plan(m->utime);
    publish_laser_odom();
    last_utime_ = std::max(last_utime_, m->utime);
    // The localisation estimate, once per scan that produced one, stamped when it was true.
    if (node_.localised_utime_us() > last_loc_us_) {
      last_loc_us_ = node_.localised_utime_us();
      publish_amcl(node_.localised_pose(), last_loc_us_);
    }
    report_state(m->utime);
  }

  void on_odom(const lcm::ReceiveBuffer *, const std::string &, const autodrive::odometry_t *m) {
    const int plans_before = node_.plans();
    node_.on_odom({m->x_m, m->y_m, m->yaw_rad}, m->utime);
    if (node_.plans() != plans_before) write_plan(m->utime);
    last_utime_ = std::max(last_utime_, m->utime);
    if (m->utime - last_cmd_us_ >= static_cast<int64_t>(1e6 / cfg_.command_rate_hz)) {
      publish_command(m->utime);
      last_cmd_us_ = m->utime;
    }
    if (node_.have_pose() && m->utime - last_traj_us_ >= 50000) {
      const Pose2 p = node_.pose_map();
      traj_ << m->utime * 1e-6 << "," << p.x_m << "," << p.y_m << "," << p.yaw_rad << ","
            << mission_state_name(node_.mission().state()) << "\n";
      last_traj_us_ = m->utime;
    }
    report_state(m->utime);
  }

  bool finished() const { return node_.mission().finished(); }
  bool parked() const { return node_.mission().state() == MissionState::kParked; }
  int64_t last_utime() const { return last_utime_; }
  // stop: a disengaged zero command (on the way out), whatever the mission was doing.
  void publish_command(int64_t utime, bool stop = false) {
    autodrive::vehicle_command_t c{};
    c.utime = utime;
    c.seq = seq_++;
    c.throttle = stop ? 0.0f : static_cast<float>(node_.command().throttle);
    c.steering = stop ? 0.0f : static_cast<float>(node_.command().steering);
    c.headlights = 0;
    c.indicators = node_.mission().state() == MissionState::kParked ? 3 : 0;
    c.engaged = !stop && node_.engaged();
    if (signer_) signer_->sign(c);
    lcm_.publish(cfg_.vehicle + AUTODRIVE_CH_COMMAND_SUFFIX, &c);
  }

 private:
  void publish_amcl(const Pose2 &p, int64_t utime) {
    const Eigen::Matrix3d c = node_.amcl_covariance();
    std::array<double, 9> cov{};
    for (size_t i = 0; i < cov.size(); ++i)
      cov[i] = c(static_cast<int>(i / 3), static_cast<int>(i % 3));
    const autodrive::pose2d_t m = autodrive_lcm::map_pose2d(
        utime, cfg_.vehicle, autodrive::pose2d_t::SOURCE_AMCL, p.x_m, p.y_m, p.yaw_rad, cov);
    lcm_.publish(cfg_.vehicle + AUTODRIVE_CH_POSE_AMCL_SUFFIX, &m);
  }

  void publish_path(int64_t utime) {
    autodrive::path2d_t m{};
    m.utime = utime;
    m.vehicle = cfg_.vehicle;
    m.frame_id = "map";
    m.plan = node_.plans();
    m.purpose = node_.mission().state() == MissionState::kMapping ? "mapping" : "parking";
    for (const auto &q : node_.path()) {
      m.x_m.push_back(q.pose.x_m);
      m.y_m.push_back(q.pose.y_m);
      m.yaw_rad.push_back(q.pose.yaw_rad);
      m.direction.push_back(static_cast<int8_t>(q.direction));
      m.curvature_1pm.push_back(q.curvature_1pm);
    }
    m.num_poses = static_cast<int32_t>(m.x_m.size());
    lcm_.publish(cfg_.vehicle + AUTODRIVE_CH_PATH_SUFFIX, &m);
  }

  // Laser odometry in its own frame (the base pose at the first scan), at the scan's mid-time;
  // the twist is the last step over the time between scans.
  void publish_laser_odom() {
    const int64_t t = node_.laser_odom_utime_us();
    const Pose2 p = node_.laser_odometry().pose();
    autodrive::odometry_t m{};
    m.utime = t;
    m.vehicle = cfg_.vehicle;
    m.frame_id = "laser_odom";
    m.child_frame_id = "base_link";
    m.x_m = p.x_m;
    m.y_m = p.y_m;
    m.yaw_rad = p.yaw_rad;
    if (last_lo_us_ >= 0 && t > last_lo_us_) {
      const double dt_s = (t - last_lo_us_) * 1e-6;
      const Pose2 d = pose_between(last_lo_pose_, p);
      m.vx_m_s = d.x_m / dt_s;
      m.vy_m_s = d.y_m / dt_s;
      m.yaw_rate_rad_s = d.yaw_rad / dt_s;
    }
    last_lo_us_ = t;
    last_lo_pose_ = p;
    lcm_.publish(cfg_.vehicle + AUTODRIVE_CH_LASER_ODOM_SUFFIX, &m);
  }

  // Publishes on every state change and at 2 Hz; prints state changes.
  void report_state(int64_t utime) {
    const auto &ms = node_.mission();
    const bool changed = ms.history().size() != printed_;
    for (; printed_ < ms.history().size(); ++printed_)
      std::printf("[autonomy] %.2f s  %s\n", utime * 1e-6, ms.history()[printed_].c_str());
    if (changed) std::fflush(stdout);
    if (!changed && utime - last_status_us_ < 500000) return;
    last_status_us_ = utime;
    autodrive::mission_status_t m{};
    m.utime = utime;
    m.vehicle = cfg_.vehicle;
    m.state = static_cast<int8_t>(ms.state());
    m.progress = static_cast<float>(node_.progress());
    m.detail = ms.detail();
    lcm_.publish(cfg_.vehicle + AUTODRIVE_CH_MISSION_SUFFIX, &m);
  }

  // path.csv keeps every plan of the run (column plan = 1, 2, ...: replans and retries), so a
  // plot shows the path the car gave up as well as the one it finished on.
  void write_plan(int64_t utime) {
    if (node_.mission().state() == MissionState::kFailed) return;  // no new path, only the old
    publish_path(utime);
    const bool first = node_.plans() <= 1;
    std::ofstream p(std::filesystem::path(cfg_.out_dir) / "path.csv",
                    first ? std::ios::trunc : std::ios::app);
    if (first) p << "x_m,y_m,yaw_rad,direction,curvature_1pm,plan\n";
    for (const auto &q : node_.path())
      p << q.pose.x_m << "," << q.pose.y_m << "," << q.pose.yaw_rad << "," << q.direction << ","
        << q.curvature_1pm << "," << node_.plans() << "\n";
    std::ofstream r(std::filesystem::path(cfg_.out_dir) / "route.csv");
    r << "x_m,y_m\n";
    for (const auto &q : node_.route_m()) r << q.x() << "," << q.y() << "\n";
  }

  const ProgramConfig &cfg_;
  lcm::LCM &lcm_;
  AutonomyNode node_;
  std::optional<autodrive::auth::Signer> signer_;
  std::ofstream traj_;
  int32_t seq_ = 0;
  Pose2 last_lo_pose_;
  int64_t last_lo_us_ = -1, last_loc_us_ = -1, last_cmd_us_ = 0, last_traj_us_ = 0,
          last_status_us_ = -1000000000, last_utime_ = 0;
  size_t printed_ = 0;
};

}  // namespace

int main(int argc, char **argv) {
  CLI::App cli{
      "autodrive-autonomy: autonomous parking mission (map, save, localise, plan, drive, park) on "
      "LCM"};
  std::string config_path, url_override, vehicle_override, replay_in, replay_out, key_file;
  cli.add_option("--config", config_path,
                 "YAML configuration (see runtime/jetson/config/autonomy.example.yaml)")
      ->required();
  cli.add_option("--lcm-url", url_override, "override lcm_url of the config");
  cli.add_option("--vehicle", vehicle_override, "override vehicle (e.g. NIGEL1)");
  cli.add_option("--replay", replay_in, "read LIDAR and ODOM from this recorded LCM log")
      ->check(CLI::ExistingFile);
  cli.add_option("--replay-out", replay_out, "with --replay: the LCM log to publish into");
  cli.add_option("--key-file", key_file,
                 "the car's command key (default: $AUTODRIVE_KEY_DIR/<VEH>.key, else "
                 "~/.config/autodrive/keys/<VEH>.key; tools/keys creates it)");
  CLI11_PARSE(cli, argc, argv);
  if (replay_in.empty() != replay_out.empty()) {
    std::fprintf(stderr, "autodrive-autonomy: --replay and --replay-out go together\n");
    return 2;
  }
  const bool replay = !replay_in.empty();

  ProgramConfig cfg;
  try {
    cfg = cfg_load(config_path);
  } catch (const std::exception &e) {
    std::fprintf(stderr, "autodrive-autonomy: %s\n", e.what());
    return 2;
  }
  if (!url_override.empty()) cfg.lcm_url = url_override;
  if (!vehicle_override.empty()) cfg.vehicle = vehicle_override;

  std::optional<autodrive::auth::Signer> signer;
  if (!replay) {
    signer = autodrive::auth::load_machine_signer("autodrive-autonomy", cfg.vehicle, key_file,
                                                  "autonomy");
    if (!signer) return 2;
  }
  if (replay) {
    cfg.lcm_url = "file://" + std::filesystem::absolute(replay_in).string() + "?speed=0";
    replay_out = "file://" + std::filesystem::absolute(replay_out).string() + "?mode=w";
  }
  cfg.lcm_url = autodrive::instance_lcm_url(cfg.lcm_url);  // AUTODRIVE_INSTANCE
  lcm::LCM lcm(cfg.lcm_url);
  std::unique_ptr<lcm::LCM> replay_lcm;  // replay: what the autonomy publishes goes here
  if (replay) replay_lcm = std::make_unique<lcm::LCM>(replay_out);
  if (!lcm.good() || (replay_lcm && !replay_lcm->good())) {
    std::fprintf(stderr, "autodrive-autonomy: cannot open LCM at '%s' (multicast route missing?)\n",
                 (lcm.good() ? replay_out : cfg.lcm_url).c_str());
    return 2;
  }
  std::signal(SIGINT, on_signal);
  std::signal(SIGTERM, on_signal);
  App app(cfg, replay_lcm ? *replay_lcm : lcm, std::move(signer));
  auto *s1 = autodrive_lcm::subscribe<autodrive::lidar_scan_t, App, &App::on_scan>(
      lcm, cfg.vehicle + AUTODRIVE_CH_LIDAR_SUFFIX, &app);
  auto *s2 = autodrive_lcm::subscribe<autodrive::odometry_t, App, &App::on_odom>(
      lcm, cfg.vehicle + AUTODRIVE_CH_ODOM_SUFFIX, &app);
  s1->setQueueCapacity(10);
  s2->setQueueCapacity(200);
  std::printf("[autonomy] %s on %s: listening to %s_LIDAR, %s_ODOM\n", cfg.vehicle.c_str(),
              cfg.lcm_url.c_str(), cfg.vehicle.c_str(), cfg.vehicle.c_str());
  std::fflush(stdout);
  int64_t finished_at = -1;
  while (!g_stop) {
    if (replay) {
      if (lcm.handle() != 0) break;  // the end of the log
    } else {
      lcm.handleTimeout(100);
    }
    if (app.finished()) {
      if (finished_at < 0) finished_at = app.last_utime();
      if (app.last_utime() - finished_at >= static_cast<int64_t>(cfg.exit_after_finish_s * 1e6))
        break;
    }
  }
  app.publish_command(app.last_utime(), true);  // a final stop, also when interrupted mid-drive
  if (replay) return 0;
  if (!app.finished()) return 130;
  return app.parked() ? 0 : 1;
}
