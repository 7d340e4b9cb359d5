// The pixel-centre convention end to end: our renderer's coverage, then libapriltag's corners
// against the rendered truth (the +0.5 px trap of issue 6).
#include <gtest/gtest.h>

#include <cmath>

#include "eye_detect.hpp"
#include "eye_error.hpp"
#include "eye_test_util.hpp"

// A white rectangle whose left edge is at x = 10.0 covers half of pixel 10 (which spans
// [9.5, 10.5]); one at x = 10.25 covers a quarter of it. Pixel centres sit at integers.
TEST(Convention, RendererCoverageFollowsPixelCentres) {
  for (double edge : {10.0, 10.25}) {
    cv::Mat img(8, 40, CV_8UC1, cv::Scalar(0));
    const cv::Mat white(1, 1, CV_8UC1, cv::Scalar(255));
    // texel 0 covers u in [-0.5, 0.5] -> x = edge + 10 (u + 0.5), y spans the whole image
    const cv::Matx33d h(10, 0, edge + 5, 0, 20, 3.5, 0, 0, 1);
    eye::render_texture(img, white, h, 4);
    const double expect = 255.0 * (10.5 - edge);
    EXPECT_EQ(img.at<uint8_t>(4, 9), 0) << "edge " << edge;
    EXPECT_NEAR(img.at<uint8_t>(4, 10), expect, 1.0) << "edge " << edge;
    EXPECT_EQ(img.at<uint8_t>(4, 11), 255) << "edge " << edge;
    EXPECT_EQ(img.at<uint8_t>(4, 19), 255) << "edge " << edge;  // right edge at edge+10
    EXPECT_NEAR(img.at<uint8_t>(4, 20), 255.0 - expect, 1.0) << "edge " << edge;
  }
}

TEST(Convention, TagBitmapFromFamilyCodesDecodes) {
  // A large axis-aligned render of a few ids must decode to exactly those ids.
  eye::Detector det;
  for (int id : {0, 1, 7, 42, 586}) {
    cv::Mat img(200, 200, CV_8UC1, cv::Scalar(128));
    const cv::Mat bmp = eye::render_tag_bitmap(id);
    ASSERT_EQ(bmp.cols, 10);
    eye::render_texture(img, bmp, cv::Matx33d(12, 0, 40, 0, 12, 40, 0, 0, 1), 2);
    const auto d = det.detect(img);
    ASSERT_EQ(d.size(), 1u) << "id " << id;
    EXPECT_EQ(d[0].id, id);
  }
  EXPECT_THROW(eye::render_tag_bitmap(587), eye::Error);
}

// Corners of tags rendered at known poses: the corrected corners must be unbiased (mean
// within 0.03 px) and precise; the raw libapriltag corners carry the +0.5 px offset.
TEST(Convention, ApriltagCornersMatchRenderedTruth) {
  const eye::SynthScene s = eye::synth_scene(1280, 720, 0.10);
  eye::Detector det;
  cv::RNG rng(7);
  double sx = 0, sy = 0, ss = 0;
  int n = 0;
  for (int k = 0; k < 12; ++k) {
    const eye::SynthCar car{1, rng.uniform(0.2, 2.8), rng.uniform(0.2, 1.8),
                            rng.uniform(-3.1, 3.1)};
    const auto dets = det.detect(eye::synth_frame(s, {car}, {}, static_cast<uint64_t>(k)));
    ASSERT_EQ(dets.size(), 1u) << "frame " << k;
    const auto truth = eye_test::truth_corners(s, car);
    for (size_t i = 0; i < 4; ++i) {
      const cv::Point2d e = dets[0].corners_px[i] - truth[i];
      sx += e.x;
      sy += e.y;
      ss += e.dot(e);
      ++n;
    }
  }
  const double mx = sx / n, my = sy / n;
  EXPECT_NEAR(mx, 0.0, 0.03);
  EXPECT_NEAR(my, 0.0, 0.03);
  EXPECT_LT(std::sqrt(ss / n), 0.15);
  // Undo the correction: libapriltag's own convention is half a pixel off ours.
  EXPECT_NEAR(mx - eye::kApriltagToOpencvPx, 0.5, 0.03);
  EXPECT_NEAR(my - eye::kApriltagToOpencvPx, 0.5, 0.03);
}
