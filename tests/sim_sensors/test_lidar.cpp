// sim_lidar against analytic ranges in the known test room (test_room.xml).
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "room.hpp"

extern "C" {
#include "sim_lidar.h"
}

namespace {

constexpr double kOx_m = AUTODRIVE_VEHICLE_LIDAR_POS_M_X,
                 kOy_m = 0.0;  // scanner origin in the room (car at origin)

// Nearest positive t of the 2D ray o + t (c, s) against the room's walls, pillar and the other
// car's mast, all of which span the scan height.
double analytic_range_m(double angle_rad) {
  const double c = std::cos(angle_rad), s = std::sin(angle_rad);
  double best = INFINITY;
  auto take = [&](double t) {
    if (t > 1e-9 && t < best) best = t;
  };
  // room interior walls
  if (c > 0) take((3.0 - kOx_m) / c);
  if (c < 0) take((-2.0 - kOx_m) / c);
  if (s > 0) take((2.5 - kOy_m) / s);
  if (s < 0) take((-1.5 - kOy_m) / s);
  // pillar: circle centre (1.5, 0), radius 0.2
  {
    const double px = kOx_m - 1.5, py = kOy_m;
    const double b = px * c + py * s, cc = px * px + py * py - 0.04;
    const double disc = b * b - cc;
    if (disc >= 0) take(-b - std::sqrt(disc));
  }
  // other car's mast: square half 0.04 at (-0.06, 0) in the car at (-1, 1.5) with yaw 30 deg
  {
    const double yaw = 30.0 * M_PI / 180.0, cy = std::cos(yaw), sy = std::sin(yaw);
    const double mx = -1.0 - 0.06 * cy, my = 1.5 - 0.06 * sy;
    const double rx = kOx_m - mx, ry = kOy_m - my;
    const double lo[2] = {rx * cy + ry * sy, -rx * sy + ry * cy};  // origin in box frame
    const double ld[2] = {c * cy + s * sy, -c * sy + s * cy};
    double tmin = -INFINITY, tmax = INFINITY;
    for (int a = 0; a < 2; a++) {
      if (std::fabs(ld[a]) < 1e-12) {
        if (std::fabs(lo[a]) > 0.04) tmin = INFINITY;
        continue;
      }
      double t1 = (-0.04 - lo[a]) / ld[a], t2 = (0.04 - lo[a]) / ld[a];
      if (t1 > t2) std::swap(t1, t2);
      tmin = std::max(tmin, t1);
      tmax = std::min(tmax, t2);
    }
    if (tmin <= tmax) take(tmin);
  }
  return best;
}

sim_lidar_t *make_lidar(const mjModel *m, const sim_lidar_config_t &cfg) {
  char err[256] = "";
  sim_lidar_t *l = sim_lidar_create(m, "car", &cfg, err, sizeof err);
  EXPECT_NE(l, nullptr) << err;
  return l;
}

}  // namespace

TEST(SimLidar, AllRaysMatchAnalyticRoom) {
  room::Room r;
  ASSERT_NE(r.m, nullptr);
  sim_lidar_config_t cfg;
  sim_lidar_config_default(&cfg);
  sim_lidar_t *l = make_lidar(r.m, cfg);
  ASSERT_NE(l, nullptr);
  sim_lidar_scan_now(r.m, r.d, l, 1234);
  const sim_lidar_scan_t *s = sim_lidar_last_scan(l);
  ASSERT_EQ(s->num_rays, 360);
  EXPECT_EQ(s->utime, 1234);
  EXPECT_NEAR(s->angle_increment_rad, M_PI / 180.0, 1e-7);
  int hits_mast = 0, hits_pillar = 0;
  for (int i = 0; i < 360; i++) {
    const double a = i * M_PI / 180.0;
    const double want = analytic_range_m(a);
    ASSERT_TRUE(std::isfinite(want)) << "ray " << i;  // a closed room: every ray hits
    EXPECT_NEAR(s->ranges_m[i], want, 1e-4) << "ray " << i << " deg";
    EXPECT_EQ(s->intensities[i] > 0, true) << "ray " << i;
    if (i >= 120 && i <= 140 && want < 2.0) hits_mast++;
    if ((i <= 10 || i >= 350) && want < 1.3) hits_pillar++;
  }
  // the scene features are really in the scan (not just the walls)
  EXPECT_GT(hits_mast, 0);
  EXPECT_GT(hits_pillar, 0);
  sim_lidar_destroy(l);
}

