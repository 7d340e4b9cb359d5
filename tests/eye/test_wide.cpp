// Wide-angle lens, whole-field detection, camera health and several cameras as one Eye, on
// frames of our renderer with the lens rendered (k1 -0.30, k2 0.10).
#include <gtest/gtest.h>

#include <autodrive/angles.hpp>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgcodecs.hpp>

#include <cmath>
#include <set>

#include "eye_error.hpp"
#include "eye_fuse.hpp"
#include "eye_health.hpp"
#include "eye_render.hpp"
#include "eye_rowdecode.hpp"
#include "eye_scanplan.hpp"
#include "eye_source.hpp"
#include "eye_synth.hpp"
#include "eye_test_util.hpp"
#include "eye_tracker.hpp"

namespace {

// A small wide-angle scene (fast under ASan; tags keep their pixel size), calibrated from its
// reference tags like a user would.
struct Wide {
  eye::SynthScene s;
  std::vector<eye::RefTag> refs;
  eye::RunConfig cfg;
};

Wide wide_scene(int w = 800, int h = 450) {
  Wide x;
  x.s = eye::synth_scene_wide(w, h);
  x.refs = eye::synth_reference_tags_in_view(x.s);
  eye::DetectorParams dp;
  dp.decimate = 1;
  eye::Detector det(dp);
  const auto m =
      eye::map_calibrate(x.s.in, x.refs, {det.detect(eye::synth_frame(x.s, {}, x.refs, 3))});
  x.cfg.in = x.s.in;
  x.cfg.pose = m.pose;
  x.cfg.locate = x.s.car;
  for (int k = 1; k <= 10; ++k) x.cfg.vehicles.push_back({"NIGEL" + std::to_string(k), k, 0.0});
  return x;
}

double pos_err_mm(const eye::CarPose &p, const eye::SynthCar &t) {
  return 1000 * std::hypot(p.x_m - t.x_m, p.y_m - t.y_m);
}

}  // namespace

// The lens in the renderer is OpenCV's: tag corners detected in a distorted frame sit where
// cv::projectPoints (with the distortion) puts the true corners.
TEST(Lens, RenderedDistortionMatchesOpenCvProjection) {
  Wide x = wide_scene();
  x.s.noise_sigma = 0;
  x.s.blur_sigma_px = 0.6;
  std::vector<eye::SynthCar> cars;
  // Cars near the corners and edges, where the lens bends most, and one in the middle.
  for (const cv::Point2d f :
       {cv::Point2d(0.08, 0.12), cv::Point2d(0.92, 0.12), cv::Point2d(0.08, 0.88),
        cv::Point2d(0.92, 0.88), cv::Point2d(0.5, 0.5), cv::Point2d(0.5, 0.1)}) {
    const cv::Vec2d p = eye::synth_pixel_to_plane(
        x.s, {f.x * x.s.in.width_px, f.y * x.s.in.height_px}, x.s.car.tag_offset_m[2]);
    cars.push_back({static_cast<int>(cars.size()) + 1, p[0] - x.s.car.tag_offset_m[0], p[1], 0.7});
  }
  eye::DetectorParams dp;
  dp.decimate = 1;
  eye::Detector det(dp);
  const auto dets = det.detect(eye::synth_frame(x.s, cars, {}, 1));
  ASSERT_EQ(dets.size(), cars.size());
  double sum = 0, worst = 0;
  for (const auto &d : dets) {
    const auto truth = eye_test::truth_corners(x.s, cars[static_cast<size_t>(d.id - 1)]);
    for (size_t i = 0; i < 4; ++i) {
      const double e = cv::norm(d.corners_px[i] - truth[i]);
      sum += e;
      worst = std::max(worst, e);
    }
  }
  const double mean = sum / (4.0 * static_cast<double>(dets.size()));
  std::printf("corner error through the lens: mean %.3f px, max %.3f px\n", mean, worst);
  // libapriltag fits straight lines to edges the lens bends slightly (a real lens does the
  // same): a small bias at the edges, well below the 20+ px of an unmodelled lens.
  EXPECT_LT(mean, 0.3);
  EXPECT_LT(worst, 0.6);
  // Without the lens model the same corners are pixels off at the image edges.
  eye::Intrinsics pinhole = x.s.in;
  pinhole.dist = {0, 0, 0, 0, 0};
  const auto far = eye::camera_project(pinhole, x.s.pose, {cars[0].x_m, cars[0].y_m, 0.13});
  const auto near = eye::camera_project(x.s.in, x.s.pose, {cars[0].x_m, cars[0].y_m, 0.13});
  EXPECT_GT(cv::norm(far - near), 20.0);
}

