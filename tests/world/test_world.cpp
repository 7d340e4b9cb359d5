// The world side of the simulator (ctest prefix "world."): every map loads and steps, the route
// driver keeps its lane, traffic lights are lit in rendered frames and refuse conflicting
// commands, signs are visible, camera noise, blur, exposure, light colour, mount jitter and
// distractors. In-process, real MuJoCo and rendering.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "camera_fx.h"
#include "route.h"
#include <autodrive/pure_pursuit.h>
#include "route_driver.h"
#include "sim.h"
#include "sim_camera.h"
#include "sim_render.h"
#include "sim_test_util.h"
#include "traffic_lights.h"

namespace {

const char *const kMaps[] = {"parking_school", "driving_school", "intersection_school",
                             "tiny_town"};

nlohmann::json sidecar(const char *map) {
  std::ifstream f(std::string(MAPS_DIR) + "/" + map + ".json");
  return nlohmann::json::parse(f);
}

// A sim on map with car 1 at a start pose (or the map's spawn) and an optional script.
struct WorldSim {
  sim_t *s = nullptr;
  std::string run_dir, err, params, map;
  scn_pose_t start{};
  WorldSim(const char *map_name, const scn_pose_t *pose, const char *script = nullptr,
           int distractors = 0, uint64_t seed = 1, const scn_pose_t *keep_clear = nullptr) {
    run_dir = simtest::temp_dir();
    params = simtest::params_path();
    map = simtest::map_path(map_name);
    sim_config_t cfg = {};
    cfg.params_path = params.c_str();
    cfg.map_path = map.c_str();
    cfg.run_dir = run_dir.c_str();
    cfg.cars = 1;
    cfg.seed = seed;
    cfg.script = script;
    cfg.distractors = distractors;
    cfg.distractor_keep_clear = keep_clear ? 1 : 0;
    cfg.distractor_keep_clear_pose = keep_clear;
    cfg.tyre_model = -1;
    if (pose) {
      start = *pose;
      cfg.start = &start;
    }
    char e[2048] = "";
    s = sim_create(&cfg, e, sizeof e);
    err = e;
  }
  ~WorldSim() {
    sim_destroy(s);
    rmdir(run_dir.c_str());
  }
  bool run_to(double t_s) {
    char e[512];
    while (sim_time_us(s) < (int64_t)llround(t_s * 1e6))
      if (sim_step(s, e, sizeof e) != 0) {
        err = e;
        return false;
      }
    return true;
  }
};

// Pixel (column, row) of world point p in camera cam_id (MuJoCo: looks along -z, y up).
bool project(const mjModel *m, const mjData *d, int cam_id, const double p[3], int w, int h,
             double *u, double *v) {
  const mjtNum *c = d->cam_xpos + 3 * cam_id, *R = d->cam_xmat + 9 * cam_id;
  double rel[3] = {p[0] - c[0], p[1] - c[1], p[2] - c[2]}, loc[3];
  for (int i = 0; i < 3; i++) loc[i] = R[i] * rel[0] + R[3 + i] * rel[1] + R[6 + i] * rel[2];
  const double depth = -loc[2];
  if (depth <= 0) return false;
  const double f = 0.5 * h / tan(0.5 * m->cam_fovy[cam_id] * M_PI / 180.0);
  *u = 0.5 * (w - 1) + f * loc[0] / depth;
  *v = 0.5 * (h - 1) - f * loc[1] / depth;
  return *u >= 0 && *u < w && *v >= 0 && *v < h;
}

// Mean RGB in a (2r+1)^2 window around (u, v).
std::vector<double> mean_rgb(const uint8_t *rgb, int w, int h, double u, double v, int r) {
  std::vector<double> acc(3, 0.0);
  int n = 0;
  for (int y = (int)v - r; y <= (int)v + r; y++)
    for (int x = (int)u - r; x <= (int)u + r; x++) {
      if (x < 0 || y < 0 || x >= w || y >= h) continue;
      for (int c = 0; c < 3; c++) acc[c] += rgb[3 * (y * w + x) + c];
      n++;
    }
  for (double &a : acc) a /= n > 0 ? n : 1;
  return acc;
}

// Car 1's pose facing the thing at (x, y) whose face points along yaw, dist metres from it.
scn_pose_t facing(double x, double y, double face_yaw, double dist) {
  scn_pose_t p{};
  p.x_m = x + dist * cos(face_yaw);
  p.y_m = y + dist * sin(face_yaw);
  p.yaw_deg = (face_yaw + M_PI) * 180.0 / M_PI;
  return p;
}

class EveryMap : public ::testing::TestWithParam<const char *> {};

TEST_P(EveryMap, LoadsAndSteps10sWithoutAMujocoWarning) {
  WorldSim k(GetParam(), nullptr);
  ASSERT_NE(k.s, nullptr) << k.err;
  ASSERT_TRUE(k.run_to(10.0)) << k.err;
  const mjData *d = sim_data(k.s);
  for (int w = 0; w < mjNWARNING; w++)
    EXPECT_EQ(d->warning[w].number, 0) << GetParam() << ": MuJoCo warning " << w;
}
INSTANTIATE_TEST_SUITE_P(World, EveryMap, ::testing::ValuesIn(kMaps));

// Drives a route to its end at 0.8 of top speed; the cross-track error stays within 3 cm.
void drive_route(const char *map, const char *route) {
  const std::string script = std::string("route:") + route + ",speed=0.8";
  WorldSim k(map, nullptr, script.c_str());
  ASSERT_NE(k.s, nullptr) << k.err;
  const route_driver_t *r = sim_route(k.s);
  ASSERT_NE(r, nullptr);
  const double t_end = r->path.length_m / (0.8 * 0.267) * 1.5 + 2.0;
  char e[512];
  while (!r->st.done && sim_time_us(k.s) < (int64_t)(t_end * 1e6))
    ASSERT_EQ(sim_step(k.s, e, sizeof e), 0) << e;
  double rms, max;
  const long n = route_driver_stats(r, &rms, &max);
  printf("%s %s: %.2f m in %.1f s, %ld samples, cross-track RMS %.2f mm, max %.2f mm\n", map, route,
         r->path.length_m, sim_time_us(k.s) * 1e-6, n, rms * 1e3, max * 1e3);
  EXPECT_TRUE(r->st.done) << "the car did not reach the route's end";
  EXPECT_GT(n, 100);
  EXPECT_LE(max, 0.03);
  EXPECT_LT(max, r->half_width_m);
}

TEST(World, RouteDriverKeepsItsLaneIntersectionSchoolLeftTurn) {
  drive_route("intersection_school", "west_to_north");
}
TEST(World, RouteDriverKeepsItsLaneIntersectionSchoolRightTurn) {
  drive_route("intersection_school", "north_to_west");
}
TEST(World, RouteDriverKeepsItsLaneTinyTown) {
  drive_route("tiny_town", "lot_to_east");
}

// Distance [m] from (x, y) to the polyline's nearest segment.
double dist_to_polyline(const pp_path_t &p, double x, double y) {
  double best = 1e9;
  for (int k = 0; k + 1 < p.n; k++) {
    const double *a = p.xy_m + 2 * k, *b = a + 2;
    const double dx = b[0] - a[0], dy = b[1] - a[1], l2 = dx * dx + dy * dy;
    const double t = l2 > 0 ? std::clamp(((x - a[0]) * dx + (y - a[1]) * dy) / l2, 0.0, 1.0) : 0;
    best = std::min(best, std::hypot(x - a[0] - t * dx, y - a[1] - t * dy));
  }
  return best;
}

// lane_shift=1 on Driving School's loop_ccw (the outer lane) is the inner lane driven the same
// way round: every point lies on loop_cw's centre line (the map's inner lane), and the car
// starts on it heading counter-clockwise, i.e. against loop_cw's direction.
TEST(World, RouteLaneShiftDrivesTheNeighbouringLane) {
  WorldSim k("driving_school", nullptr, "route:loop_ccw,lane_shift=1");
  ASSERT_NE(k.s, nullptr) << k.err;
  const route_driver_t *r = sim_route(k.s);
  ASSERT_NE(r, nullptr);
  route_driver_t own{}, inner{};
  char e[512];
  ASSERT_EQ(route_driver_init(&own, sim_model(k.s), "loop_ccw", 0.8, 0.2, 0, e, sizeof e), 0) << e;
  ASSERT_EQ(route_driver_init(&inner, sim_model(k.s), "loop_cw", 0.8, 0.2, 0, e, sizeof e), 0) << e;
  double worst = 0, off_own = 1e9;
  for (int i = 0; i < r->path.n; i++) {
    const double x = r->xy_m[2 * i], y = r->xy_m[2 * i + 1];
    worst = std::max(worst, dist_to_polyline(inner.path, x, y));
    off_own = std::min(off_own, dist_to_polyline(own.path, x, y));
  }
  EXPECT_LT(worst, 0.002);  // on the inner lane's centre line, curves included
  EXPECT_NEAR(off_own, 2 * own.half_width_m, 0.002);  // one lane width from its own everywhere
  EXPECT_NEAR(r->path.length_m, inner.path.length_m, 0.05);
  double x, y, yaw, yaw_own;
  route_driver_start(r, &x, &y, &yaw);
  route_driver_start(&own, &x, &y, &yaw_own);
  EXPECT_NEAR(std::remainder(yaw - yaw_own, 2 * M_PI), 0.0, 1e-6);  // the route's direction
  route_driver_free(&own);
  route_driver_free(&inner);
}

TEST(World, PhysicsModelLeavesOutVisualGeomsTheCamerasStillSeeThem) {
  WorldSim k("tiny_town", nullptr);
  ASSERT_NE(k.s, nullptr) << k.err;
  const mjModel *m = sim_model(k.s), *mv = sim_render_model(k.s);
  ASSERT_NE(m, mv);
  EXPECT_LT(mj_name2id(m, mjOBJ_GEOM, "tl1_lamp_red"), 0);
  EXPECT_GE(mj_name2id(mv, mjOBJ_GEOM, "tl1_lamp_red"), 0);
  EXPECT_GE(mj_name2id(m, mjOBJ_GEOM, "tl1_pole"), 0) << "a pole collides: the physics keeps it";
  for (int g = 0; g < m->ngeom; g++)  // the map's geoms in the physics model all collide
    if (m->geom_bodyid[g] == 0) {
      EXPECT_TRUE(m->geom_contype[g] || m->geom_conaffinity[g]) << g;
    }
  EXPECT_EQ(m->nq, mv->nq);
  ASSERT_TRUE(k.run_to(0.5));
  const mjData *d = sim_data(k.s), *dv = sim_render_data(k.s);
  for (int b = 0; b < m->nbody; b++)
    for (int i = 0; i < 3; i++) EXPECT_NEAR(d->xpos[3 * b + i], dv->xpos[3 * b + i], 1e-9) << b;
}

TEST(World, ProgramFollowsTheMapsTiming) {
  tl_light_t l{};
  l.cycle_s = 20;
  l.offset_s = 10;
  l.green_s = 6;
  l.yellow_s = 2;
  double left;
  EXPECT_EQ(tl_program_state(&l, 0.0, &left), TL_RED);
  EXPECT_NEAR(left, 10.0, 1e-9);
  EXPECT_EQ(tl_program_state(&l, 10.5, &left), TL_GREEN);
  EXPECT_NEAR(left, 5.5, 1e-9);
  EXPECT_EQ(tl_program_state(&l, 17.0, nullptr), TL_YELLOW);
  EXPECT_EQ(tl_program_state(&l, 18.5, nullptr), TL_RED);
  EXPECT_EQ(tl_program_state(&l, 30.0, nullptr), TL_GREEN);
}

TEST(World, ACommandThatWouldPutTwoConflictingLightsGreenIsRefused) {
  WorldSim k("intersection_school", nullptr);
  ASSERT_NE(k.s, nullptr) << k.err;
  traffic_lights_t *t = sim_traffic_lights(k.s);
  ASSERT_EQ(t->n, 4);
  ASSERT_TRUE(k.run_to(1.0));  // programs: lights 1 and 3 green, 2 and 4 red (offset 10 s)
  EXPECT_EQ(t->light[tl_find(t, 1)].state, TL_GREEN);
  char why[256] = "";
  EXPECT_NE(tl_command(t, 2, TL_GREEN, 0.0, sim_time_us(k.s), why, sizeof why), 0);
  printf("refused: %s\n", why);
  EXPECT_NE(std::string(why).find("light 2"), std::string::npos) << why;
  EXPECT_NE(std::string(why).find("light 1"), std::string::npos) << why;
  EXPECT_NE(tl_command(t, 4, TL_YELLOW, 0.0, sim_time_us(k.s), why, sizeof why), 0);
  EXPECT_NE(tl_command(t, 9, TL_RED, 0.0, sim_time_us(k.s), why, sizeof why), 0);  // no light 9
  ASSERT_TRUE(k.run_to(1.1));
  EXPECT_EQ(t->light[tl_find(t, 2)].state, TL_RED);
  // green straight to red is fine; then 2 may go green while 1 and 3 are red
  EXPECT_EQ(tl_command(t, 1, TL_RED, 0.0, sim_time_us(k.s), why, sizeof why), 0) << why;
  EXPECT_EQ(tl_command(t, 3, TL_RED, 0.0, sim_time_us(k.s), why, sizeof why), 0) << why;
  ASSERT_TRUE(k.run_to(1.2));
  EXPECT_EQ(tl_command(t, 2, TL_GREEN, 3.0, sim_time_us(k.s), why, sizeof why), 0) << why;
  ASSERT_TRUE(k.run_to(1.3));
  EXPECT_EQ(t->light[tl_find(t, 2)].state, TL_GREEN);
  // light 1's command ends (RED until the next command): free it with a short one; its program
  // says green at t < 6 s but it yields while light 2 is held green
  EXPECT_EQ(tl_command(t, 1, TL_RED, 0.1, sim_time_us(k.s), why, sizeof why), 0) << why;
  ASSERT_TRUE(k.run_to(2.0));
  EXPECT_EQ(t->light[tl_find(t, 1)].state, TL_RED);
  EXPECT_EQ(t->light[tl_find(t, 2)].state, TL_GREEN);
  // light 2's hold (3 s from 1.2 s) ends at 4.2 s: back to its program (red), 1 back to green
  ASSERT_TRUE(k.run_to(4.3));
  EXPECT_EQ(t->light[tl_find(t, 2)].state, TL_RED);
  EXPECT_EQ(t->light[tl_find(t, 1)].state, TL_GREEN);
  for (double ts = 4.3; ts < 40.0; ts += 0.1) {  // and never two conflicting lights non-red
    ASSERT_TRUE(k.run_to(ts));
    for (int c = 0; c < t->nconflicts; c++) {
      const int a = t->light[tl_find(t, t->conflict[c][0])].state,
                b = t->light[tl_find(t, t->conflict[c][1])].state;
      ASSERT_FALSE((a == TL_GREEN || a == TL_YELLOW) && (b == TL_GREEN || b == TL_YELLOW))
          << "t = " << ts;
    }
  }
}

// Front camera of a car 1.2 m in front of light 1, facing it.
struct LightCamera {
  scn_pose_t p;
  WorldSim k;
  sim_render_t *rd = nullptr;
  sim_camera_t *cam = nullptr;
  char err[1024] = "";
  static scn_pose_t pose() {
    const auto j = sidecar("intersection_school")["traffic_lights"][0];
    return facing(j["position_m"][0], j["position_m"][1], j["yaw_rad"], 1.2);
  }
  LightCamera() : p(pose()), k("intersection_school", &p) {}
  ~LightCamera() {
    sim_camera_destroy(cam);
    sim_render_destroy(rd);
  }
  bool open() {
    if (!k.s) return false;
    rd = sim_render_create(sim_render_model(k.s), 640, 480, SIM_RENDER_AUTO, err, sizeof err);
    if (rd)
      cam = sim_camera_create(rd, sim_render_model(k.s), "nigel1/cam_front", "camera_front", 640,
                              480, 85, err, sizeof err);
    return cam != nullptr;
  }
  // Mean colour of lamp colour ("red", "yellow", "green") of light 1 in the frame.
  std::vector<double> lamp(const char *colour) {
    const mjModel *m = sim_render_model(k.s);
    const mjData *d = sim_render_data(k.s);
    const std::string name = std::string("tl1_lamp_") + colour;
    const int g = mj_name2id(m, mjOBJ_GEOM, name.c_str());
    EXPECT_GE(g, 0) << name;
    double u = 0, v = 0;
    const int cam_id = mj_name2id(m, mjOBJ_CAMERA, "nigel1/cam_front");
    EXPECT_TRUE(project(m, d, cam_id, d->geom_xpos + 3 * g, 640, 480, &u, &v))
        << name << " is not in the frame";
    return mean_rgb(sim_camera_rgb(cam), 640, 480, u, v, 2);
  }
};

TEST(World, ALightCommandedRedIsRenderedRedInTheFrontCamera) {
  LightCamera lc;
  ASSERT_TRUE(lc.open()) << lc.k.err << lc.err;
  traffic_lights_t *t = sim_traffic_lights(lc.k.s);
  char why[256] = "";
  ASSERT_TRUE(lc.k.run_to(0.5));
  ASSERT_EQ(tl_command(t, 1, TL_RED, 0.0, sim_time_us(lc.k.s), why, sizeof why), 0) << why;
  ASSERT_TRUE(lc.k.run_to(0.52));
  ASSERT_EQ(sim_camera_capture(lc.cam, sim_render_model(lc.k.s), sim_render_data(lc.k.s), 0), 0);
  auto red = lc.lamp("red"), green = lc.lamp("green");
  printf("commanded RED: red lamp rgb %.0f %.0f %.0f, green lamp rgb %.0f %.0f %.0f\n", red[0],
         red[1], red[2], green[0], green[1], green[2]);
  EXPECT_GT(red[0], 180);
  EXPECT_GT(red[0] - red[1], 100);
  EXPECT_LT(green[1], 120);
  // and GREEN: the lamps swap
  ASSERT_EQ(tl_command(t, 1, TL_GREEN, 0.0, sim_time_us(lc.k.s), why, sizeof why), 0) << why;
  ASSERT_TRUE(lc.k.run_to(0.54));
  ASSERT_EQ(sim_camera_capture(lc.cam, sim_render_model(lc.k.s), sim_render_data(lc.k.s), 0), 0);
  red = lc.lamp("red");
  green = lc.lamp("green");
  printf("commanded GREEN: red lamp rgb %.0f %.0f %.0f, green lamp rgb %.0f %.0f %.0f\n", red[0],
         red[1], red[2], green[0], green[1], green[2]);
  EXPECT_GT(green[1], 180);
  EXPECT_GT(green[1] - green[0], 100);
  EXPECT_LT(red[0], 120);
}

TEST(World, AStopSignIsVisibleFrom1mInTheFrontCamera) {
  const auto j = sidecar("tiny_town")["signs"];
  nlohmann::json sign;
  for (const auto &s : j)
    if (s["kind"] == "stop") sign = s;
  ASSERT_FALSE(sign.is_null());
  const scn_pose_t p = facing(sign["position_m"][0], sign["position_m"][1], sign["yaw_rad"], 1.0);
  WorldSim k("tiny_town", &p);
  ASSERT_NE(k.s, nullptr) << k.err;
  const mjModel *m = sim_render_model(k.s);
  char err[1024] = "";
  sim_render_t *rd = sim_render_create(m, 640, 480, SIM_RENDER_AUTO, err, sizeof err);
  ASSERT_NE(rd, nullptr) << err;
  sim_camera_t *cam =
      sim_camera_create(rd, m, "nigel1/cam_front", "camera_front", 640, 480, 85, err, sizeof err);
  ASSERT_NE(cam, nullptr) << err;
  ASSERT_TRUE(k.run_to(0.05));
  mjData *d = sim_render_data(k.s);
  ASSERT_EQ(sim_camera_capture(cam, m, d, 0), 0);
  const std::string face = std::string(sign["name"]) + "_face";
  const int g = mj_name2id(m, mjOBJ_GEOM, face.c_str());
  ASSERT_GE(g, 0) << face;
  double u = 0, v = 0;
  ASSERT_TRUE(project(m, d, mj_name2id(m, mjOBJ_CAMERA, "nigel1/cam_front"), d->geom_xpos + 3 * g,
                      640, 480, &u, &v));
  // the face (8 cm at 1 m: ~40 px): the stop texture's red, with its white letters
  int red = 0, n = 0;
  const uint8_t *rgb = sim_camera_rgb(cam);
  for (int y = (int)v - 12; y <= (int)v + 12; y++)
    for (int x = (int)u - 12; x <= (int)u + 12; x++, n++) {
      const uint8_t *px = rgb + 3 * (y * 640 + x);
      red += px[0] > 120 && px[0] > 2 * px[1] && px[0] > 2 * px[2];
    }
  printf("stop sign at pixel (%.0f, %.0f): %d of %d pixels red\n", u, v, red, n);
  EXPECT_GT(red, n / 3);
  sim_camera_destroy(cam);
  sim_render_destroy(rd);
}

TEST(World, PurePursuitSteersACircleExactly) {
  // a circle of radius 0.6 m, CCW, points 0.02 m apart: on it and tangent, the steering angle is
  // atan(L / R) for any lookahead
  std::vector<double> xy;
  const double R = 0.6, L = 0.14154;
  const int n = (int)(2 * M_PI * R / 0.02);
  for (int i = 0; i < n; i++) {
    xy.push_back(R * cos(2 * M_PI * i / n));
    xy.push_back(R * sin(2 * M_PI * i / n));
  }
  pp_path_t p;
  char err[128];
  ASSERT_EQ(pp_path_init(&p, xy.data(), n, 1, err, sizeof err), 0) << err;
  pp_state_t st;
  pp_reset(&st, &p, R, 0.0);
  pp_project(&st, &p, R, 0.0);
  EXPECT_NEAR(st.cross_track_m, 0.0, 1e-9);
  const pp_vehicle_t car = {L, 1.0};
  for (double ld : {0.1, 0.2, 0.4})
    EXPECT_NEAR(pp_steer(&st, &p, R, 0.0, M_PI / 2, ld, &car), atan(L / R), 2e-3) << ld;
  pp_project(&st, &p, R + 0.01, 0.0);  // 1 cm outside the CCW circle: right of it
  EXPECT_NEAR(st.cross_track_m, -0.01, 1e-4);
  pp_path_free(&p);
}

TEST(World, CameraNoiseIsSeededAndBlurSmooths) {
  std::vector<uint8_t> a(64 * 48 * 3), b, c;
  for (size_t i = 0; i < a.size(); i++) a[i] = (i / 3) % 2 ? 200 : 40;  // a fine stripe pattern
  cfx_t f1, f2, blur;
  cfx_init(&f1, 8.0, 0.0, 7);
  cfx_init(&f2, 8.0, 0.0, 7);
  cfx_init(&blur, 0.0, 2.0, 7);
  b = a;
  c = a;
  cfx_apply(&f1, b.data(), 64, 48);
  cfx_apply(&f2, c.data(), 64, 48);
  EXPECT_EQ(b, c) << "same seed, same noise";
  EXPECT_NE(b, a);
  c = a;
  cfx_apply(&blur, c.data(), 64, 48);
  EXPECT_NEAR(c[3 * (24 * 64 + 32)], 120, 8) << "blurred stripes tend to their mean";
  cfx_free(&f1);
  cfx_free(&f2);
  cfx_free(&blur);
}

TEST(World, LightRgbIsAGainPerChannelOnEveryLight) {
  WorldSim w("tiny_town", nullptr);
  ASSERT_NE(w.s, nullptr) << w.err;
  mjModel *m = sim_render_model(w.s);
  ASSERT_GT(m->nlight, 0);
  std::vector<float> diffuse(m->light_diffuse, m->light_diffuse + 3 * m->nlight),
      specular(m->light_specular, m->light_specular + 3 * m->nlight);
  const float head = m->vis.headlight.diffuse[1];
  const double level0 = cfx_light_level(m);
  ASSERT_EQ(cfx_set_light_level(m, 0.5), 0);  // both options: the level first, then the colour
  const double gain[3] = {1.5, 0.5, 1.0};
  cfx_set_light_rgb(m, gain);
  for (int i = 0; i < m->nlight; i++)
    for (int c = 0; c < 3; c++) {
      const double k = 0.5 / level0 * gain[c];
      EXPECT_NEAR(m->light_diffuse[3 * i + c], diffuse[3 * i + c] * k, 1e-5) << i << " " << c;
      EXPECT_NEAR(m->light_specular[3 * i + c], specular[3 * i + c] * k, 1e-5) << i << " " << c;
    }
  EXPECT_NEAR(m->vis.headlight.diffuse[1], head * 0.5 / level0 * 0.5, 1e-5) << "the headlight too";
}

TEST(World, CameraExposureScalesClipsAndComesBeforeBlur) {
  std::vector<uint8_t> a(64 * 48 * 3), b;
  for (size_t i = 0; i < a.size(); i++) a[i] = (i / 3) % 2 ? 200 : 40;  // fine stripes
  cfx_t up, down, up_blur;
  cfx_init(&up, 0.0, 0.0, 7);
  cfx_set_exposure(&up, 1.0);
  cfx_init(&down, 0.0, 0.0, 7);
  cfx_set_exposure(&down, -2.0);
  cfx_init(&up_blur, 0.0, 2.0, 7);
  cfx_set_exposure(&up_blur, 1.0);
  EXPECT_TRUE(cfx_active(&up));
  b = a;
  cfx_apply(&up, b.data(), 64, 48);
  EXPECT_EQ(b[3], 255) << "200 x 2 clips at 255, as a sensor does";
  EXPECT_EQ(b[0], 80);
  b = a;
  cfx_apply(&down, b.data(), 64, 48);
  EXPECT_EQ(b[3], 50);
  EXPECT_EQ(b[0], 10);
  b = a;
  cfx_apply(&up_blur, b.data(), 64, 48);
  // exposed first (255, 80), then blurred: their mean 167.5; blurred first would give 240
  EXPECT_NEAR(b[3 * (24 * 64 + 32)], 167.5, 8);
  cfx_t none;
  cfx_init(&none, 0.0, 0.0, 7);
  cfx_set_exposure(&none, 0.0);
  EXPECT_FALSE(cfx_active(&none)) << "0 EV changes nothing";
  for (cfx_t *f : {&up, &down, &up_blur, &none}) cfx_free(f);
}

TEST(World, CameraJitterIsSeededPerCarAndWithinTheTolerance) {
  const cfx_jitter_t a = cfx_jitter_draw(5, 1, 10, 3), b = cfx_jitter_draw(5, 1, 10, 3);
  const cfx_jitter_t c = cfx_jitter_draw(6, 1, 10, 3), d = cfx_jitter_draw(5, 2, 10, 3);
  EXPECT_EQ(memcmp(&a, &b, sizeof a), 0) << "same seed and car, same offset";
  EXPECT_NE(memcmp(&a, &c, sizeof a), 0) << "another seed, another offset";
  EXPECT_NE(memcmp(&a, &d, sizeof a), 0) << "another car, another offset";
  double max_mm = 0, max_deg = 0;
  for (uint64_t seed = 0; seed < 200; seed++) {
    const cfx_jitter_t j = cfx_jitter_draw(seed, 1, 4, 1.5);
    for (int k = 0; k < 3; k++) {
      max_mm = fmax(max_mm, fabs(j.pos_m[k]) * 1e3);
      max_deg = fmax(max_deg, fabs(j.rot_deg[k]));
    }
  }
  EXPECT_LE(max_mm, 4.0);
  EXPECT_GT(max_mm, 3.5) << "uniform over the whole +-MM";
  EXPECT_LE(max_deg, 1.5);
  EXPECT_GT(max_deg, 1.3);
  // on the model: the mount moves by the offset, turns by no more than the angles, and keeps
  // its field of view (the published intrinsics)
  WorldSim w("driving_school", nullptr);
  ASSERT_NE(w.s, nullptr) << w.err;
  mjModel *m = sim_render_model(w.s);
  const int id = mj_name2id(m, mjOBJ_CAMERA, "nigel1/cam_front");
  ASSERT_GE(id, 0);
  const double pos0[3] = {m->cam_pos[3 * id], m->cam_pos[3 * id + 1], m->cam_pos[3 * id + 2]};
  const double q0[4] = {m->cam_quat[4 * id], m->cam_quat[4 * id + 1], m->cam_quat[4 * id + 2],
                        m->cam_quat[4 * id + 3]};
  const double fovy = m->cam_fovy[id];
  cfx_jitter_camera(m, id, &a);
  for (int k = 0; k < 3; k++) EXPECT_NEAR(m->cam_pos[3 * id + k] - pos0[k], a.pos_m[k], 1e-12);
  double dot = 0;
  for (int k = 0; k < 4; k++) dot += q0[k] * m->cam_quat[4 * id + k];
  const double turned_deg = 2 * acos(fmin(1.0, fabs(dot))) * 180 / M_PI;
  EXPECT_GT(turned_deg, 0.01);
  EXPECT_LE(turned_deg, sqrt(3.0) * 3.0 + 1e-9);
  EXPECT_EQ(m->cam_fovy[id], fovy);
}

// Every distractor's place: x, y [m] of its geom in the physics model.
std::vector<double> distractor_places(const WorldSim &w, int n) {
  std::vector<double> xy;
  const mjModel *m = sim_model(w.s);
  for (int k = 1; k <= n; k++) {
    const int g = mj_name2id(m, mjOBJ_GEOM, ("scenario/distractor" + std::to_string(k)).c_str());
    EXPECT_GE(g, 0) << k;
    if (g < 0) continue;
    xy.push_back(m->geom_pos[3 * g]);
    xy.push_back(m->geom_pos[3 * g + 1]);
  }
  return xy;
}

// Distance from (x, y) to the polyline r [m].
double to_line(const route_t &r, double x, double y) {
  double best = 1e9;
  for (int i = 0; i + 1 < r.n + (r.loop ? 1 : 0); i++) {
    const double *a = r.xy + 2 * i, *b = r.xy + 2 * ((i + 1) % r.n);
    const double ex = b[0] - a[0], ey = b[1] - a[1], l2 = ex * ex + ey * ey;
    const double t = l2 > 0 ? fmin(1.0, fmax(0.0, ((x - a[0]) * ex + (y - a[1]) * ey) / l2)) : 0;
    best = fmin(best, hypot(x - a[0] - t * ex, y - a[1] - t * ey));
  }
  return best;
}

TEST(World, DistractorsStandBesideTheRoadFromTheSeed) {
  for (const char *map : {"driving_school", "tiny_town", "intersection_school"}) {
    WorldSim a(map, nullptr, nullptr, 20, 4), b(map, nullptr, nullptr, 20, 4),
        c(map, nullptr, nullptr, 20, 5);
    ASSERT_NE(a.s, nullptr) << map << ": " << a.err;
    ASSERT_NE(b.s, nullptr) << b.err;
    ASSERT_NE(c.s, nullptr) << c.err;
    const std::vector<double> pa = distractor_places(a, 20), pb = distractor_places(b, 20),
                              pc = distractor_places(c, 20);
    EXPECT_EQ(pa, pb) << map << ": same seed, same places";
    EXPECT_NE(pa, pc) << map << ": another seed, other places";
    const mjModel *m = sim_model(a.s);
    // none on a lane: its footprint's circle clear of every lane's (and route's) width
    int lanes = 0;
    for (int i = 0; i < m->nnumeric; i++) {
      const std::string name = m->names + m->name_numericadr[i];
      const bool lane = name.rfind("lane_", 0) == 0, route = name.rfind("route_", 0) == 0;
      if ((!lane && !route) || name.find(".part") != std::string::npos) continue;
      route_t r;
      char err[256];
      ASSERT_EQ(route_from_numeric(&r, m, i, route, err, sizeof err), 0) << err;
      lanes++;
      for (int k = 0; k < 20; k++) {
        const int g =
            mj_name2id(m, mjOBJ_GEOM, ("scenario/distractor" + std::to_string(k + 1)).c_str());
        const double radius =
            hypot(m->geom_size[3 * g],
                  m->geom_type[g] == mjGEOM_BOX ? m->geom_size[3 * g + 1] : m->geom_size[3 * g]);
        EXPECT_GT(to_line(r, pa[2 * k], pa[2 * k + 1]), r.half_width_m + radius)
            << map << ": distractor " << k + 1 << " on " << name;
      }
      route_free(&r);
    }
    EXPECT_GT(lanes, 0) << map;
    // on the floor, not on the car's start, not on each other
    sim_truth_t t;
    sim_get_truth(a.s, 1, &t);
    for (int k = 0; k < 20; k++) {
      EXPECT_GT(hypot(pa[2 * k] - t.pos_m[0], pa[2 * k + 1] - t.pos_m[1]), 0.2) << map << k;
      for (int j = 0; j < k; j++)
        EXPECT_GT(hypot(pa[2 * k] - pa[2 * j], pa[2 * k + 1] - pa[2 * j + 1]), 0.05) << map << k;
    }
    // the cars stand clear: the run steps without a collision
    ASSERT_TRUE(a.run_to(0.5)) << a.err;
    sim_get_truth(a.s, 1, &t);
    EXPECT_FALSE(t.in_collision) << map;
  }
}

// A start pose the program gives later (--car-start, --start per car) is kept clear too: a car
// put where the first distractor stood moves that distractor elsewhere, clear of the car.
TEST(World, DistractorsKeepClearOfTheStartPosesGivenLater) {
  WorldSim before("tiny_town", nullptr, nullptr, 3, 9);
  ASSERT_NE(before.s, nullptr) << before.err;
  const std::vector<double> p = distractor_places(before, 3);
  const scn_pose_t there = {p[0] - 0.07, p[1], 0.0};  // base_link 7 cm behind: the car over it
  WorldSim after("tiny_town", nullptr, nullptr, 3, 9, &there);
  ASSERT_NE(after.s, nullptr) << after.err;
  const std::vector<double> q = distractor_places(after, 3);
  EXPECT_NE(p, q);
  for (int k = 0; k < 3; k++)
    EXPECT_GT(hypot(q[2 * k] - there.x_m, q[2 * k + 1] - there.y_m), 0.2) << k;
  char err[512];
  const double poses[3] = {there.x_m, there.y_m, 0.0};
  EXPECT_NE(sim_reset(before.s, 9, poses, err, sizeof err), 0) << "the car would stand on it";
  EXPECT_NE(std::string(err).find("distractor"), std::string::npos) << err;
  EXPECT_EQ(sim_reset(after.s, 9, poses, err, sizeof err), 0) << err;
}

TEST(World, DistractorsAreSeenByRaysAsTheLidarAndCamerasSeeThem) {
  WorldSim w("parking_school", nullptr, nullptr, 20, 2);
  ASSERT_NE(w.s, nullptr) << w.err;
  for (const mjModel *m : {sim_model(w.s), (const mjModel *)sim_render_model(w.s)}) {
    mjData *d = mj_makeData(m);
    mj_forward(m, d);
    int seen = 0;
    for (int k = 1; k <= 20; k++) {
      const int g = mj_name2id(m, mjOBJ_GEOM, ("scenario/distractor" + std::to_string(k)).c_str());
      ASSERT_GE(g, 0);
      // a ray from 0.5 m beside it in the LIDAR's scan plane (0.176 m over base_link, ~2 mm
      // over the floor) towards its centre (the LIDAR's groups 0..2), and one from 1 m above,
      // looking down (a camera)
      const mjtNum *c = d->geom_xpos + 3 * g;
      const mjtNum side[3] = {c[0] - 0.5, c[1], 0.178}, at[3] = {0.5, 0, 0};
      const mjtNum top[3] = {c[0], c[1], 1.0}, down[3] = {0, 0, -1};
      const mjtByte groups[mjNGROUP] = {1, 1, 1, 0, 0, 0};
      int hit = -1;
      mj_ray(m, d, side, at, groups, 1, -1, &hit);
      seen += hit == g;
      hit = -1;
      mj_ray(m, d, top, down, nullptr, 1, -1, &hit);
      EXPECT_EQ(hit, g) << k;
    }
    EXPECT_GE(seen, 18) << "a sideways ray may meet another distractor first";
    mj_deleteData(d);
  }
}

TEST(World, DistractorsWithoutRoomAreAClearError) {
  const std::string small = simtest::fixture("small_floor.xml");
  WorldSim w(small.c_str(), nullptr, nullptr, 20, 1);
  EXPECT_EQ(w.s, nullptr);
  EXPECT_NE(w.err.find("--distractors 20"), std::string::npos) << w.err;
  EXPECT_NE(w.err.find("no free place"), std::string::npos) << w.err;
  WorldSim one(small.c_str(), nullptr, nullptr, 1, 1);
  EXPECT_NE(one.s, nullptr) << "one small thing fits: " << one.err << " / " << w.err;
}

}  // namespace