TEST(SimLidar, OwnCarExcludedOtherCarSeen) {
  room::Room r;
  ASSERT_NE(r.m, nullptr);
  sim_lidar_config_t cfg;
  sim_lidar_config_default(&cfg);
  sim_lidar_t *l = make_lidar(r.m, cfg);
  ASSERT_NE(l, nullptr);
  // straight ahead is the car's own bumper at 0.4855 m; the scanner must see past it
  const double fwd = sim_lidar_ray(r.m, r.d, l, 0.0);
  EXPECT_NEAR(fwd, 1.5 - 0.2 - kOx_m, 1e-6);
  EXPECT_GT(fwd, 0.6);
  // the other car's mast is seen: ray aimed at its centre
  const double a =
      std::atan2(1.5 - 0.06 * std::sin(M_PI / 6) - kOy_m, -1.0 - 0.06 * std::cos(M_PI / 6) - kOx_m);
  const double want = analytic_range_m(a);
  EXPECT_LT(want, 2.0);
  EXPECT_NEAR(sim_lidar_ray(r.m, r.d, l, a), want, 1e-4);
  // a lidar mounted on "other" does not see its own mast but sees "car"'s bumper
  sim_lidar_config_t c2 = cfg;
  c2.mount_pos_m[0] = -0.06;  // scanner inside its own mast
  char err[256];
  sim_lidar_t *lo = sim_lidar_create(r.m, "other", &c2, err, sizeof err);
  ASSERT_NE(lo, nullptr) << err;
  EXPECT_GT(sim_lidar_ray(r.m, r.d, lo, 0.0), 0.15);
  sim_lidar_destroy(lo);
  sim_lidar_destroy(l);
}

// The per-ray sector buckets (scan_now, spinning update) against testing every candidate geom
// (sim_lidar_ray), for a moved, yawed and slightly tilted car.
TEST(SimLidar, SectorCullingMatchesTestingEveryGeom) {
  room::Room r;
  ASSERT_NE(r.m, nullptr);
  const int j = r.m->body_jntadr[mj_name2id(r.m, mjOBJ_BODY, "car")];
  mjtNum *q = r.d->qpos + r.m->jnt_qposadr[j];
  q[0] = 0.3;
  q[1] = 0.4;
  const mjtNum euler[3] = {0.03, -0.02, 37.0 * M_PI / 180};
  mjtNum qz[4], qy[4], qx[4], tmp[4];
  const mjtNum az[3] = {0, 0, 1}, ay[3] = {0, 1, 0}, axx[3] = {1, 0, 0};
  mju_axisAngle2Quat(qz, az, euler[2]);
  mju_axisAngle2Quat(qy, ay, euler[1]);
  mju_axisAngle2Quat(qx, axx, euler[0]);
  mju_mulQuat(tmp, qz, qy);
  mju_mulQuat(q + 3, tmp, qx);
  mj_forward(r.m, r.d);
  sim_lidar_config_t cfg;
  sim_lidar_config_default(&cfg);
  sim_lidar_t *l = make_lidar(r.m, cfg);
  ASSERT_NE(l, nullptr);
  sim_lidar_scan_now(r.m, r.d, l, 0);
  std::vector<float> now(sim_lidar_last_scan(l)->ranges_m, sim_lidar_last_scan(l)->ranges_m + 360);
  int scans = 0;
  for (int64_t t_us = 0; t_us <= 150000; t_us += 1000) scans += sim_lidar_update(r.m, r.d, l, t_us);
  ASSERT_EQ(scans, 1);
  int finite = 0;
  for (int i = 0; i < 360; i++) {
    const float every = (float)sim_lidar_ray(r.m, r.d, l, i * 2 * M_PI / 360);
    EXPECT_EQ(now[i], every) << "ray " << i;
    EXPECT_EQ(sim_lidar_last_scan(l)->ranges_m[i], every) << "ray " << i;
    finite += std::isfinite(every);
  }
  EXPECT_EQ(finite, 360);
  sim_lidar_destroy(l);
}