// The plan scans the whole frame coarsely and the image border (small tags) finely.
TEST(WholeField, PlanIsFinerWhereTagsAreSmall) {
  const Wide x = wide_scene();
  const double z = x.s.car.tag_offset_m[2];
  const auto mid = eye::expected_tag_side_px(x.cfg.in, x.cfg.pose, z, 0.08,
                                             {x.s.in.width_px / 2.0, x.s.in.height_px / 2.0});
  const auto corner = eye::expected_tag_side_px(x.cfg.in, x.cfg.pose, z, 0.08, {5.0, 5.0});
  std::printf("expected tag side: centre %.1f-%.1f px, corner %.1f-%.1f px\n", mid[0], mid[1],
              corner[0], corner[1]);
  EXPECT_GT(mid[0], 30.0);
  EXPECT_LT(corner[0], 26.0);
  // The 0.08 m tags of this scene are small nearly everywhere: the plan is one scan at
  // decimate 1 (cheaper than the padded regions). With larger tags most of the frame suits
  // decimate 2 and only the far side and the corners need finer: a mixed plan.
  EXPECT_EQ(eye::plan_full_scan(x.cfg.in, x.cfg.pose, z, 0.08, 2.0f).regions.size(), 1u);
  eye::ScanPlan plan;
  double tag_m = 0;
  for (double t : {0.11, 0.12, 0.13, 0.14, 0.15, 0.16}) {
    plan = eye::plan_full_scan(x.cfg.in, x.cfg.pose, z, t, 2.0f);
    tag_m = t;
    if (plan.regions.size() >= 2) break;
  }
  std::printf("mixed plan with %.2f m tags: %zu regions\n", tag_m, plan.regions.size());
  ASSERT_GE(plan.regions.size(), 2u);
  EXPECT_GT(plan.max_tag_px, 0.9 * 38.0 * tag_m / 0.08);  // at least the centre tag
  bool corner_fine = false, centre_coarse = false;
  double area = 0;
  for (const auto &r : plan.regions) {
    area += r.rect.area();
    corner_fine = corner_fine || (r.decimate < 2.0f && r.rect.contains({3, 3}));
    centre_coarse = centre_coarse || (r.decimate == 2.0f &&
                                      r.rect.contains({x.s.in.width_px / 2, x.s.in.height_px / 2}));
  }
  EXPECT_TRUE(corner_fine);
  EXPECT_TRUE(centre_coarse);
  // Cheaper than one scan at the finest level (pixels / decimate^2).
  double cost = 0;
  float finest = 2.0f;
  for (const auto &r : plan.regions) {
    cost += r.rect.area() / (static_cast<double>(r.decimate) * r.decimate);
    finest = std::min(finest, r.decimate);
  }
  EXPECT_LT(cost, x.s.in.width_px * x.s.in.height_px / (static_cast<double>(finest) * finest));
  EXPECT_GT(area, x.s.in.width_px * x.s.in.height_px);
  // The staggered scan: its bands cover every region.
  cv::Mat covered(x.s.in.height_px, x.s.in.width_px, CV_8UC1, cv::Scalar(0));
  for (int k = 0; k < 10; ++k)
    for (const auto &r : eye::plan_slice(plan, k, 10, x.s.in.height_px)) covered(r.rect).setTo(255);
  EXPECT_EQ(cv::countNonZero(covered), x.s.in.width_px * x.s.in.height_px);
  // A pinhole looking straight down at big tags needs nothing finer.
  EXPECT_EQ(eye::decimate_for_side(40.0, 2.0f, 16.0), 2.0f);
  EXPECT_EQ(eye::decimate_for_side(25.0, 2.0f, 16.0), 1.5f);
  EXPECT_EQ(eye::decimate_for_side(20.0, 2.0f, 16.0), 1.0f);
}

