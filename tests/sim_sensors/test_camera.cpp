// Headless cameras: a real render of the test room (EGL or OSMesa), JPEG round trip, camera
// intrinsics, and the overhead frame's roof tags decoded by libapriltag at the true ids.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include <dlfcn.h>
#include <jpeglib.h>

#include "room.hpp"

extern "C" {
#include <apriltag/apriltag.h>
#include <apriltag/tag36h11.h>

#include "sim_camera.h"
#include "sim_jpeg.h"
#include "sim_render.h"
}

namespace {

struct Px {
  int r, g, b;
};
Px px(const uint8_t *rgb, int w, int x, int y) {
  const uint8_t *p = rgb + 3 * ((size_t)y * w + x);
  return {p[0], p[1], p[2]};
}

// Writes an RGB frame as PPM next to the test binary when SIM_SENSORS_DUMP is set (debugging).
void maybe_dump(const char *name, const uint8_t *rgb, int w, int h) {
  if (!std::getenv("SIM_SENSORS_DUMP")) return;
  FILE *f = std::fopen(name, "wb");
  if (!f) return;
  std::fprintf(f, "P6 %d %d 255\n", w, h);
  std::fwrite(rgb, 3, (size_t)w * h, f);
  std::fclose(f);
}

struct Scene {
  room::Room room;
  sim_render_t *r = nullptr;
  explicit Scene(sim_render_backend_t b = SIM_RENDER_AUTO) {
    if (!room.m) return;
    char err[256] = "";
    r = sim_render_create(room.m, 1280, 960, b, err, sizeof err);
    EXPECT_NE(r, nullptr) << err;
  }
  ~Scene() { sim_render_destroy(r); }
};

// The room's front camera at 640x480 with one frame captured, or NULL (the test failed, why).
sim_camera_t *front_camera_captured(Scene &s) {
  char err[256] = "";
  sim_camera_t *c = sim_camera_create(s.r, s.room.m, "car_cam_front", "camera_front", 640, 480, 90,
                                      err, sizeof err);
  if (!c) {
    ADD_FAILURE() << err;
    return nullptr;
  }
  if (sim_camera_capture(c, s.room.m, s.room.d, 42) != 0) {
    ADD_FAILURE() << "the first capture failed";
    sim_camera_destroy(c);
    return nullptr;
  }
  return c;
}

}  // namespace

void check_front_frame(sim_render_backend_t backend) {
  Scene s(backend);
  ASSERT_NE(s.r, nullptr);
  sim_camera_t *c = front_camera_captured(s);
  ASSERT_NE(c, nullptr);
  const uint8_t *rgb = sim_camera_rgb(c);
  maybe_dump("front.ppm", rgb, 640, 480);
  // not blank: many distinct grey levels
  std::vector<int> seen(256, 0);
  for (size_t i = 0; i < 640u * 480 * 3; i += 3) seen[(rgb[i] + rgb[i + 1] + rgb[i + 2]) / 3] = 1;
  int levels = 0;
  for (int v : seen) levels += v;
  EXPECT_GT(levels, 20);
  // the blue pillar is straight ahead, the green floor at the bottom (rows are top-down), the
  // red front wall to the left of the pillar
  Px centre = px(rgb, 640, 320, 240), bottom = px(rgb, 640, 320, 470),
     left = px(rgb, 640, 100, 240);
  EXPECT_GT(centre.b, centre.r + 40) << centre.r << "," << centre.g << "," << centre.b;
  EXPECT_GT(centre.b, centre.g + 40);
  EXPECT_GT(bottom.g, bottom.r + 40) << bottom.r << "," << bottom.g << "," << bottom.b;
  EXPECT_GT(bottom.g, bottom.b + 40);
  EXPECT_GT(left.r, left.g + 40) << left.r << "," << left.g << "," << left.b;
  EXPECT_GT(left.r, left.b + 40);
  sim_camera_destroy(c);
}

