// The overhead Eye camera over a real map: both cars' roof tags (tag36h11 ids 1 and 2) decode
// with libapriltag at the true ids and where the ground truth says they are (the sensors
// library's renderer, camera and tag textures).
#include <gtest/gtest.h>
#include <math.h>

#include "sim_test_util.h"

#include <autodrive_vehicle.h>

#include <apriltag/apriltag.h>
#include <apriltag/tag36h11.h>

#include "sim_camera.h"
#include "sim_render.h"

namespace {

TEST(Eye, RoofTagsDecodeAtTheirIdsAndPositions) {
  simtest::Sim s("constant:throttle=0.3,steering=0.2", 2);
  ASSERT_NE(s.s, nullptr) << s.err;
  ASSERT_TRUE(s.run_to(1.0)) << s.err;  // moving and turned a little
  const mjModel *m = sim_render_model(s.s);
  char err[512] = "";
  sim_render_t *r = sim_render_create(m, 1280, 960, SIM_RENDER_AUTO, err, sizeof err);
  ASSERT_NE(r, nullptr) << err;
  sim_camera_t *cam = sim_camera_create(r, m, "eye", "eye", 1280, 960, 90, err, sizeof err);
  ASSERT_NE(cam, nullptr) << err;
  ASSERT_EQ(sim_camera_capture(cam, m, sim_render_data(s.s), sim_time_us(s.s)), 0);
  const uint8_t *rgb = sim_camera_rgb(cam);
  image_u8_t *gray = image_u8_create(1280, 960);
  for (int y = 0; y < 960; y++)
    for (int x = 0; x < 1280; x++) {
      const uint8_t *p = rgb + 3 * (y * 1280 + x);
      gray->buf[y * gray->stride + x] = (uint8_t)((p[0] * 30 + p[1] * 59 + p[2] * 11) / 100);
    }
  apriltag_family_t *fam = tag36h11_create();
  apriltag_detector_t *det = apriltag_detector_create();
  apriltag_detector_add_family(det, fam);
  det->quad_decimate = 1.0f;
  zarray_t *found = apriltag_detector_detect(det, gray);
  double k[9];
  sim_camera_intrinsics(m, mj_name2id(m, mjOBJ_CAMERA, "eye"), 1280, 960, k);
  const double cam_h = m->cam_pos[3 * mj_name2id(m, mjOBJ_CAMERA, "eye") + 2];
  int seen[3] = {0, 0, 0};
  for (int i = 0; i < zarray_size(found); i++) {
    apriltag_detection_t *d;
    zarray_get(found, i, &d);
    ASSERT_TRUE(d->id == 1 || d->id == 2) << "unexpected tag id " << d->id;
    seen[d->id]++;
    // project the car's tag centre (ground truth + roof offset) through the camera
    const sim_truth_t t = s.truth(d->id);
    const double tx = t.pos_m[0] + AUTODRIVE_VEHICLE_TAG_POS_M_X * cos(t.yaw_rad),
                 ty = t.pos_m[1] + AUTODRIVE_VEHICLE_TAG_POS_M_X * sin(t.yaw_rad);
    const double depth = cam_h - (t.pos_m[2] + AUTODRIVE_VEHICLE_TAG_POS_M_Z);
    const double u = k[2] + k[0] * tx / depth, v = k[5] - k[4] * ty / depth;  // image up = +y
    // libapriltag's pixel centres are +0.5 px off OpenCV's
    EXPECT_NEAR(d->c[0] - 0.5, u, 2.0) << "tag " << d->id;
    EXPECT_NEAR(d->c[1] - 0.5, v, 2.0) << "tag " << d->id;
  }
  EXPECT_EQ(seen[1], 1);
  EXPECT_EQ(seen[2], 1);
  apriltag_detections_destroy(found);
  apriltag_detector_destroy(det);
  tag36h11_destroy(fam);
  image_u8_destroy(gray);
  sim_camera_destroy(cam);
  sim_render_destroy(r);
}

}  // namespace