// 10 cars on the wide lens, tags 20-40 px, edges and corners included, with window tracking:
// every car in every frame, poses within bounds.
TEST(WholeField, EveryCarAtTheEdgesOfAWideLensIsFound) {
  const Wide x = wide_scene();
  const int frames = 16;
  const auto drive = eye::synth_wide_drive(x.s, frames);
  eye::Tracker tr(x.cfg);
  int seen = 0, total = 0;
  double ss = 0, worst = 0, tag_min = 1e9;
  for (int i = 0; i < frames; ++i) {
    const auto &cars = drive[static_cast<size_t>(i)];
    const auto poses = tr.process(eye::synth_frame(x.s, cars, x.refs, static_cast<uint64_t>(i)));
    for (const auto &c : cars) {
      ++total;
      tag_min = std::min(tag_min, eye::synth_tag_side_px(x.s, c));
      for (const auto &p : poses)
        if (p.tag_id == c.tag_id) {
          ++seen;
          const double e = pos_err_mm(p, c);
          ss += e * e;
          worst = std::max(worst, e);
        }
    }
  }
  const double rms = std::sqrt(ss / std::max(1, seen));
  std::printf("wide lens: %d/%d car frames posed, smallest tag %.1f px, RMS %.2f mm, max %.2f mm\n",
              seen, total, tag_min, rms, worst);
  EXPECT_LT(tag_min, 26.0);
  // The detector's contrast followed the rendered noise (sigma 6): noise-only patches are
  // skipped, and still every car is found.
  std::printf("noise sigma %.2f, min contrast %d grey levels\n", tr.noise_sigma(),
              tr.min_contrast());
  EXPECT_GT(tr.noise_sigma(), 4.0);
  EXPECT_LT(tr.noise_sigma(), 7.0);
  EXPECT_GE(tr.min_contrast(), 40);
  EXPECT_EQ(seen, total);
  EXPECT_LT(rms, 1.5);
  EXPECT_LT(worst, 5.0);
}

// Each staggered band reaches down only as far as the tallest tag whose top row lies in it, yet
// every tag of a frame is whole in some band: scanning the n bands finds every car.
TEST(WholeField, StaggeredBandsFindEveryTagOfAStillFrame) {
  const Wide x = wide_scene();
  const double z = x.cfg.locate.base_link_height_m + x.cfg.locate.tag_offset_m[2];
  const auto plan = eye::plan_full_scan(x.cfg.in, x.cfg.pose, z, x.cfg.locate.tag_size_m, 2.0f);
  const auto drive = eye::synth_wide_drive(x.s, 8);
  eye::DetectorParams dp;
  dp.min_contrast = 40;  // the noise-adaptive contrast of the tracker at this noise (above)
  eye::Detector det(dp);
  const int n = 10;
  int rows = 0;
  for (int k = 0; k < n; ++k)
    for (const auto &r : eye::plan_slice(plan, k, n, x.s.in.height_px))
      rows = std::max(rows, r.rect.height);
  // One-sided padding: a band is its share of the frame plus at most sqrt(2) largest tags.
  std::printf("tallest band %d rows of %d (largest tag %.1f px)\n", rows, x.s.in.height_px,
              plan.max_tag_px);
  EXPECT_LE(rows, x.s.in.height_px / n + 1 + std::ceil(std::sqrt(2.0) * plan.max_tag_px));
  for (size_t f = 0; f < drive.size(); f += 7) {
    const cv::Mat g = eye::synth_frame(x.s, drive[f], x.refs, 40 + f);
    std::set<int> found;
    for (int k = 0; k < n; ++k)
      for (const auto &r : eye::plan_slice(plan, k, n, x.s.in.height_px))
        for (const auto &d : det.detect(g, r.rect, r.decimate)) found.insert(d.id);
    for (const auto &c : drive[f]) EXPECT_TRUE(found.count(c.tag_id)) << "car " << c.tag_id;
  }
}