// --camera-scale: a frame rendered at half size per side and stretched back keeps its size and
// what it shows (within a few grey levels on average), but is not the full render
TEST(SimCamera, RenderScaleKeepsTheFrameSizeAndWhatItShows) {
  Scene s(SIM_RENDER_AUTO);
  ASSERT_NE(s.r, nullptr);
  sim_camera_t *c = front_camera_captured(s);
  ASSERT_NE(c, nullptr);
  const std::vector<uint8_t> full(sim_camera_rgb(c), sim_camera_rgb(c) + 640 * 480 * 3);
  EXPECT_EQ(sim_camera_set_render_scale(c, 0.1), -1);  // below SIM_CAMERA_MIN_SCALE
  EXPECT_EQ(sim_camera_set_render_scale(c, 1.5), -1);
  ASSERT_EQ(sim_camera_set_render_scale(c, 0.5), 0);
  ASSERT_EQ(sim_camera_capture(c, s.room.m, s.room.d, 43), 0);
  EXPECT_EQ(sim_camera_width(c), 640);
  EXPECT_EQ(sim_camera_height(c), 480);
  const uint8_t *half = sim_camera_rgb(c);
  double diff = 0;
  for (size_t i = 0; i < full.size(); i++) diff += std::abs(int(full[i]) - int(half[i]));
  diff /= double(full.size());
  printf("render scale 0.5: mean |full - scaled| %.2f grey levels\n", diff);
  EXPECT_GT(diff, 0.0);  // it did render smaller
  EXPECT_LT(diff, 6.0);  // and shows the same room
  Px centre = px(half, 640, 320, 240);
  EXPECT_GT(centre.b, centre.r + 40);  // the blue pillar ahead, as in full
  sim_camera_destroy(c);
}

TEST(SimCamera, FrontFrameShowsTheRoomTopDown) {
  check_front_frame(SIM_RENDER_AUTO);
}

// ctest runs every test in its own process; run alone, OSMesa must not follow libEGL
TEST(SimCamera, OsmesaBackendRendersTheSameRoom) {
  if (void *egl = dlopen("libEGL.so.1", RTLD_NOW | RTLD_NOLOAD)) {
    dlclose(egl);
    room::Room room;
    char err[256] = "";
    EXPECT_EQ(sim_render_create(room.m, 64, 64, SIM_RENDER_OSMESA, err, sizeof err), nullptr);
    EXPECT_NE(std::string(err).find("libEGL"), std::string::npos) << err;
    GTEST_SKIP() << "libEGL already loaded in this process (run the test alone, as ctest does)";
  }
  check_front_frame(SIM_RENDER_OSMESA);
}

TEST(SimCamera, JpegDecodesBackToTheFrame) {
  Scene s;
  ASSERT_NE(s.r, nullptr);
  sim_camera_t *c = front_camera_captured(s);
  ASSERT_NE(c, nullptr);
  size_t n = 0;
  const uint8_t *jpg = sim_camera_jpeg(c, &n);
  ASSERT_GT(n, 1000u);
  ASSERT_EQ(jpg[0], 0xFF);
  ASSERT_EQ(jpg[1], 0xD8);
  jpeg_decompress_struct d;
  jpeg_error_mgr e;
  d.err = jpeg_std_error(&e);
  jpeg_create_decompress(&d);
  jpeg_mem_src(&d, jpg, (unsigned long)n);
  ASSERT_EQ(jpeg_read_header(&d, TRUE), JPEG_HEADER_OK);
  jpeg_start_decompress(&d);
  ASSERT_EQ(d.output_width, 640u);
  ASSERT_EQ(d.output_height, 480u);
  ASSERT_EQ(d.output_components, 3);
  std::vector<uint8_t> out(640 * 480 * 3);
  while (d.output_scanline < d.output_height) {
    JSAMPROW row = out.data() + (size_t)d.output_scanline * 640 * 3;
    jpeg_read_scanlines(&d, &row, 1);
  }
  jpeg_finish_decompress(&d);
  jpeg_destroy_decompress(&d);
  double err_sum = 0;
  for (size_t i = 0; i < out.size(); i++) err_sum += std::abs(out[i] - sim_camera_rgb(c)[i]);
  EXPECT_LT(err_sum / out.size(), 4.0);  // quality 90: a few levels of mean error
  sim_camera_destroy(c);
}

TEST(SimCamera, IntrinsicsFromFovy) {
  Scene s;
  ASSERT_NE(s.room.m, nullptr);
  int id = mj_name2id(s.room.m, mjOBJ_CAMERA, "car_cam_front");
  double k[9];
  sim_camera_intrinsics(s.room.m, id, 640, 480, k);
  // fovy 48.8 deg at 4:3 is Nigel's 62.2 deg horizontal field of view
  const double hfov_deg = 2 * std::atan(320.0 / k[0]) * 180 / M_PI;
  EXPECT_NEAR(hfov_deg, SIM_CAMERA_HFOV_DEG, 0.1);
  EXPECT_DOUBLE_EQ(k[0], k[4]);
  EXPECT_DOUBLE_EQ(k[2], 319.5);
  EXPECT_DOUBLE_EQ(k[5], 239.5);
  EXPECT_EQ(k[8], 1.0);
}

