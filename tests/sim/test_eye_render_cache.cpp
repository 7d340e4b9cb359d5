// The overhead cameras' static-world cache (sim_render_cache.h) against a full render: Tiny
// Town's four Eye cameras, four cars put at seeded places and driving between frames, a traffic
// light switched, a late box appearing, night and day. Stated tolerance: per frame and camera,
// at most CACHE_MAX_DIFF_FRACTION of the pixels differ at all, whatever their difference (a
// car's pixels are drawn through a frustum narrowed to its rectangle: a vertex rounds a little
// differently, which flips an edge pixel or a depth tie where a wheel touches the floor; seen:
// ~5e-6 of the pixels, about 6 per frame).
#include <gtest/gtest.h>
#include <stdio.h>

#include <algorithm>
#include <cstdlib>
#include <random>
#include <vector>

#include "sim_test_util.h"
#include "sim_render.h"
#include "sim_render_cache.h"
#include "traffic_lights.h"

namespace {

constexpr int kW = 1280, kH = 960;
constexpr double CACHE_MAX_DIFF_FRACTION = 1e-4;  // of a frame's pixels (123 of 1280x960)

struct Diff {
  long pixels = 0;  // pixels where any channel differs
  int max_abs = 0;  // largest channel difference [8-bit levels]
};

Diff compare(const std::vector<uint8_t> &a, const std::vector<uint8_t> &b) {
  Diff d;
  for (size_t p = 0; p < a.size(); p += 3) {
    int m = 0;
    for (int c = 0; c < 3; c++) m = std::max(m, std::abs(int(a[p + c]) - int(b[p + c])));
    d.pixels += m > 0;
    d.max_abs = std::max(d.max_abs, m);
  }
  return d;
}

// Puts every car at a seeded pose on the floor under the cameras (a refused pose, on an
// obstacle or another car, is drawn again).
void scatter_cars(sim_t *s, std::mt19937 &rng) {
  std::uniform_real_distribution<double> x(-4.5, 4.5), y(-3.3, 3.3), yaw(-3.14, 3.14);
  char err[512];
  for (int c = 1; c <= sim_cars(s); c++)
    for (int tries = 0; tries < 50 && sim_teleport(s, c, x(rng), y(rng), yaw(rng), err, sizeof err);
         tries++) {
    }
}

TEST(EyeRenderCache, EqualsTheFullRenderWithinTolerance) {
  simtest::Sim s("constant:throttle=0.6,steering=0.4", 4, 0, -1, "tiny_town");
  ASSERT_NE(s.s, nullptr) << s.err;
  mjModel *m = sim_render_model(s.s);
  char err[512] = "";
  sim_render_t *r = sim_render_create(m, kW, kH, SIM_RENDER_AUTO, err, sizeof err);
  ASSERT_NE(r, nullptr) << err;
  std::vector<int> cams;
  std::vector<sim_render_cache_t *> caches;
  for (const char *name : {"eye1", "eye2", "eye3", "eye4"}) {
    cams.push_back(mj_name2id(m, mjOBJ_CAMERA, name));
    ASSERT_GE(cams.back(), 0) << name;
    caches.push_back(sim_render_cache_create(m, cams.back(), kW, kH, err, sizeof err));
    ASSERT_NE(caches.back(), nullptr) << err;
  }
  std::vector<uint8_t> full(kW * kH * 3), cached(kW * kH * 3);
  std::mt19937 rng(41);
  const int frames = 8;
  long differing = 0;
  int max_abs = 0, boxes = 0;
  for (int f = 0; f < frames; f++) {
    scatter_cars(s.s, rng);
    if (f == 3) {  // a green light switched to red: its lamps change colour and emission
      traffic_lights_t *tl = sim_traffic_lights(s.s);
      int green = -1;
      for (int i = 0; i < tl->n && green < 0; i++)
        if (tl->light[i].state == TL_GREEN) green = i;
      ASSERT_GE(green, 0) << "no green light at t = " << sim_time_us(s.s) * 1e-6 << " s";
      char why[256];
      ASSERT_EQ(tl_command(tl, tl->light[green].id, TL_RED, 0, sim_time_us(s.s), why, sizeof why),
                0)
          << why;
    }
    if (f == 4) {  // car 1 within the trigger radius of late_box_0 at (0, 1.2) m
      char e[256];
      ASSERT_EQ(sim_teleport(s.s, 1, 0.0, 0.55, 0.0, e, sizeof e), 0) << e;
    }
    sim_render_set_daylight(r, m, f != 5);  // night in frame 5
    while (sim_time_us(s.s) < 100000 * (f + 1)) {
      ASSERT_EQ(sim_step(s.s, err, sizeof err), 0) << err;
      for (int k = 0; k < sim_late_boxes(s.s); k++) boxes += sim_late_box_appeared(s.s, k, nullptr);
    }
    for (size_t i = 0; i < cams.size(); i++) {
      ASSERT_EQ(sim_render_camera(r, m, sim_render_data(s.s), cams[i], kW, kH, full.data()), 0);
      ASSERT_EQ(sim_render_camera_cached(r, caches[i], m, sim_render_data(s.s), cached.data()), 0);
      const Diff d = compare(full, cached);
      EXPECT_LE(d.pixels, CACHE_MAX_DIFF_FRACTION * kW * kH)
          << "frame " << f << " camera eye" << i + 1 << ": " << d.pixels
          << " pixels differ, by up to " << d.max_abs;
      differing += d.pixels;
      max_abs = std::max(max_abs, d.max_abs);
    }
  }
  EXPECT_EQ(boxes, 1);  // late_box_0 appeared (frame 4)
  long rebuilds = 0, promoted = 0, in_full = 0;
  for (auto *c : caches) {
    sim_render_cache_stats_t st;
    sim_render_cache_get_stats(c, &st);
    EXPECT_EQ(st.frames, frames);
    rebuilds += st.rebuilds;
    promoted += st.promoted;
    in_full += st.full;
    sim_render_cache_destroy(c);
  }
  printf(
      "cached vs full: %ld of %ld pixels differ (%.2g), by up to %d; %ld rebuilds, %ld world "
      "geoms promoted, %ld frames in full\n",
      differing, long(frames) * long(cams.size()) * kW * kH,
      double(differing) / (double(frames) * double(cams.size()) * kW * kH), max_abs, rebuilds,
      promoted, in_full);
  EXPECT_EQ(in_full, 0);  // Tiny Town has no transparent geom
  // rebuilt for: the first frame, the light, the late box, night, day again (5 each)
  EXPECT_EQ(rebuilds, 5 * long(cams.size()));
  // the switched light's red and green lamps and the late box, seen by every camera's cache
  EXPECT_EQ(promoted, 3 * long(cams.size()));
  sim_render_destroy(r);
}

TEST(EyeRenderCache, RefusesACameraThatMoves) {
  simtest::Sim s(nullptr, 1);
  ASSERT_NE(s.s, nullptr) << s.err;
  const mjModel *m = sim_render_model(s.s);
  const int front = mj_name2id(m, mjOBJ_CAMERA, "nigel1/cam_front");
  ASSERT_GE(front, 0);
  EXPECT_FALSE(sim_render_cache_applies(m, front));
  char err[256] = "";
  EXPECT_EQ(sim_render_cache_create(m, front, 640, 480, err, sizeof err), nullptr);
  EXPECT_NE(std::string(err).find("not fixed in the world"), std::string::npos) << err;
  EXPECT_TRUE(sim_render_cache_applies(m, mj_name2id(m, mjOBJ_CAMERA, "eye")));
}

}  // namespace