// detector.threads 2 (windows on both threads, a whole-frame scan in two halves) poses the
// same cars as one thread, within a small fraction of the error budget, from a decoded frame
// and from a JPEG decoded on the second thread while the caller's searches the windows as their
// rows come in (the same pixels as cv::imdecode; every tracked car from track(), none left
// for finish()).
TEST(Tracking, TwoDetectorThreadsPoseTheSameCars) {
  const Wide x = wide_scene();
  const auto drive = eye::synth_wide_drive(x.s, 40);
  eye::RunConfig two = x.cfg;
  two.detector.threads = 2;
  eye::Tracker t1(x.cfg), t2(two), t2_jpeg(two);
  int fulls = 0;
  for (size_t i = 0; i < 12; ++i) {
    // A jump (every car ~300 px on along its loop) at frame 6: windows miss, a whole-frame scan
    // in halves.
    const auto &cars = drive[i < 6 ? i : i + 20];
    std::vector<uint8_t> jpg;
    cv::imencode(".jpg", eye::synth_frame(x.s, cars, x.refs, 60 + i), jpg,
                 {cv::IMWRITE_JPEG_QUALITY, 90});
    const cv::Mat g = eye::decode_gray(jpg.data(), jpg.size(), "frame");
    const auto dec = std::make_shared<eye::RowDecoder>(jpg.data(), jpg.size(), "frame");
    const auto p1 = t1.process(g), p2 = t2.process(g);
    const auto p3 = t2_jpeg.track({cv::Mat(), dec});
    const auto late = t2_jpeg.finish();
    fulls += t2.last_was_full_scan() + t2_jpeg.last_was_full_scan();
    EXPECT_EQ(cv::norm(dec->image(), g, cv::NORM_INF), 0.0) << "frame " << i;
    EXPECT_TRUE(late.empty()) << "frame " << i;
    for (const auto *p : {&p1, &p2, &p3}) ASSERT_EQ(p->size(), cars.size()) << "frame " << i;
    for (const auto &a : p1)
      for (const auto *p : {&p2, &p3})
        for (const auto &b : *p)
          if (a.tag_id == b.tag_id) {
            EXPECT_LT(1000 * std::hypot(a.x_m - b.x_m, a.y_m - b.y_m), 0.5) << "car " << a.tag_id;
            EXPECT_LT(std::abs(autodrive::angle_wrap_rad(a.yaw_rad - b.yaw_rad)), 0.002);
          }
  }
  EXPECT_GE(fulls, 4);  // the first frame and the jump, on both
}