TEST(SimLidar, BeyondRangeIsInfinity) {
  room::Room r;
  ASSERT_NE(r.m, nullptr);
  sim_lidar_config_t cfg;
  sim_lidar_config_default(&cfg);
  cfg.range_max_m = 2.0;
  cfg.range_min_m = 1.2;
  sim_lidar_t *l = make_lidar(r.m, cfg);
  ASSERT_NE(l, nullptr);
  sim_lidar_scan_now(r.m, r.d, l, 0);
  const sim_lidar_scan_t *s = sim_lidar_last_scan(l);
  int inf = 0, fin = 0;
  for (int i = 0; i < 360; i++) {
    const double want = analytic_range_m(i * M_PI / 180.0);
    if (want > 2.0 || want < 1.2) {
      EXPECT_TRUE(std::isinf(s->ranges_m[i]) && s->ranges_m[i] > 0) << "ray " << i;
      EXPECT_EQ(s->intensities[i], 0.0f);
      inf++;
    } else {
      EXPECT_NEAR(s->ranges_m[i], want, 1e-4) << "ray " << i;
      fin++;
    }
  }
  EXPECT_GT(inf, 0);
  EXPECT_GT(fin, 0);
  sim_lidar_destroy(l);
}

TEST(SimLidar, SpinningUpdateGivesOneScanPerRevolution) {
  room::Room r;
  ASSERT_NE(r.m, nullptr);
  sim_lidar_config_t cfg;
  sim_lidar_config_default(&cfg);
  sim_lidar_t *l = make_lidar(r.m, cfg);
  ASSERT_NE(l, nullptr);
  // 1 s of sim time at 1 kHz: 7 revolutions at 7 Hz
  int scans = 0;
  int64_t first_utime = -1;
  for (int64_t t_us = 0; t_us <= 1000000; t_us += 1000) {
    if (sim_lidar_update(r.m, r.d, l, t_us)) {
      if (first_utime < 0) first_utime = sim_lidar_last_scan(l)->utime;
      scans++;
    }
  }
  EXPECT_EQ(scans, 7);
  EXPECT_EQ(first_utime, 0);
  // the static scene gives the same ranges as a one-shot scan
  const sim_lidar_scan_t *s = sim_lidar_last_scan(l);
  std::vector<float> spun(s->ranges_m, s->ranges_m + s->num_rays);
  sim_lidar_scan_now(r.m, r.d, l, 0);
  for (int i = 0; i < 360; i++) EXPECT_EQ(spun[i], s->ranges_m[i]) << "ray " << i;
  sim_lidar_destroy(l);
}

TEST(SimLidar, ClockResetStartsANewRevolution) {
  room::Room r;
  ASSERT_NE(r.m, nullptr);
  sim_lidar_config_t cfg;
  sim_lidar_config_default(&cfg);
  sim_lidar_t *l = make_lidar(r.m, cfg);
  ASSERT_NE(l, nullptr);
  for (int64_t t_us = 5000000; t_us < 5100000; t_us += 1000) sim_lidar_update(r.m, r.d, l, t_us);
  // the sim resets its clock to 0: scans resume one period later, stamped from 0
  int scans = 0;
  for (int64_t t_us = 0; t_us <= 300000; t_us += 1000) {
    if (sim_lidar_update(r.m, r.d, l, t_us)) {
      if (scans == 0) {
        EXPECT_EQ(sim_lidar_last_scan(l)->utime, 0);
      }
      scans++;
    }
  }
  EXPECT_EQ(scans, 2);
  sim_lidar_destroy(l);
}

TEST(SimLidar, NoiseIsSeededAndSized) {
  room::Room r;
  ASSERT_NE(r.m, nullptr);
  sim_lidar_config_t cfg;
  sim_lidar_config_default(&cfg);
  cfg.noise_std_m = 0.01;
  cfg.seed = 42;
  sim_lidar_t *a = make_lidar(r.m, cfg), *b = make_lidar(r.m, cfg);
  cfg.seed = 43;
  sim_lidar_t *c = make_lidar(r.m, cfg);
  ASSERT_TRUE(a && b && c);
  double sum2 = 0;
  int n = 0, differ = 0;
  for (int k = 0; k < 20; k++) {
    sim_lidar_scan_now(r.m, r.d, a, 0);
    std::vector<float> ra(sim_lidar_last_scan(a)->ranges_m, sim_lidar_last_scan(a)->ranges_m + 360);
    sim_lidar_scan_now(r.m, r.d, b, 0);
    sim_lidar_scan_now(r.m, r.d, c, 0);
    for (int i = 0; i < 360; i++) {
      EXPECT_EQ(ra[i], sim_lidar_last_scan(b)->ranges_m[i]);
      differ += ra[i] != sim_lidar_last_scan(c)->ranges_m[i];
      const double e = ra[i] - analytic_range_m(i * M_PI / 180.0);
      sum2 += e * e;
      n++;
    }
  }
  EXPECT_GT(differ, 3000);
  EXPECT_NEAR(std::sqrt(sum2 / n), 0.01, 0.001);
  sim_lidar_destroy(a);
  sim_lidar_destroy(b);
  sim_lidar_destroy(c);
}