TEST(SimCamera, BadCameraOrSizeIsAClearError) {
  Scene s;
  ASSERT_NE(s.r, nullptr);
  char err[256] = "";
  EXPECT_EQ(sim_camera_create(s.r, s.room.m, "nope", "x", 640, 480, 90, err, sizeof err), nullptr);
  EXPECT_NE(std::string(err).find("nope"), std::string::npos) << err;
  EXPECT_EQ(sim_camera_create(s.r, s.room.m, "eye", "x", 4000, 480, 90, err, sizeof err), nullptr);
  EXPECT_NE(std::string(err).find("4000"), std::string::npos) << err;
}

TEST(SimCamera, OverheadRoofTagsDecodeAtTrueIdsAndHeadings) {
  Scene s;
  ASSERT_NE(s.r, nullptr);
  const int w = 1280, h = 960;
  char err[256] = "";
  sim_camera_t *c = sim_camera_create(s.r, s.room.m, "eye", "eye", w, h, 90, err, sizeof err);
  ASSERT_NE(c, nullptr) << err;
  ASSERT_EQ(sim_camera_capture(c, s.room.m, s.room.d, 0), 0);
  const uint8_t *rgb = sim_camera_rgb(c);
  maybe_dump("eye.ppm", rgb, w, h);
  std::vector<uint8_t> grey((size_t)w * h);
  for (size_t i = 0; i < grey.size(); i++)
    grey[i] = (uint8_t)((rgb[3 * i] * 77 + rgb[3 * i + 1] * 150 + rgb[3 * i + 2] * 29) >> 8);
  image_u8_t im = {w, h, w, grey.data()};
  apriltag_family_t *fam = tag36h11_create();
  apriltag_detector_t *det = apriltag_detector_create();
  apriltag_detector_add_family(det, fam);
  det->quad_decimate = 1.0f;
  det->nthreads = 1;
  zarray_t *dets = apriltag_detector_detect(det, &im);
  // truth: each car's tag centre projected into the eye camera, and the car's yaw
  const int eye = mj_name2id(s.room.m, mjOBJ_CAMERA, "eye");
  double k[9];
  sim_camera_intrinsics(s.room.m, eye, w, h, k);
  const mjtNum *cp = s.room.d->cam_xpos + 3 * eye;
  struct Truth {
    int id;
    const char *body;
    double yaw_deg;
    bool found;
  } truth[2] = {{room::kTagCar, "car", 0.0, false}, {room::kTagOther, "other", 30.0, false}};
  for (int i = 0; i < zarray_size(dets); i++) {
    apriltag_detection_t *dd;
    zarray_get(dets, i, &dd);
    for (Truth &t : truth) {
      if (dd->id != t.id) continue;
      t.found = true;
      const int b = mj_name2id(s.room.m, mjOBJ_BODY, t.body);
      const mjtNum *bp = s.room.d->xpos + 3 * b;
      const double yaw = t.yaw_deg * M_PI / 180;
      const double wx = bp[0] + SIM_TAGS_OFFSET_X_M * std::cos(yaw);
      const double wy = bp[1] + SIM_TAGS_OFFSET_X_M * std::sin(yaw);
      const double depth = cp[2] - (bp[2] + SIM_TAGS_OFFSET_Z_M);
      // camera looks down with image right = world +x, image up = world +y
      const double u = k[2] + k[0] * (wx - cp[0]) / depth;
      const double v = k[5] - k[4] * (wy - cp[1]) / depth;
      // libapriltag's pixel centres are 0.5 px off OpenCV's (docs/reference/eye.md)
      EXPECT_NEAR(dd->c[0] - 0.5, u, 1.0) << "tag " << t.id;
      EXPECT_NEAR(dd->c[1] - 0.5, v, 1.0) << "tag " << t.id;
      // heading: from the bottom edge's middle (p0, p1) to the top edge's middle (p3, p2)
      const double dx = (dd->p[3][0] + dd->p[2][0] - dd->p[0][0] - dd->p[1][0]) / 2;
      const double dy = (dd->p[3][1] + dd->p[2][1] - dd->p[0][1] - dd->p[1][1]) / 2;
      const double heading_deg = std::atan2(-dy, dx) * 180 / M_PI;  // image y is down
      EXPECT_NEAR(std::remainder(heading_deg - t.yaw_deg, 360.0), 0.0, 2.0) << "tag " << t.id;
      // apparent size: black square of SIM_TAGS_SIZE_M
      const double side_px = std::hypot(dd->p[1][0] - dd->p[0][0], dd->p[1][1] - dd->p[0][1]);
      EXPECT_NEAR(side_px, k[0] * SIM_TAGS_SIZE_M / depth, 1.5) << "tag " << t.id;
    }
  }
  for (const Truth &t : truth) EXPECT_TRUE(t.found) << "tag " << t.id << " not detected";
  EXPECT_EQ(zarray_size(dets), 2);
  apriltag_detections_destroy(dets);
  apriltag_detector_destroy(det);
  tag36h11_destroy(fam);
  sim_camera_destroy(c);
}

