// autodrive-autonomy over real LCM (UDP multicast, port 7811): given a saved map it localises
// from the LIDAR and odometry it hears, plans, and publishes POSE_AMCL, LASER_ODOM, PATH, MISSION
// and engaged COMMANDs. Also --help and a clear error on a bad config.
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>
#include <lcm/lcm-cpp.hpp>
#include <autodrive_lcm/subscribe.hpp>

#include <autodrive/lidar_scan_t.hpp>
#include <autodrive/mission_status_t.hpp>
#include <autodrive/odometry_t.hpp>
#include <autodrive/path2d_t.hpp>
#include <autodrive/pose2d_t.hpp>
#include <autodrive/command_auth.hpp>
#include <autodrive/vehicle_command_t.hpp>

#include <autodrive/autonomy/map_io.hpp>
#include "synthetic_world.hpp"

using namespace autodrive::autonomy;
namespace fs = std::filesystem;

namespace {

const char *kUrl = "udpm://239.255.76.67:7811?ttl=0";

int run_program(const std::vector<std::string> &args, std::string *out) {
  const std::string cmd = std::string(AUTONOMY_PROGRAM) + [&] {
    std::string s;
    for (const auto &a : args) s += " '" + a + "'";
    return s;
  }() + " 2>&1";
  FILE *p = popen(cmd.c_str(), "r");
  if (!p) return -1;
  char buf[512];
  while (fgets(buf, sizeof buf, p)) *out += buf;
  const int st = pclose(p);
  return WIFEXITED(st) ? WEXITSTATUS(st) : -1;
}

struct Listener {
  int max_state = -1;
  bool engaged_motion = false;
  bool have_amcl = false;
  autodrive::pose2d_t amcl{};
  int laser_odom_msgs = 0;
  bool have_path = false;
  autodrive::path2d_t path{};
  void on_path(const lcm::ReceiveBuffer *, const std::string &, const autodrive::path2d_t *m) {
    have_path = true;
    path = *m;
  }
  autodrive::odometry_t laser_odom{};
  void on_laser_odom(const lcm::ReceiveBuffer *, const std::string &,
                     const autodrive::odometry_t *m) {
    ++laser_odom_msgs;
    laser_odom = *m;
  }
  void on_mission(const lcm::ReceiveBuffer *, const std::string &,
                  const autodrive::mission_status_t *m) {
    max_state = std::max<int>(max_state, m->state);
  }
  void on_cmd(const lcm::ReceiveBuffer *, const std::string &,
              const autodrive::vehicle_command_t *m) {
    if (m->engaged && std::abs(m->throttle) > 0.0f && std::abs(m->throttle) <= 1.0f)
      engaged_motion = true;
    last_cmd = *m;
  }
  autodrive::vehicle_command_t last_cmd{};
  void on_amcl(const lcm::ReceiveBuffer *, const std::string &, const autodrive::pose2d_t *m) {
    have_amcl = true;
    amcl = *m;
  }
};

}  // namespace

TEST(Program, HelpAndBadConfig) {
  std::string out;
  EXPECT_EQ(run_program({"--help"}, &out), 0);
  EXPECT_NE(out.find("--config"), std::string::npos);
  const fs::path bad =
      fs::temp_directory_path() / ("autonomy_bad_" + std::to_string(getpid()) + ".yaml");
  std::ofstream(bad) << "goal: {x_m: 1, y_m: 0, yaw_rad: 0}\nplanner: {wheelbase: 0.1}\n";
  out.clear();
  EXPECT_EQ(run_program({"--config", bad.string()}, &out), 2);
  EXPECT_NE(out.find(bad.string() + ": planner.wheelbase: unknown key"), std::string::npos) << out;
  // A figure of the car is refused with where it comes from instead.
  std::ofstream(bad) << "goal: {x_m: 1, y_m: 0, yaw_rad: 0}\nplanner: {wheelbase_m: 0.1}\n";
  out.clear();
  EXPECT_EQ(run_program({"--config", bad.string()}, &out), 2);
  EXPECT_NE(out.find("planner.wheelbase_m: is a figure of the car"), std::string::npos) << out;
  std::ofstream(bad) << "goal: {x_m: 1, y_m: 0, yaw_rad: 0}\nslam: {levels: many}\n";
  out.clear();
  EXPECT_EQ(run_program({"--config", bad.string()}, &out), 2);
  EXPECT_NE(out.find("slam.levels: bad value 'many'"), std::string::npos) << out;
  fs::remove(bad);
}