// The tracked cars' poses come from track(), before the band: a car that drives into view is
// found by finish() (the staggered band) within full_every frames, and tracked from then on.
TEST(Tracking, TrackedCarsComeBeforeTheBandFindsANewOne) {
  const Wide x = wide_scene();
  const auto drive = eye::synth_wide_drive(x.s, 20);
  eye::Tracker t(x.cfg);
  const size_t arrives = 3;
  long found_at = -1;
  std::set<int> before;  // the cars posed in the frame before
  for (size_t i = 0; i < drive.size(); ++i) {
    std::vector<eye::SynthCar> cars;
    for (const auto &c : drive[i])
      if (c.tag_id != 10 || i >= arrives) cars.push_back(c);
    const cv::Mat g = eye::synth_frame(x.s, cars, x.refs, 90 + i);
    std::set<int> tracked, late;
    for (const auto &p : t.track(g)) tracked.insert(p.tag_id);
    for (const auto &p : t.finish()) late.insert(p.tag_id);
    if (i > 0) {
      EXPECT_EQ(tracked, before) << "frame " << i;
    }
    if (late.count(10) && found_at < 0) found_at = static_cast<long>(i);
    EXPECT_TRUE(late.empty() || late == std::set<int>{10}) << "frame " << i;
    before = tracked;
    before.insert(late.begin(), late.end());
  }
  ASSERT_GE(found_at, static_cast<long>(arrives));
  EXPECT_LT(found_at, static_cast<long>(arrives) + x.cfg.tracking.full_every);
}

// A frame that is not a JPEG is refused with its name before anything is decoded; a colour
// JPEG decodes to the same grey as cv::imdecode.
TEST(Tracking, RowDecoderNamesBadDataAndDecodesColourToGrey) {
  const std::vector<uint8_t> junk = {1, 2, 3, 4, 5, 6, 7, 8};
  try {
    eye::RowDecoder d(junk.data(), junk.size(), "EYE_IMAGE@42");
    FAIL() << "junk decoded";
  } catch (const eye::Error &e) {
    EXPECT_NE(std::string(e.what()).find("EYE_IMAGE@42"), std::string::npos) << e.what();
  }
  EXPECT_THROW(eye::RowDecoder(junk.data(), 0, "empty"), eye::Error);
  cv::Mat bgr(120, 160, CV_8UC3);
  cv::randu(bgr, 0, 255);
  std::vector<uint8_t> jpg;
  cv::imencode(".jpg", bgr, jpg);
  eye::RowDecoder d(jpg.data(), jpg.size(), "colour");
  d.decode();
  EXPECT_TRUE(d.wait_rows(d.height_px()));
  EXPECT_EQ(cv::norm(d.image(), eye::decode_gray(jpg.data(), jpg.size(), "colour"), cv::NORM_INF),
            0.0);
}

// The noise estimate follows the noise added, not the tags' edges or the vignetting.
TEST(WholeField, NoiseEstimateFollowsTheNoiseNotTheEdges) {
  Wide x = wide_scene();
  const auto cars = eye::synth_wide_drive(x.s, 1)[0];
  for (double sigma : {2.0, 6.0}) {
    x.s.noise_sigma = sigma;
    const double est = eye::estimate_noise_sigma(eye::synth_frame(x.s, cars, x.refs, 3));
    std::printf("noise sigma %.1f: estimated %.2f\n", sigma, est);
    EXPECT_NEAR(est, sigma, 0.2 * sigma);
  }
}

// Same id found by two overlapping regions: one detection; far apart: both (ambiguous).
TEST(WholeField, OverlappingRegionsMergeTheSameTag) {
  eye::Detection a;
  a.id = 3;
  a.margin = 50;
  a.corners_px = {cv::Point2d(0, 30), cv::Point2d(30, 30), cv::Point2d(30, 0), cv::Point2d(0, 0)};
  a.centre_px = {15, 15};
  eye::Detection b = a;
  b.margin = 60;
  b.centre_px = {15.2, 15.1};
  eye::Detection c = a;
  c.centre_px = {300, 15};
  const auto m = eye::merge_detections({a, b, c});
  ASSERT_EQ(m.size(), 2u);
  EXPECT_EQ(m[0].margin, 60.0f);
}

