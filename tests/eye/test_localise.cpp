// Map calibration on synthetic frames with known tag placements, then golden frames with known
// car poses through the calibrated camera: error bounds, roof-height parallax, lost tags.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "eye_detect.hpp"
#include "eye_error.hpp"
#include "eye_mapcal.hpp"
#include "eye_test_util.hpp"
#include "eye_tracker.hpp"

namespace {

// The scene (720p, blur and noise) and its map calibration from the reference tags.
struct Calibrated {
  eye::SynthScene scene;
  eye::MapCalib map;
};

const Calibrated &calibrated() {
  static const Calibrated c = [] {
    Calibrated out;
    out.scene = eye::synth_scene(1280, 720, 0.10);
    out.scene.blur_sigma_px = 0.6;
    out.scene.noise_sigma = 2.0;
    const auto refs = eye::synth_reference_tags(out.scene);
    eye::DetectorParams dp;
    dp.decimate = 1;
    eye::Detector det(dp);
    const cv::Mat frame = eye::synth_frame(out.scene, {}, refs, 11);
    out.map = eye::map_calibrate(out.scene.in, refs, {det.detect(frame)});
    return out;
  }();
  return c;
}

}  // namespace

TEST(MapCalib, RecoversCameraPoseFromReferenceTags) {
  const Calibrated &c = calibrated();
  EXPECT_TRUE(c.map.missing_ids.empty());
  EXPECT_EQ(c.map.tags.size(), 8u);
  EXPECT_LT(c.map.rms_mm, 1.0);
  const cv::Vec3d err = c.map.pose.centre_map() - c.scene.pose.centre_map();
  EXPECT_LT(cv::norm(err), 0.01) << "camera centre off by " << cv::norm(err) << " m";
  const cv::Matx33d dr = c.map.pose.r_cam_map * c.scene.pose.r_cam_map.t();
  const double angle_rad = std::acos(std::min(1.0, (cv::trace(dr) - 1) / 2));
  EXPECT_LT(angle_rad, 0.2 * M_PI / 180);

  const std::string path = testing::TempDir() + "eye_map_roundtrip.yaml";
  eye::mapcal_save(path, c.map);
  const eye::MapCalib back = eye::mapcal_load(path);
  EXPECT_LT(cv::norm(back.pose.t_cam_map - c.map.pose.t_cam_map), 1e-9);
  EXPECT_NEAR(back.rms_mm, c.map.rms_mm, 1e-9);
  std::remove(path.c_str());
}

TEST(MapCalib, RefusesTooFewReferenceTags) {
  const Calibrated &c = calibrated();
  auto refs = eye::synth_reference_tags(c.scene);
  refs.resize(2);
  eye::Detector det;
  const cv::Mat frame = eye::synth_frame(c.scene, {}, refs, 3);
  try {
    eye::map_calibrate(c.scene.in, eye::synth_reference_tags(c.scene), {det.detect(frame)});
    FAIL() << "two reference tags accepted";
  } catch (const eye::Error &e) {
    EXPECT_NE(std::string(e.what()).find("saw 2 of 8 reference tags"), std::string::npos)
        << e.what();
  }
}