TEST(SimLidar, BadInputGivesClearError) {
  room::Room r;
  ASSERT_NE(r.m, nullptr);
  sim_lidar_config_t cfg;
  sim_lidar_config_default(&cfg);
  char err[256] = "";
  EXPECT_EQ(sim_lidar_create(r.m, "no_such_body", &cfg, err, sizeof err), nullptr);
  EXPECT_NE(std::string(err).find("no_such_body"), std::string::npos) << err;
  cfg.range_max_m = 0.1;
  EXPECT_EQ(sim_lidar_create(r.m, "car", &cfg, err, sizeof err), nullptr);
  EXPECT_NE(std::string(err).find("range"), std::string::npos) << err;
}

extern "C" {
#include <autodrive_lidar_scan_t.h>
#include <lcm/lcm.h>

#include "sim_lidar_lcm.h"
}

namespace {
struct Got {
  int n = 0;
  std::vector<float> ranges;
  std::string frame;
  float inc = 0, amax = 0, rmax = 0;
  int64_t utime = 0;
};
void on_scan(const lcm_recv_buf_t *, const char *, const autodrive_lidar_scan_t *msg, void *user) {
  Got *g = static_cast<Got *>(user);
  g->n++;
  g->ranges.assign(msg->ranges_m, msg->ranges_m + msg->num_ranges);
  g->frame = msg->frame_id;
  g->inc = msg->angle_increment_rad;
  g->amax = msg->angle_max_rad;
  g->rmax = msg->range_max_m;
  g->utime = msg->utime;
}
}  // namespace

TEST(SimLidar, PublishesLidarScanOnLcm) {
  room::Room r;
  ASSERT_NE(r.m, nullptr);
  sim_lidar_config_t cfg;
  sim_lidar_config_default(&cfg);
  cfg.range_max_m = 2.0;  // so the message carries +inf too
  sim_lidar_t *l = make_lidar(r.m, cfg);
  ASSERT_NE(l, nullptr);
  lcm_t *lcm = lcm_create("memq://");
  ASSERT_NE(lcm, nullptr);
  Got got;
  autodrive_lidar_scan_t_subscription_t *sub =
      autodrive_lidar_scan_t_subscribe(lcm, "NIGEL1_LIDAR", on_scan, &got);
  EXPECT_EQ(sim_lidar_publish(lcm, "NIGEL1_LIDAR", "laser", sim_lidar_last_scan(l)), -1);  // empty
  sim_lidar_scan_now(r.m, r.d, l, 777);
  ASSERT_EQ(sim_lidar_publish(lcm, "NIGEL1_LIDAR", "laser", sim_lidar_last_scan(l)), 0);
  ASSERT_GE(lcm_handle_timeout(lcm, 1000), 0);
  ASSERT_EQ(got.n, 1);
  EXPECT_EQ(got.utime, 777);
  EXPECT_EQ(got.frame, "laser");
  EXPECT_NEAR(got.amax, 359 * M_PI / 180, 1e-5);
  EXPECT_FLOAT_EQ(got.rmax, 2.0f);
  ASSERT_EQ(got.ranges.size(), 360u);
  int inf = 0;
  for (int i = 0; i < 360; i++) {
    EXPECT_EQ(got.ranges[i], sim_lidar_last_scan(l)->ranges_m[i]) << "ray " << i;
    inf += std::isinf(got.ranges[i]);
  }
  EXPECT_GT(inf, 0);
  autodrive_lidar_scan_t_unsubscribe(lcm, sub);
  lcm_destroy(lcm);
  sim_lidar_destroy(l);
}