// A bumped camera (5 mm and 0.3 deg after calibration) is found within 30 frames by its
// reference tags; its poses then carry an inflated covariance. The unmoved camera stays quiet.
TEST(Health, BumpedCameraIsFlaggedWithin30FramesAndInflatesCovariance) {
  const Wide x = wide_scene(640, 360);
  eye::SynthScene moved = x.s;
  cv::Matx33d rot;
  cv::Rodrigues(cv::Vec3d(0.6, 0.8, 0.0) * (0.3 * M_PI / 180), rot);
  moved.pose.r_cam_map = rot * moved.pose.r_cam_map;
  moved.pose.t_cam_map = rot * moved.pose.t_cam_map + cv::Vec3d(0.003, -0.004, 0.0);
  eye::CameraHealth still("still", x.cfg.in, x.cfg.pose, x.refs);
  eye::CameraHealth bumped("bumped", x.cfg.in, x.cfg.pose, x.refs);
  eye::Tracker ts(x.cfg), tb(x.cfg);
  const auto drive = eye::synth_wide_drive(x.s, 30);
  int found = -1;
  for (int i = 0; i < 30; ++i) {
    // 3 of the 10 cars: enough traffic over the reference tags, quick to render under ASan.
    const std::vector<eye::SynthCar> cars(drive[static_cast<size_t>(i)].begin(),
                                          drive[static_cast<size_t>(i)].begin() + 3);
    auto ps = ts.process(eye::synth_frame(x.s, cars, x.refs, static_cast<uint64_t>(100 + i)));
    EXPECT_FALSE(still.observe(i * 33333, ts.last_detections(), &ps));
    auto pb = tb.process(eye::synth_frame(moved, cars, x.refs, static_cast<uint64_t>(100 + i)));
    std::vector<eye::CarPose> raw = pb;
    if (bumped.observe(i * 33333, tb.last_detections(), &pb)) found = i;
    if (bumped.status().moved && !pb.empty()) {
      EXPECT_NEAR(pb[0].cov[0], 100.0 * raw[0].cov[0], 1e-12);
    }
  }
  std::printf("bumped at frame %d: residual %.2f mm / %.2f px (still camera %.2f mm / %.2f px)\n",
              found, bumped.status().ref_rms_mm, bumped.status().ref_rms_px,
              still.status().ref_rms_mm, still.status().ref_rms_px);
  EXPECT_GE(found, 0);
  EXPECT_LT(found, 30);
  EXPECT_TRUE(bumped.status().moved);
  EXPECT_EQ(bumped.status().cov_scale, 100.0);
  EXPECT_FALSE(still.status().moved);
  EXPECT_GE(still.status().ref_tags_seen, 1);  // those in the last band or window
  EXPECT_LT(still.status().ref_rms_mm, 1.5);
  EXPECT_GT(still.status().fps_hz, 29.0);
  EXPECT_LT(still.status().fps_hz, 31.0);
}

// Covariance-weighted fusion: the better camera dominates, the fused covariance is smaller.
TEST(MultiCam, FusionWeighsByCovariance) {
  eye::CarPose a, b;
  a.vehicle = b.vehicle = "NIGEL1";
  a.x_m = 1.0;
  b.x_m = 1.004;
  a.yaw_rad = M_PI - 0.01;
  b.yaw_rad = -M_PI + 0.01;  // the same heading across the wrap
  a.cov = {1e-6, 0, 0, 0, 1e-6, 0, 0, 0, 1e-4};
  b.cov = {3e-6, 0, 0, 0, 3e-6, 0, 0, 0, 1e-4};
  const auto f = eye::fuse_poses({{a}, {b}});
  ASSERT_EQ(f.size(), 1u);
  EXPECT_NEAR(f[0].x_m, 1.001, 1e-9);
  EXPECT_NEAR(std::abs(f[0].yaw_rad), M_PI, 1e-9);
  EXPECT_NEAR(f[0].cov[0], 0.75e-6, 1e-12);
  EXPECT_EQ(f[0].cameras, 2);
}