// Golden frames: two cars at known poses all over the map, through the calibrated camera.
TEST(Golden, CarPosesWithinBounds) {
  const Calibrated &c = calibrated();
  eye::Tracker tr(eye_test::config_for(c.scene, c.map.pose));
  cv::RNG rng(2026);
  double ss_pos = 0, ss_yaw = 0;
  int n = 0;
  for (int k = 0; k < 16; ++k) {
    const eye::SynthCar a{1, rng.uniform(0.2, 2.8), rng.uniform(0.2, 1.8),
                          rng.uniform(-M_PI, M_PI)};
    eye::SynthCar b{2, rng.uniform(0.2, 2.8), rng.uniform(0.2, 1.8), rng.uniform(-M_PI, M_PI)};
    if (std::hypot(a.x_m - b.x_m, a.y_m - b.y_m) < 0.35)
      b.x_m = a.x_m > 1.5 ? a.x_m - 0.6 : a.x_m + 0.6;
    const auto poses = tr.process(eye::synth_frame(c.scene, {a, b}, {}, static_cast<uint64_t>(k)));
    ASSERT_EQ(poses.size(), 2u) << "frame " << k;
    for (const auto &p : poses) {
      const eye::SynthCar &t = p.vehicle == "NIGEL1" ? a : b;
      EXPECT_EQ(p.tag_id, t.tag_id);
      const double e_mm = 1000 * std::hypot(p.x_m - t.x_m, p.y_m - t.y_m);
      const double e_deg = std::abs(eye_test::angle_diff_rad(p.yaw_rad, t.yaw_rad)) * 180 / M_PI;
      EXPECT_LT(e_mm, 5.0) << p.vehicle << " frame " << k;
      EXPECT_LT(e_deg, 0.5) << p.vehicle << " frame " << k;
      ss_pos += e_mm * e_mm;
      ss_yaw += e_deg * e_deg;
      ++n;
      // covariance: positive variances, symmetric
      EXPECT_GT(p.cov[0], 0);
      EXPECT_GT(p.cov[8], 0);
      EXPECT_DOUBLE_EQ(p.cov[1], p.cov[3]);
    }
  }
  const double rms_mm = std::sqrt(ss_pos / n), rms_deg = std::sqrt(ss_yaw / n);
  std::printf("golden: %d poses, position rms %.3f mm, heading rms %.4f deg\n", n, rms_mm, rms_deg);
  EXPECT_LT(rms_mm, 2.0);
  EXPECT_LT(rms_deg, 0.25);
}

// The tag is on the roof: locating it on the floor plane instead would misplace the car by
// d*h/(H-h), tens of millimetres off-axis. The Eye must use the roof plane.
TEST(Golden, RoofHeightParallaxIsAccountedFor) {
  const Calibrated &c = calibrated();
  eye::RunConfig cfg = eye_test::config_for(c.scene, c.map.pose);
  eye::Tracker roof(cfg);
  cfg.locate.tag_offset_m[2] = 0.0;  // pretend the tag lies on the floor
  eye::Tracker floor(cfg);
  const eye::SynthCar car{1, 2.8, 1.8, 0.3};  // far off-axis
  const cv::Mat frame = eye::synth_frame(c.scene, {car}, {}, 5);
  const auto pr = roof.process(frame), pf = floor.process(frame);
  ASSERT_EQ(pr.size(), 1u);
  ASSERT_EQ(pf.size(), 1u);
  EXPECT_LT(1000 * std::hypot(pr[0].x_m - car.x_m, pr[0].y_m - car.y_m), 3.0);
  EXPECT_GT(1000 * std::hypot(pf[0].x_m - car.x_m, pf[0].y_m - car.y_m), 30.0);
}

TEST(Golden, PoseIsOfBaseLinkNotOfTag) {
  const Calibrated &c = calibrated();
  eye::Tracker tr(eye_test::config_for(c.scene, c.map.pose));
  const eye::SynthCar car{1, 1.0, 0.7, M_PI / 2};  // tag 35 mm ahead of base_link: +y here
  const auto p = tr.process(eye::synth_frame(c.scene, {car}, {}, 9));
  ASSERT_EQ(p.size(), 1u);
  EXPECT_NEAR(p[0].x_m, 1.0, 0.003);
  EXPECT_NEAR(p[0].y_m, 0.7, 0.003);
}

TEST(LostTag, NoPoseForUnseenOrUnknownTags) {
  const Calibrated &c = calibrated();
  eye::Tracker tr(eye_test::config_for(c.scene, c.map.pose));
  // nothing on the map
  EXPECT_TRUE(tr.process(eye::synth_frame(c.scene, {}, {}, 1)).empty());
  // a car whose tag is not configured
  EXPECT_TRUE(tr.process(eye::synth_frame(c.scene, {{9, 1.0, 1.0, 0.0}}, {}, 2)).empty());
  // NIGEL1 seen, then lost: the next frame publishes only NIGEL2 (no stale NIGEL1)
  const eye::SynthCar a{1, 0.8, 0.8, 0.0}, b{2, 2.0, 1.2, 1.0};
  auto p = tr.process(eye::synth_frame(c.scene, {a, b}, {}, 3));
  ASSERT_EQ(p.size(), 2u);
  p = tr.process(eye::synth_frame(c.scene, {b}, {}, 4));
  ASSERT_EQ(p.size(), 1u);
  EXPECT_EQ(p[0].vehicle, "NIGEL2");
}