extern "C" {
#include <autodrive_camera_info_t.h>
#include <autodrive_compressed_image_t.h>
#include <lcm/lcm.h>
}

namespace {
struct GotImg {
  int n = 0;
  std::vector<uint8_t> data;
  std::string format, frame;
  int w = 0, h = 0;
  int64_t utime = 0;
};
void on_img(const lcm_recv_buf_t *, const char *, const autodrive_compressed_image_t *msg,
            void *user) {
  GotImg *g = static_cast<GotImg *>(user);
  g->n++;
  g->data.assign(msg->data, msg->data + msg->size_bytes);
  g->format = msg->format;
  g->frame = msg->frame_id;
  g->w = msg->width_px;
  g->h = msg->height_px;
  g->utime = msg->utime;
}
struct GotInfo {
  int n = 0;
  double k[9] = {0};
  int num_d = -1;
  std::string model;
};
void on_info(const lcm_recv_buf_t *, const char *, const autodrive_camera_info_t *msg, void *user) {
  GotInfo *g = static_cast<GotInfo *>(user);
  g->n++;
  std::copy(msg->k, msg->k + 9, g->k);
  g->num_d = msg->num_d;
  g->model = msg->distortion_model;
}
}  // namespace

TEST(SimCamera, PublishesJpegAndCameraInfoOnLcm) {
  Scene s;
  ASSERT_NE(s.r, nullptr);
  char err[256] = "";
  sim_camera_t *c = sim_camera_create(s.r, s.room.m, "car_cam_front", "camera_front", 640, 480, 85,
                                      err, sizeof err);
  ASSERT_NE(c, nullptr) << err;
  lcm_t *lcm = lcm_create("memq://");
  ASSERT_NE(lcm, nullptr);
  GotImg img;
  GotInfo info;
  autodrive_compressed_image_t_subscription_t *s1 =
      autodrive_compressed_image_t_subscribe(lcm, "NIGEL1_CAM_FRONT", on_img, &img);
  autodrive_camera_info_t_subscription_t *s2 =
      autodrive_camera_info_t_subscribe(lcm, "NIGEL1_CAM_FRONT_INFO", on_info, &info);
  EXPECT_NE(sim_camera_publish_image(c, lcm, "NIGEL1_CAM_FRONT"), 0);  // nothing captured yet
  ASSERT_EQ(sim_camera_capture(c, s.room.m, s.room.d, 5000), 0);
  ASSERT_EQ(sim_camera_publish_image(c, lcm, "NIGEL1_CAM_FRONT"), 0);
  ASSERT_EQ(sim_camera_publish_info(c, s.room.m, lcm, "NIGEL1_CAM_FRONT_INFO", 5000), 0);
  for (int i = 0; i < 2; i++) ASSERT_GE(lcm_handle_timeout(lcm, 1000), 0);
  ASSERT_EQ(img.n, 1);
  size_t n = 0;
  const uint8_t *jpg = sim_camera_jpeg(c, &n);
  EXPECT_EQ(img.data, std::vector<uint8_t>(jpg, jpg + n));
  EXPECT_EQ(img.format, "jpeg");
  EXPECT_EQ(img.frame, "camera_front");
  EXPECT_EQ(img.w, 640);
  EXPECT_EQ(img.h, 480);
  EXPECT_EQ(img.utime, 5000);
  ASSERT_EQ(info.n, 1);
  double k[9];
  sim_camera_intrinsics(s.room.m, mj_name2id(s.room.m, mjOBJ_CAMERA, "car_cam_front"), 640, 480, k);
  for (int i = 0; i < 9; i++) EXPECT_EQ(info.k[i], k[i]);
  EXPECT_EQ(info.num_d, 5);
  EXPECT_EQ(info.model, "plumb_bob");
  autodrive_compressed_image_t_unsubscribe(lcm, s1);
  autodrive_camera_info_t_unsubscribe(lcm, s2);
  lcm_destroy(lcm);
  sim_camera_destroy(c);
}