// Probe findings: a negative steering limit or footprint and a NaN goal were accepted; a huge
// map grid aborted with an uncaught bad_alloc. Each is refused, naming the key and the bound.
TEST(Program, OutOfRangeConfigValuesAreRefusedNamingTheKey) {
  const fs::path bad =
      fs::temp_directory_path() / ("autonomy_range_" + std::to_string(getpid()) + ".yaml");
  const std::pair<const char *, const char *> cases[] = {
      {"goal: {x_m: .nan, y_m: 0, yaw_rad: 0}\n", "goal.x_m: must be a finite number"},
      {"goal: {x_m: 1, y_m: 0, yaw_rad: 0}\nfootprint: {margin_m: -0.1}\n",
       "footprint.margin_m: -0.1 is out of range: must be 0..0.5"},
      {"goal: {x_m: 1, y_m: 0, yaw_rad: 0}\nplanner: {steer_use_fraction: -1}\n",
       "planner.steer_use_fraction: -1 is out of range"},
      {"goal: {x_m: 1, y_m: 0, yaw_rad: 0}\ncommand_rate_hz: 0\n", "command_rate_hz: must be"},
      {"goal: {x_m: 1, y_m: 0, yaw_rad: 0}\nslam: {resolution_m: 0.001, width_m: 900, height_m: "
       "900}\n",
       "slam: a grid of 900000 x 900000 cells"},
  };
  for (const auto &[yaml, expected] : cases) {
    std::ofstream(bad) << yaml;
    std::string out;
    EXPECT_EQ(run_program({"--config", bad.string()}, &out), 2) << yaml;
    EXPECT_NE(out.find(expected), std::string::npos) << yaml << " -> " << out;
  }
  fs::remove(bad);
}

