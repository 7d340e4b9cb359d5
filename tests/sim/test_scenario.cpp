// Scenario options of autodrive-sim: --start X,Y,YAW_DEG and --late-box X,Y,T[,SX,SY[,R]].
// The real program publishes on real LCM UDP multicast (loopback, ttl=0, ports 7750-7752):
// ground truth at the start pose; a late box that the LIDAR sees only after its time and that
// sets the collision flag when driven into; bad values exit 2 naming the option. In-process:
// a reset returns to the start pose and keeps the box; the front camera (sensors library's
// renderer) sees the box only after its time.
#include <gtest/gtest.h>
#include <lcm/lcm.h>
#include <math.h>
#include <signal.h>
#include <stdio.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "autodrive_ground_truth_t.h"
#include "autodrive_lidar_scan_t.h"
#include "scenario.h"
#include "sim_test_util.h"
#include "vehicle_params.h"

#include "sim_camera.h"
#include "sim_render.h"

namespace {

constexpr double kDeg = M_PI / 180.0;
constexpr double kCarSpacingM = 0.35;  // cars 2..N line up to car 1's right at this pitch

// A map's facts from its JSON sidecar (generated from maps/<map>.yaml).
const nlohmann::json &map_facts(const std::string &name) {
  static std::map<std::string, nlohmann::json> cache;
  auto it = cache.find(name);
  if (it == cache.end()) {
    const std::string path = std::string(MAPS_DIR) + "/" + name + ".json";
    std::ifstream f(path);
    if (!f) throw std::runtime_error(path + ": cannot read the map sidecar");
    it = cache.emplace(name, nlohmann::json::parse(f)).first;
  }
  return it->second;
}

// The named entry of a list in the parking school's sidecar (walls, boxes...).
const nlohmann::json &parking(const char *list, const char *name) {
  for (const auto &e : map_facts("parking_school").at(list))
    if (e.at("name") == name) return e;
  throw std::runtime_error(std::string("parking_school.json: no ") + list + " '" + name + "'");
}

std::string xy(double x, double y) {
  char buf[64];
  snprintf(buf, sizeof buf, "%g,%g", x, y);
  return buf;
}

std::string url(int port) {
  return "udpm://239.255.76.67:" + std::to_string(port) + "?ttl=0";
}

std::string slurp(const std::string &path) {
  std::ifstream f(path);
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

double wrap(double a) {
  return atan2(sin(a), cos(a));
}

struct Truth {
  int64_t utime;
  double x, y, yaw;
  bool collision;
};
struct Scan {
  int64_t utime;
  double scan_time_s;
  std::vector<float> ranges;
};

// Runs the real sim binary with args on an LCM url and collects what it publishes.
struct SimRun {
  std::vector<Truth> truth[3];  // index: car 1, 2
  std::vector<Scan> scans;      // NIGEL1_LIDAR
  std::string out;              // stdout + stderr
  int status = -1;
  bool no_route = false;

  static void on_truth(const lcm_recv_buf_t *, const char *ch, const autodrive_ground_truth_t *m,
                       void *u) {
    const int car = ch[5] - '0';  // "NIGEL<car>_GROUND_TRUTH"
    if (car >= 1 && car <= 2)
      static_cast<SimRun *>(u)->truth[car].push_back(
          {m->utime, m->position_m[0], m->position_m[1], m->yaw_rad, m->in_collision != 0});
  }
  static void on_scan(const lcm_recv_buf_t *, const char *, const autodrive_lidar_scan_t *m,
                      void *u) {
    static_cast<SimRun *>(u)->scans.push_back(
        {m->utime, m->scan_time_s, std::vector<float>(m->ranges_m, m->ranges_m + m->num_ranges)});
  }

  SimRun(int port, const std::string &args) {
    lcm_t *lcm = lcm_create(url(port).c_str());
    if (!lcm) {  // no multicast route on this machine (docs/INTERFACES.md)
      no_route = true;
      return;
    }
    autodrive_ground_truth_t_subscription_t *sub_truth =
        autodrive_ground_truth_t_subscribe(lcm, "NIGEL._GROUND_TRUTH", on_truth, this);
    autodrive_lidar_scan_t_subscription_t *sub_scan =
        autodrive_lidar_scan_t_subscribe(lcm, "NIGEL1_LIDAR", on_scan, this);
    const std::string dir = simtest::temp_dir(), log = dir + "/out.txt";
    const std::string cmd = std::string(SIM_BIN) + " --quiet --no-pty --lcm-url '" + url(port) +
                            "' --run-dir " + dir + " " + args + " >" + log + " 2>&1";
    const pid_t pid = fork();
    if (pid == 0) {
      execl("/bin/sh", "sh", "-c", cmd.c_str(), (char *)nullptr);
      _exit(127);
    }
    int st = 0, idle = 0;
    bool done = false;
    // receive while it runs, then until the bus has been quiet for 0.5 s (not an assertion)
    while (!done || idle < 5) {
      if (!done && waitpid(pid, &st, WNOHANG) == pid) done = true;
      const int n = lcm_handle_timeout(lcm, 100);
      idle = (n == 0 && done) ? idle + 1 : 0;
    }
    status = WIFEXITED(st) ? WEXITSTATUS(st) : -1;
    out = slurp(log);
    unlink(log.c_str());
    rmdir(dir.c_str());
    autodrive_ground_truth_t_unsubscribe(lcm, sub_truth);
    autodrive_lidar_scan_t_unsubscribe(lcm, sub_scan);
    lcm_destroy(lcm);
  }
};

// Exit status and output of the program run with args (no LCM traffic: memq).
std::pair<int, std::string> run_cli(const std::string &args) {
  const std::string dir = simtest::temp_dir();
  const std::string cmd = std::string(SIM_BIN) + " --lockstep --duration 0.05 --no-pty --quiet " +
                          "--lcm-url memq:// --run-dir " + dir + " " + args + " 2>&1";
  std::string out;
  FILE *p = popen(cmd.c_str(), "r");
  if (!p) return {-1, ""};
  char buf[512];
  size_t n;
  while ((n = fread(buf, 1, sizeof buf, p)) > 0) out.append(buf, n);
  const int st = pclose(p);
  rmdir(dir.c_str());
  return {WIFEXITED(st) ? WEXITSTATUS(st) : -1, out};
}

vehicle_params_t params() {
  vehicle_params_t p;
  char err[512] = "";
  EXPECT_EQ(vehicle_params_load(simtest::params_path().c_str(), &p, err, sizeof err), 0) << err;
  return p;
}

// Distance along the unit ray (ox, oy) + t (dx, dy) to an axis-aligned box, or -1.
double ray_box(double ox, double oy, double dx, double dy, double cx, double cy, double hx,
               double hy) {
  double lo = 0.0, hi = 1e9;
  const double o[2] = {ox, oy}, d[2] = {dx, dy}, c[2] = {cx, cy}, h[2] = {hx, hy};
  for (int k = 0; k < 2; k++) {
    if (fabs(d[k]) < 1e-12) {
      if (fabs(o[k] - c[k]) > h[k]) return -1;
      continue;
    }
    double t0 = (c[k] - h[k] - o[k]) / d[k], t1 = (c[k] + h[k] - o[k]) / d[k];
    if (t0 > t1) std::swap(t0, t1);
    lo = fmax(lo, t0);
    hi = fmin(hi, t1);
  }
  return lo <= hi ? lo : -1;
}

// Distance along the ray to the parking school's walls (planes at their inner faces).
double ray_walls(double ox, double oy, double dx, double dy) {
  double best = 1e9;
  for (const auto &w : map_facts("parking_school").at("walls")) {
    const double cx = w["face_centre_m"][0], cy = w["face_centre_m"][1];
    const double nx = w["normal"][0], ny = w["normal"][1];
    const double towards = dx * nx + dy * ny;  // < 0: the ray runs into the face
    if (towards < -1e-12) best = fmin(best, ((cx - ox) * nx + (cy - oy) * ny) / towards);
  }
  return best;
}

TEST(Scenario, ParsesStartAndLateBoxValues) {
  char err[512];
  scn_pose_t p;
  ASSERT_EQ(scn_parse_start("-1.5,0.25,-90", &p, err, sizeof err), 0) << err;
  EXPECT_DOUBLE_EQ(p.x_m, -1.5);
  EXPECT_DOUBLE_EQ(p.y_m, 0.25);
  EXPECT_DOUBLE_EQ(p.yaw_deg, -90);
  scn_late_box_t b;
  ASSERT_EQ(scn_parse_late_box("0.5,0.6,10", &b, err, sizeof err), 0) << err;
  EXPECT_DOUBLE_EQ(b.t_s, 10);
  EXPECT_DOUBLE_EQ(b.half_x_m, SCN_LATE_BOX_HALF_DEFAULT_M);
  EXPECT_DOUBLE_EQ(b.half_y_m, SCN_LATE_BOX_HALF_DEFAULT_M);
  ASSERT_EQ(scn_parse_late_box("0.5,0.6,10,0.2,0.03", &b, err, sizeof err), 0) << err;
  EXPECT_DOUBLE_EQ(b.half_x_m, 0.2);
  EXPECT_DOUBLE_EQ(b.half_y_m, 0.03);
  EXPECT_DOUBLE_EQ(b.near_m, 0.0);
  ASSERT_EQ(scn_parse_late_box("0.5,0.6,10,0.06,0.06,0.4", &b, err, sizeof err), 0) << err;
  EXPECT_DOUBLE_EQ(b.near_m, 0.4);
  for (const char *bad :
       {"", "1,2", "1,2,3,4", "1,,3", "1,2,3x", "nan,0,0", "0,0,361", "1e9,0,0"}) {
    EXPECT_EQ(scn_parse_start(bad, &p, err, sizeof err), -1) << bad;
    EXPECT_NE(std::string(err).find("--start"), std::string::npos) << err;
  }
  for (const char *bad : {"1,2", "1,2,3,4", "1,2,-1", "1,2,3,0,0.1", "1,2,3,0.1,5", "a,2,3",
                          "1,2,3,0.1,0.1,0", "1,2,3,0.1,0.1,0.3,1"}) {
    EXPECT_EQ(scn_parse_late_box(bad, &b, err, sizeof err), -1) << bad;
    EXPECT_NE(std::string(err).find("--late-box"), std::string::npos) << err;
  }
}

TEST(Scenario, BadStartAndLateBoxValuesExit2NamingTheOption) {
  struct Case {
    std::string args;
    const char *option, *detail;
  };
  // map facts from the sidecar: poses on a box, through a wall, off the floor
  const auto &box_a = parking("boxes", "box_a")["centre_m"];
  const double wall_e_x = parking("walls", "wall_e")["face_centre_m"][0];
  const double wall_n_y = parking("walls", "wall_n")["face_centre_m"][1];
  const double wall_s_y = parking("walls", "wall_s")["face_centre_m"][1];
  const double driving_half_m = map_facts("driving_school")["floor"]["half_size_m"];
  const Case cases[] = {
      {"--start 1,2", "--start", "1,2"},
      {"--start north,0,0", "--start", "north"},
      {"--start", "--start", "missing"},
      {"--start " + xy(box_a[0], box_a[1]) + ",0", "--start", "box_a"},    // on the map's box
      {"--start " + xy(wall_e_x - 0.075, 0) + ",0", "--start", "wall_e"},  // nose through it
      {"--map driving_school --start " + xy(driving_half_m + 1, 0) + ",0", "--start", "floor"},
      // car 3 (2 pitches to car 1's right) through the south wall
      {"--cars 3 --start " + xy(-1, wall_s_y + 2 * kCarSpacingM - 0.225) + ",0", "--start",
       "NIGEL3"},
      {"--late-box 0.5,0.6", "--late-box", "0.5,0.6"},
      {"--late-box 0.5,0.6,-2", "--late-box", "T [s]"},
      {"--late-box " + xy(box_a[0], box_a[1]) + ",3", "--late-box", "box_a"},
      {"--late-box " + xy(0, wall_n_y - 0.025) + ",1,0.1,0.1", "--late-box", "wall_n"},
      {"--late-box 0,0,1 --late-box 0,0.5,1 --late-box 0,1,1 --late-box 0.5,0,1 --late-box "
       "0.5,0.5,1",
       "--late-box", "at most 4"},
  };
  for (const Case &c : cases) {
    const auto r = run_cli(c.args);
    EXPECT_EQ(r.first, 2) << c.args << ": " << r.second;
    EXPECT_NE(r.second.find(c.option), std::string::npos) << c.args << ": " << r.second;
    EXPECT_NE(r.second.find(c.detail), std::string::npos) << c.args << ": " << r.second;
  }
  // good values still run
  const auto ok = run_cli("--start -1.2,-0.6,-120 --cars 2 --late-box 0.5,0.6,0.01,0.1,0.05");
  EXPECT_EQ(ok.first, 0) << ok.second;
  EXPECT_NE(ok.second.find("late box 1 appeared"), std::string::npos) << ok.second;
}

TEST(Scenario, StartPutsGroundTruthAtThePoseAndCar2BesideIt) {
  const double x = -1.2, y = -0.6, yaw_deg = -120;
  SimRun r(7750, "--rtf 5 --duration 1.5 --cars 2 --start -1.2,-0.6,-120");
  if (r.no_route) GTEST_SKIP() << "no multicast route for " << url(7750);
  ASSERT_EQ(r.status, 0) << r.out;
  const double yaw = yaw_deg * kDeg;
  const double x2 = x + kCarSpacingM * sin(yaw), y2 = y - kCarSpacingM * cos(yaw);
  const double want[3][2] = {{0, 0}, {x, y}, {x2, y2}};
  for (int car = 1; car <= 2; car++) {
    int settled = 0;
    double worst_m = 0.0, worst_deg = 0.0;
    for (const Truth &t : r.truth[car]) {
      if (t.utime < 1000000) continue;  // after 1 s of sim time the car rests on its tyres
      settled++;
      worst_m = fmax(worst_m, hypot(t.x - want[car][0], t.y - want[car][1]));
      worst_deg = fmax(worst_deg, fabs(wrap(t.yaw - yaw)) / kDeg);
      EXPECT_NEAR(t.x, want[car][0], 0.005) << "car " << car << " at " << t.utime << " us";
      EXPECT_NEAR(t.y, want[car][1], 0.005) << "car " << car << " at " << t.utime << " us";
      EXPECT_NEAR(wrap(t.yaw - yaw), 0.0, 0.5 * kDeg) << "car " << car;
      EXPECT_FALSE(t.collision) << "car " << car;
    }
    EXPECT_GE(settled, 10) << "car " << car << ": too few ground-truth messages received";
    printf("NIGEL%d: %d settled messages, worst error %.2f mm, %.3f deg\n", car, settled,
           worst_m * 1e3, worst_deg);
  }
  EXPECT_NE(r.out.find("NIGEL1 start (--start)"), std::string::npos) << r.out;
}

TEST(Scenario, LidarSeesTheLateBoxOnlyAfterItsTime) {
  // car 1 at yaw 20 deg; the box 1 m from the scanner at a bearing of +25 deg (world 45 deg),
  // where the far wall is ~6.3 m away; half sizes 0.08 x 0.05 m
  const vehicle_params_t p = params();
  const double cx = -1.0, cy = -0.5, yaw = 20 * kDeg, t_box_s = 1.0;
  const double ox = cx + p.lidar_pos_m[0] * cos(yaw), oy = cy + p.lidar_pos_m[0] * sin(yaw);
  const double bx = ox + cos(45 * kDeg), by = oy + sin(45 * kDeg), hx = 0.08, hy = 0.05;
  char box[128];
  snprintf(box, sizeof box, "%.4f,%.4f,%.1f,%.2f,%.2f", bx, by, t_box_s, hx, hy);
  SimRun r(7751, std::string("--rtf 5 --duration 2.2 --start -1,-0.5,20 --late-box ") + box);
  if (r.no_route) GTEST_SKIP() << "no multicast route for " << url(7751);
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_NE(r.out.find("late box 1 appeared at t = 1.000 s"), std::string::npos) << r.out;
  ASSERT_FALSE(r.truth[1].empty());
  // the scanner where the car really rests
  const Truth &t = r.truth[1].back();
  const double sx = t.x + p.lidar_pos_m[0] * cos(t.yaw), sy = t.y + p.lidar_pos_m[0] * sin(t.yaw);
  const int ray = ((int)lround(wrap(atan2(by - sy, bx - sx) - t.yaw) / kDeg) + 360) % 360;
  const double a = t.yaw + ray * kDeg;
  const double want_box = ray_box(sx, sy, cos(a), sin(a), bx, by, hx, hy);
  const double want_wall = ray_walls(sx, sy, cos(a), sin(a));
  ASSERT_GT(want_box, 0.5) << "ray " << ray << " misses the box";
  EXPECT_EQ(ray, 25);
  int before = 0, after = 0;
  double worst_before = 0.0, worst_after = 0.0;
  for (const Scan &s : r.scans) {
    ASSERT_EQ(s.ranges.size(), 360u);
    const double t_ray_s = s.utime * 1e-6 + s.scan_time_s * ray / 360.0;
    if (s.utime * 1e-6 + s.scan_time_s < t_box_s) {  // the whole scan before the box
      before++;
      EXPECT_NEAR(s.ranges[ray], want_wall, 0.03) << "scan at " << s.utime << " us";
      worst_before = fmax(worst_before, fabs(s.ranges[ray] - want_wall));
    } else if (t_ray_s > t_box_s + 0.002) {
      after++;
      EXPECT_NEAR(s.ranges[ray], want_box, 0.03) << "scan at " << s.utime << " us";
      worst_after = fmax(worst_after, fabs(s.ranges[ray] - want_box));
    }
  }
  printf(
      "ray %d: wall %.3f m expected, %d scans before within %.1f mm; box %.3f m expected, "
      "%d scans after within %.1f mm\n",
      ray, want_wall, before, worst_before * 1e3, want_box, after, worst_after * 1e3);
  EXPECT_GE(before, 2) << "too few scans received before the box";
  EXPECT_GE(after, 2) << "too few scans received after the box";
}

TEST(Scenario, DrivingIntoTheLateBoxSetsTheCollisionFlag) {
  // full throttle from x = -1 (front bumper at about -0.81 m) towards a box at -0.6 that
  // appears at 0.3 s, when the car has covered < 0.08 m
  const vehicle_params_t p = params();
  const double face_x = -0.6 - 0.06, t_box_s = 0.3;
  SimRun r(7752,
           "--rtf 5 --duration 3 --start -1,-0.5,0 --late-box -0.6,-0.5,0.3 "
           "--script constant:throttle=1,steering=0");
  if (r.no_route) GTEST_SKIP() << "no multicast route for " << url(7752);
  ASSERT_EQ(r.status, 0) << r.out;
  ASSERT_FALSE(r.truth[1].empty());
  int hits = 0;
  double max_x = -1e9;
  for (const Truth &t : r.truth[1]) {
    if (t.utime < t_box_s * 1e6) {
      EXPECT_FALSE(t.collision) << "before the box, at " << t.utime;
    }
    hits += t.collision;
    max_x = fmax(max_x, t.x);
  }
  printf(
      "%d of %zu ground-truth messages in collision; car front at most %.4f m, box face %.4f m\n",
      hits, r.truth[1].size(), max_x + p.chassis_offset_m[0] + 0.5 * p.chassis_size_m[0], face_x);
  EXPECT_GE(hits, 10) << "the chassis never touched the box";
  // the box stopped the car: its front (chassis box) never got past the box's face
  const double front = p.chassis_offset_m[0] + 0.5 * p.chassis_size_m[0];
  EXPECT_LT(max_x + front, face_x + 0.01);
  EXPECT_GT(max_x + front, face_x - 0.02) << "the car did not reach the box";
}

// A sim core with car 1 at start and one late box (in-process, no ptys, no LIDAR).
struct ScenarioSim {
  std::string dir = simtest::temp_dir(), prm = simtest::params_path(), map;
  sim_t *s = nullptr;
  std::string err;
  ScenarioSim(const scn_pose_t &start, const scn_late_box_t &box,
              const char *map_name = "parking_school", int boxes = 1)
      : map(simtest::map_path(map_name)) {
    sim_config_t cfg = {};
    cfg.params_path = prm.c_str();
    cfg.map_path = map.c_str();
    cfg.run_dir = dir.c_str();
    cfg.cars = 1;
    cfg.seed = 1;
    cfg.tyre_model = -1;
    cfg.start = &start;
    cfg.late_boxes = boxes;
    cfg.late_box = boxes ? &box : nullptr;
    char e[1024] = "";
    s = sim_create(&cfg, e, sizeof e);
    if (s && sim_check_scenario(s, e, sizeof e) != 0) {
      sim_destroy(s);
      s = nullptr;
    }
    err = e;
  }
  ~ScenarioSim() {
    sim_destroy(s);
    rmdir(dir.c_str());
  }
  // steps to t_s; returns how often box k appeared, -1 on error
  int run_to(double t_s, int k = 0) {
    int appeared = 0;
    char e[512];
    while (sim_time_us(s) < (int64_t)llround(t_s * 1e6)) {
      if (sim_step(s, e, sizeof e) != 0) {
        err = e;
        return -1;
      }
      appeared += sim_late_box_appeared(s, k, nullptr);
    }
    return appeared;
  }
};

TEST(Scenario, ResetReturnsToTheStartPoseAndKeepsAppearedBoxes) {
  const scn_pose_t start = {0.4, -2.0, 90.0};
  const scn_late_box_t box = {0.4, -1.65, 0.2, 0.06, 0.06, 0.0, 0.0, 0.0, "", 0.0};
  ScenarioSim k(start, box);
  ASSERT_NE(k.s, nullptr) << k.err;
  ASSERT_EQ(k.run_to(0.5), 1) << k.err;
  mjData *d = sim_data(k.s);
  const mjModel *m = sim_model(k.s);
  const int geom = mj_name2id(m, mjOBJ_GEOM, "scenario/late_box1");
  ASSERT_GE(geom, 0);
  const mjtNum *box_pos = d->geom_xpos + 3 * geom;
  EXPECT_NEAR(box_pos[0], 0.4, 1e-12);
  EXPECT_NEAR(box_pos[1], -1.65, 1e-12);
  EXPECT_NEAR(box_pos[2], 0.5 * SCN_LATE_BOX_HEIGHT_M, 1e-12);
  d->qpos[0] += 0.3;  // pick the car up and put it elsewhere, then reset (the viewer's R)
  mj_resetData(m, d);
  mj_forward(m, d);
  const sim_truth_t t = [&] {
    sim_truth_t x;
    sim_get_truth(k.s, 1, &x);
    return x;
  }();
  EXPECT_NEAR(t.pos_m[0], 0.4, 1e-9);
  EXPECT_NEAR(t.pos_m[1], -2.0, 1e-9);
  EXPECT_NEAR(wrap(t.yaw_rad - 90 * kDeg), 0.0, 1e-9);
  ASSERT_EQ(k.run_to(0.6), 0) << "appeared twice";
  EXPECT_NEAR(box_pos[2], 0.5 * SCN_LATE_BOX_HEIGHT_M, 1e-12) << "box not back after the reset";
}

// With R, a box waits past its time until car 1 comes within R m, like one stepping out.
TEST(Scenario, ALateBoxWithADistanceWaitsForTheCarToComeNear) {
  const scn_pose_t start = {0.4, -2.0, 90.0};
  scn_late_box_t box = {0.4, -1.65, 0.1, 0.06, 0.06, 0.0, 0.0, 0.0, "", 0.0};
  box.near_m = 0.25;  // the car starts 0.35 m away
  ScenarioSim k(start, box);
  ASSERT_NE(k.s, nullptr) << k.err;
  ASSERT_EQ(k.run_to(0.5), 0) << "appeared with the car 0.35 m away; " << k.err;
  mjData *d = sim_data(k.s);
  const mjModel *m = sim_model(k.s);
  const mjtNum *box_pos = d->geom_xpos + 3 * mj_name2id(m, mjOBJ_GEOM, "scenario/late_box1");
  EXPECT_LT(box_pos[2], -1000.0) << "still parked out of sight";
  d->qpos[1] += 0.15;  // move the car 0.15 m towards it: 0.2 m away
  mj_forward(m, d);
  ASSERT_EQ(k.run_to(0.6), 1) << k.err;
  EXPECT_NEAR(box_pos[2], 0.5 * SCN_LATE_BOX_HEIGHT_M, 1e-12);
  d->qpos[1] -= 0.5;  // once there, it stays when the car leaves
  mj_forward(m, d);
  ASSERT_EQ(k.run_to(0.7), 0) << k.err;
  EXPECT_NEAR(box_pos[2], 0.5 * SCN_LATE_BOX_HEIGHT_M, 1e-12);
}

// A box with a stay leaves again: back where it waited (in the physics and the render model),
// reported once, and no longer in the way of a ray along the floor.
TEST(Scenario, ALateBoxWithAStayLeavesAgain) {
  scn_late_box_t box = {0.4, -1.65, 0.1, 0.06, 0.06, 0.0, 0.0, 0.0, "", 0.0};
  box.stay_s = 0.2;  // appears at 0.1 s, leaves at 0.3 s
  ScenarioSim k({0.4, -2.0, 90.0}, box);
  ASSERT_NE(k.s, nullptr) << k.err;
  mjData *d = sim_data(k.s);
  const mjModel *m = sim_model(k.s);
  const int geom = mj_name2id(m, mjOBJ_GEOM, "scenario/late_box1");
  ASSERT_GE(geom, 0);
  ASSERT_EQ(k.run_to(0.2), 1) << k.err;
  EXPECT_NEAR(d->geom_xpos[3 * geom + 2], 0.5 * SCN_LATE_BOX_HEIGHT_M, 1e-12);
  int left = 0;
  char e[512];
  while (sim_time_us(k.s) < 400000) {
    ASSERT_EQ(sim_step(k.s, e, sizeof e), 0) << e;
    left += sim_late_box_left(k.s, 0);
  }
  EXPECT_EQ(left, 1) << "the box left once";
  EXPECT_LT(d->geom_xpos[3 * geom + 2], -1000.0) << "back out of sight";
  const mjModel *mv = sim_render_model(k.s);
  const int gv = mj_name2id(mv, mjOBJ_GEOM, "scenario/late_box1");
  ASSERT_GE(gv, 0);
  EXPECT_LT(sim_render_data(k.s)->geom_xpos[3 * gv + 2], -1000.0) << "the cameras lost it too";
}

TEST(Scenario, FrontCameraSeesTheLateBoxOnlyAfterItsTime) {
  // in-process: the sim core with a late box 0.5 m ahead of car 1, appearing at 0.2 s
  ScenarioSim k({-1.0, -0.5, 0.0}, {-0.33, -0.5, 0.2, 0.06, 0.06, 0.0, 0.0, 0.0, "", 0.0});
  ASSERT_NE(k.s, nullptr) << k.err;
  sim_t *s = k.s;
  const mjModel *m = sim_render_model(s);
  char err[1024] = "";
  sim_render_t *rd = sim_render_create(m, 640, 480, SIM_RENDER_AUTO, err, sizeof err);
  ASSERT_NE(rd, nullptr) << err;
  sim_camera_t *cam =
      sim_camera_create(rd, m, "nigel1/cam_front", "camera_front", 640, 480, 85, err, sizeof err);
  ASSERT_NE(cam, nullptr) << err;
  auto centre_blue_excess = [&]() {  // blue minus red at the image centre (the box is blue)
    EXPECT_EQ(sim_camera_capture(cam, m, sim_render_data(s), sim_time_us(s)), 0);
    const uint8_t *px = sim_camera_rgb(cam) + 3 * (240 * 640 + 320);
    return (int)px[2] - (int)px[0];
  };
  int appeared = k.run_to(0.15);
  EXPECT_EQ(appeared, 0);
  const int before = centre_blue_excess();
  appeared += k.run_to(0.25);
  EXPECT_EQ(appeared, 1);
  const int after = centre_blue_excess();
  printf("image centre blue - red: %d before the box, %d after\n", before, after);
  EXPECT_LT(before, 30) << "the box is visible before its time";
  EXPECT_GT(after, 60) << "the camera does not see the box";
  sim_camera_destroy(cam);
  sim_render_destroy(rd);
}

// The map's late_obstacles (Tiny Town: late_box_1 at x -4.34, y 0.6 m, 0.15 x 0.15 x 0.2 m,
// appearing at 20 s; late_box_0 when a car comes within 0.8 m): the sim adds them after the
// --late-box ones, in the physics model (a ray at 7 cm height hits it only from its time on) and in
// the render model. A sensor ray or a collision before that time finds nothing there.
TEST(Scenario, TheMapsLateObstaclesAppearAtTheirTime) {
  ScenarioSim k({-1.0, -0.5, 0.0}, scn_late_box_t{}, "tiny_town", 0);
  ASSERT_NE(k.s, nullptr) << k.err;
  ASSERT_EQ(sim_late_boxes(k.s), 2);
  int timed = -1, near = -1;
  for (int i = 0; i < 2; i++) {
    const scn_late_box_t *b = sim_late_box(k.s, i);
    if (std::string(b->name) == "late_box_1") timed = i;
    if (std::string(b->name) == "late_box_0") near = i;
  }
  ASSERT_GE(timed, 0);
  ASSERT_GE(near, 0);
  const scn_late_box_t *b = sim_late_box(k.s, timed);
  EXPECT_NEAR(b->x_m, -4.34, 1e-9);
  EXPECT_NEAR(b->y_m, 0.6, 1e-9);
  EXPECT_NEAR(b->t_s, 20.0, 1e-9);
  EXPECT_NEAR(b->half_z_m, 0.1, 1e-9);  // 0.2 m tall: the LIDAR sees it
  EXPECT_NEAR(sim_late_box(k.s, near)->near_m, 0.8, 1e-9);
  const mjModel *m = sim_model(k.s);
  mjData *d = sim_data(k.s);
  const mjtNum from[3] = {b->x_m - 0.5, b->y_m, 0.07}, dir[3] = {1, 0, 0};
  auto hit_m = [&] {  // what a sensor ray towards the box finds, as the LIDAR casts [m]
    int geom = -1;
    const mjtNum r = mj_ray(m, d, from, dir, NULL, 1, -1, &geom);
    return r < 0 ? 1e9 : r;
  };
  ASSERT_EQ(k.run_to(19.9, timed), 0) << k.err;
  EXPECT_GT(hit_m(), 0.5) << "the box is there before its time";
  ASSERT_EQ(k.run_to(20.1, timed), 1) << k.err;
  EXPECT_NEAR(hit_m(), 0.5 - 0.075, 0.002) << "the box did not appear at its place";
  // the render model shows it too (cameras and the Eye)
  const mjModel *mv = sim_render_model(k.s);
  const int geom =
      mj_name2id(mv, mjOBJ_GEOM, ("scenario/late_box" + std::to_string(timed + 1)).c_str());
  ASSERT_GE(geom, 0);
  EXPECT_NEAR(sim_render_data(k.s)->geom_xpos[3 * geom + 0], -4.34, 1e-9);
  // the car never came within 0.8 m of late_box_0: it is still out of sight
  const int ngeom =
      mj_name2id(m, mjOBJ_GEOM, ("scenario/late_box" + std::to_string(near + 1)).c_str());
  ASSERT_GE(ngeom, 0);
  EXPECT_LT(d->geom_xpos[3 * ngeom + 2], -1000.0);
}

}  // namespace