// Two cameras side by side over one map, overlapping by ~0.5 m; a car drives from one view
// into the other: one pose per frame, no gap, fused where both see it, within bounds.
TEST(MultiCam, HandoverWithoutGapAndFusedPoses) {
  eye::SynthScene base = eye::synth_scene(640, 480, 0.08);
  base.blur_sigma_px = 0.6;
  base.noise_sigma = 2.0;
  base.in.dist = {-0.10, 0.02, 0, 0, 0};
  std::vector<eye::SynthScene> cams(2, base);
  cams[0].pose = eye::camera_look_at({0.9, 1.0, 1.5}, {0.9, 1.0, 0.0}, {0, 1, 0});
  cams[1].pose = eye::camera_look_at({2.3, 1.0, 1.5}, {2.3, 1.0, 0.0}, {0, 1, 0});
  // Shared reference tags along the map, in view of one or both cameras.
  std::vector<eye::RefTag> refs;
  for (int k = 0; k < 6; ++k)
    refs.push_back({100 + k, 0.3 + 0.55 * k, k % 2 ? 0.45 : 1.55, 0.0, 0.3 * k, 0.10});
  std::vector<eye::RunConfig> cfgs;
  std::vector<std::vector<eye::RefTag>> cam_refs;
  std::vector<std::vector<std::vector<eye::Detection>>> cal_frames;
  eye::DetectorParams dp;
  dp.decimate = 1;
  eye::Detector det(dp);
  for (size_t c = 0; c < 2; ++c) {
    cal_frames.push_back({det.detect(eye::synth_frame(cams[c], {}, refs, 5 + c))});
    const auto m = eye::map_calibrate(cams[c].in, refs, cal_frames.back());
    eye::RunConfig rc = eye_test::config_for(cams[c], m.pose);
    rc.camera_name = c ? "east" : "west";
    rc.tracking.roi = true;
    cfgs.push_back(rc);
    cam_refs.push_back(refs);
  }
  // calibrate-map's overlap report: the shared tag(s) land within a millimetre in both.
  const auto agree = eye::map_overlap_agreement(refs, cfgs[0].in, cfgs[0].pose, cal_frames[0],
                                                cfgs[1].in, cfgs[1].pose, cal_frames[1]);
  std::printf("overlap: %zu shared tags, %.3f mm rms\n", agree.tags.size(), agree.rms_mm);
  ASSERT_GE(agree.tags.size(), 1u);
  EXPECT_LT(agree.rms_mm, 1.0);
  eye::MultiEye multi(cfgs, cam_refs);
  const int frames = 40;
  int gaps = 0, fused = 0;
  double ss = 0;
  for (int i = 0; i < frames; ++i) {
    const eye::SynthCar car{1, 0.35 + 2.5 * i / (frames - 1.0), 1.0, 0.05};
    std::vector<cv::Mat> imgs;
    for (size_t c = 0; c < 2; ++c)
      imgs.push_back(eye::synth_frame(cams[c], {car}, refs, static_cast<uint64_t>(i * 2 + c)));
    const auto poses = multi.process(imgs, i * 33333);
    if (poses.size() != 1) {
      ++gaps;
      continue;
    }
    const double e = pos_err_mm(poses[0], car);
    ss += e * e;
    if (poses[0].cameras == 2) {
      ++fused;
      const auto &per = multi.last_per_camera();
      EXPECT_LT(poses[0].cov[0], per[0][0].cov[0]);
      EXPECT_LT(poses[0].cov[0], per[1][0].cov[0]);
    }
  }
  const double rms = std::sqrt(ss / (frames - gaps));
  std::printf("two cameras: %d gap frames, %d fused frames, RMS %.2f mm\n", gaps, fused, rms);
  EXPECT_EQ(gaps, 0);
  EXPECT_GE(fused, 3);
  EXPECT_LT(rms, 2.0);
  EXPECT_FALSE(multi.health(0).status().moved);
  EXPECT_FALSE(multi.health(1).status().moved);
}
