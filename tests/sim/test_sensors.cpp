// The sensors library wired into the sim core: LIDAR scans at ~7 Hz of sim time from the
// car's real mount, ranges against the known parking-school wall.
#include <gtest/gtest.h>
#include <math.h>

#include "sim_test_util.h"

#include "sim_lidar.h"

namespace {

TEST(Sensors, LidarScansAt7HzAndSeesTheWall) {
  simtest::Sim s(nullptr, 1, 0, -1, "parking_school", 1);
  ASSERT_NE(s.s, nullptr) << s.err;
  int scans = 0;
  const sim_lidar_scan_t *last = nullptr;
  char err[256];
  for (int k = 0; k < 3000; k++) {
    ASSERT_EQ(sim_step(s.s, err, sizeof err), 0) << err;
    const sim_lidar_scan_t *sc = sim_lidar_new_scan(s.s, 1);
    if (sc) {
      scans++;
      last = sc;
    }
  }
  EXPECT_GE(scans, 19);  // 7 Hz for 3 s
  EXPECT_LE(scans, 22);
  ASSERT_NE(last, nullptr);
  ASSERT_EQ(last->num_rays, 360);
  // car at the spawn (-1, 0.6) facing +x; the west wall's inner face is at x = -3.975; the
  // scanner sits 0.1445 m ahead of base_link: the ray pointing backwards (180 deg) reads
  // 3.1195 m, and the ray to the left (90 deg) meets the north wall (inner face y = 3.975)
  EXPECT_NEAR(last->ranges_m[180], 3.1195, 0.02);
  EXPECT_NEAR(last->ranges_m[90], 3.375, 0.02);
}

}  // namespace