TEST(Program, LocalisesPlansAndCommandsOverLcm) {
  const autodrive::synthetic_world::World world = autodrive::synthetic_world::World::parking_lot();
  const fs::path dir = fs::temp_directory_path() / ("autonomy_program_" + std::to_string(getpid()));
  fs::create_directories(dir);
  map_save(world.rasterize(0.02), (dir / "map.yaml").string());
  const Pose2 truth{1.8, 1.2, 0.0};
  std::ofstream(dir / "cfg.yaml") << "vehicle: NIGELT\nlcm_url: \"" << kUrl << "\"\n"
                                  << "out_dir: " << (dir / "out").string() << "\n"
                                  << "map: {load_from: " << (dir / "map.yaml").string() << "}\n"
                                  << "start: {x_m: 1.8, y_m: 1.2, yaw_rad: 0.0}\n"
                                  << "goal: {x_m: 2.45, y_m: 0.18, yaw_rad: 1.5707963}\n";
  // The car's key (mode 0600): the autonomy signs every command with it.
  const std::string key_file = (dir / "NIGELT.key").string();
  std::ofstream(key_file) << std::string(64, 'b') << "\n";
  fs::permissions(key_file, fs::perms::owner_read | fs::perms::owner_write,
                  fs::perm_options::replace);
  lcm::LCM lcm(kUrl);
  ASSERT_TRUE(lcm.good());
  Listener l;
  autodrive_lcm::subscribe<autodrive::mission_status_t, Listener, &Listener::on_mission>(
      lcm, "NIGELT_MISSION", &l);
  autodrive_lcm::subscribe<autodrive::vehicle_command_t, Listener, &Listener::on_cmd>(
      lcm, "NIGELT_COMMAND", &l);
  autodrive_lcm::subscribe<autodrive::pose2d_t, Listener, &Listener::on_amcl>(
      lcm, "NIGELT_POSE_AMCL", &l);
  autodrive_lcm::subscribe<autodrive::odometry_t, Listener, &Listener::on_laser_odom>(
      lcm, "NIGELT_LASER_ODOM", &l);
  autodrive_lcm::subscribe<autodrive::path2d_t, Listener, &Listener::on_path>(lcm, "NIGELT_PATH",
                                                                              &l);

  const pid_t pid = fork();
  ASSERT_GE(pid, 0);
  if (pid == 0) {
    const std::string cfg = (dir / "cfg.yaml").string();
    execl(AUTONOMY_PROGRAM, AUTONOMY_PROGRAM, "--config", cfg.c_str(), "--key-file",
          key_file.c_str(), static_cast<char *>(nullptr));
    _exit(127);
  }
  const Pose2 lidar{AUTODRIVE_VEHICLE_LIDAR_POS_M_X, 0, 0};
  // The car stands still: odometry at its origin, scans from the true pose, 100 Hz / 7 Hz of
  // message time; a bounded number of steps, never a wall-time assert.
  for (int i = 0; i < 6000 && !(l.max_state >= 4 && l.engaged_motion && l.have_amcl && l.have_path);
       ++i) {
    const int64_t t_us = 1000000 + static_cast<int64_t>(i) * 10000;
    autodrive::odometry_t o{};
    o.utime = t_us;
    o.vehicle = "NIGELT";
    o.frame_id = "odom";
    o.child_frame_id = "base_link";
    lcm.publish("NIGELT_ODOM", &o);
    if (i % 14 == 0) {
      const Scan s = world.scan(truth, lidar);
      autodrive::lidar_scan_t m{};
      m.utime = t_us;
      m.frame_id = "laser";
      m.angle_min_rad = static_cast<float>(s.angle_min_rad);
      m.angle_increment_rad = static_cast<float>(s.angle_increment_rad);
      m.angle_max_rad = static_cast<float>(s.angle_min_rad + 359 * s.angle_increment_rad);
      m.range_min_m = 0.15f;
      m.range_max_m = 12.0f;
      m.scan_time_s = 1.0f / 7.0f;
      m.num_ranges = 360;
      m.ranges_m = s.ranges_m;
      m.intensities.assign(360, 47.0f);
      lcm.publish("NIGELT_LIDAR", &m);
    }
    lcm.handleTimeout(10);
  }
  kill(pid, SIGTERM);
  int st = 0;
  waitpid(pid, &st, 0);
  EXPECT_GE(l.max_state, 4) << "never reached DRIVING";  // mission_status_t.DRIVING
  EXPECT_TRUE(l.engaged_motion) << "no engaged command with a throttle";
  EXPECT_EQ(l.last_cmd.source, "autonomy");
  EXPECT_EQ(autodrive::auth::check_mac(autodrive::auth::load_key(key_file), "NIGELT", l.last_cmd),
            autodrive::auth::MacCheck::ok)
      << "the autonomy's commands are not signed with the car's key";
  ASSERT_TRUE(l.have_amcl);
  EXPECT_NEAR(l.amcl.x_m, truth.x_m, 0.03);
  EXPECT_NEAR(l.amcl.y_m, truth.y_m, 0.03);
  EXPECT_EQ(static_cast<int>(l.amcl.source), static_cast<int>(autodrive::pose2d_t::SOURCE_AMCL));
  // Laser odometry, once per scan: the car stood still, so it stayed at its origin.
  EXPECT_GE(l.laser_odom_msgs, 8);
  EXPECT_EQ(l.laser_odom.frame_id, "laser_odom");
  EXPECT_LT(std::hypot(l.laser_odom.x_m, l.laser_odom.y_m), 0.005);
  // The plan, on NIGELT_PATH: from where the car stands to the goal.
  ASSERT_TRUE(l.have_path);
  EXPECT_EQ(l.path.purpose, "parking");
  EXPECT_GE(l.path.plan, 1);
  ASSERT_GE(l.path.num_poses, 2);
  EXPECT_NEAR(l.path.x_m.front(), truth.x_m, 0.05);
  EXPECT_NEAR(l.path.x_m.back(), 2.45, 1e-3);
  EXPECT_NEAR(l.path.y_m.back(), 0.18, 1e-3);
  EXPECT_TRUE(fs::exists(dir / "out" / "path.csv"));
  EXPECT_TRUE(WIFEXITED(st)) << "killed by a signal instead of exiting cleanly";
  fs::remove_all(dir);
}