TEST(LostTag, HalfCoveredTagGivesNoPose) {
  const Calibrated &c = calibrated();
  eye::Tracker tr(eye_test::config_for(c.scene, c.map.pose));
  const eye::SynthCar a{1, 1.2, 1.0, 0.0};
  cv::Mat frame = eye::synth_frame(c.scene, {a}, {}, 6);
  ASSERT_EQ(tr.process(frame).size(), 1u);
  // a hand (grey box) over half of the tag, just above the roof
  eye::render_rect(frame, c.scene.in, c.scene.pose, 150, 0.07, 0.2, 1.2 + 0.035 + 0.03, 1.0, 0.2,
                   0.0, 2);
  EXPECT_TRUE(tr.process(frame).empty());
}

TEST(LostTag, DuplicateTagInOneFrameGivesNoPose) {
  const Calibrated &c = calibrated();
  eye::Tracker tr(eye_test::config_for(c.scene, c.map.pose));
  const auto p =
      tr.process(eye::synth_frame(c.scene, {{1, 0.8, 0.8, 0.0}, {1, 2.0, 1.2, 0.0}}, {}, 7));
  EXPECT_TRUE(p.empty());
}

TEST(Frames, WrongSizeFrameIsRejected) {
  const Calibrated &c = calibrated();
  eye::Tracker tr(eye_test::config_for(c.scene, c.map.pose));
  EXPECT_THROW(tr.process(cv::Mat(480, 640, CV_8UC1, cv::Scalar(0))), eye::Error);
}

// Window tracking along a drive: every frame gives the pose, most frames without a full scan;
// a car that appears is found at the next full scan; a car that leaves gives no pose at once.
TEST(Tracking, WindowsFollowACarAndFullScansFindNewOnes) {
  const Calibrated &c = calibrated();
  eye::RunConfig cfg = eye_test::config_for(c.scene, c.map.pose);
  cfg.tracking.roi = true;
  cfg.tracking.full_every = 5;
  eye::Tracker tr(cfg);
  int full = 0, first2 = -1;
  for (int k = 0; k < 15; ++k) {
    const eye::SynthCar a{1, 0.6 + 0.02 * k, 0.8 + 0.01 * k, 0.3 + 0.02 * k};
    std::vector<eye::SynthCar> cars{a};
    const eye::SynthCar b{2, 2.3, 1.4, -1.0};
    if (k >= 6) cars.push_back(b);  // NIGEL2 drives in at frame 6
    const auto poses = tr.process(eye::synth_frame(c.scene, cars, {}, static_cast<uint64_t>(k)));
    full += tr.last_was_full_scan();
    bool seen1 = false, seen2 = false;
    for (const auto &p : poses) {
      const eye::SynthCar &t = p.vehicle == "NIGEL1" ? a : b;
      EXPECT_LT(1000 * std::hypot(p.x_m - t.x_m, p.y_m - t.y_m), 3.0)
          << p.vehicle << " frame " << k;
      seen1 |= p.vehicle == "NIGEL1";
      seen2 |= p.vehicle == "NIGEL2";
    }
    EXPECT_TRUE(seen1) << "frame " << k;
    // The periodic scan is staggered: one band of the frame per frame, the whole frame every
    // 5 frames, so NIGEL2 (in from frame 6) is found within 5 frames and then kept.
    if (seen2 && first2 < 0) first2 = k;
    if (first2 >= 0) {
      EXPECT_TRUE(seen2) << "frame " << k;
    }
  }
  EXPECT_GE(first2, 6);
  EXPECT_LE(first2, 10);
  EXPECT_EQ(full, 1);  // only the first frame is scanned whole at once
  // NIGEL1 leaves the map: no pose, no stale pose, from the very next frame
  EXPECT_TRUE(tr.process(eye::synth_frame(c.scene, {}, {}, 99)).empty());
}
