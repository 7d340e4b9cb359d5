// Intrinsic calibration round trip on synthetic checkerboard renders with a known camera
// matrix, and refusal of degenerate image sets.
#include <gtest/gtest.h>

#include <opencv2/aruco/charuco.hpp>
#include <opencv2/calib3d.hpp>

#include <cstdio>
#include <filesystem>

#include "eye_error.hpp"
#include "eye_intrinsics.hpp"
#include "eye_render.hpp"

namespace {

eye::Intrinsics truth_camera() {
  eye::Intrinsics in;
  in.width_px = 640;
  in.height_px = 480;
  in.k = cv::Matx33d(520.0, 0, 318.5, 0, 522.0, 241.0, 0, 0, 1);
  in.dist = {0, 0, 0, 0, 0};
  return in;
}

// The board (9x6 inner corners, 25 mm squares, 10x7 squares) seen from `n` poses spread over
// the image: board centre near each cell of a 4x3 grid, tilted by up to ~25 deg.
std::vector<cv::Mat> board_views(const eye::Intrinsics &in, int n, double spread,
                                 std::vector<eye::CameraPose> *poses = nullptr,
                                 double scale = 1.0) {
  std::vector<cv::Mat> out;
  const double sq = 0.025, bw = 10 * sq, bh = 7 * sq;
  for (int i = 0; i < n; ++i) {
    const double u = spread * (((i % 4) + 0.5) / 4.0 - 0.5),
                 v = spread * (((i / 4) % 3 + 0.5) / 3.0 - 0.5);
    const double ax = 0.6 * std::sin(1.7 * i), ay = 0.6 * std::cos(2.3 * i),
                 az = 0.2 * std::sin(0.9 * i);
    cv::Mat rvec = (cv::Mat_<double>(3, 1) << ax, ay, az), r;
    cv::Rodrigues(rvec, r);
    eye::CameraPose p;  // board -> camera
    p.r_cam_map = cv::Matx33d(r);
    const cv::Vec3d centre_board(bw / 2, bh / 2, 0);
    const cv::Vec3d centre_cam = scale * cv::Vec3d(u * 0.75, v * 0.55, 0.7 + 0.1 * (i % 3));
    p.t_cam_map = centre_cam - p.r_cam_map * centre_board;
    out.push_back(eye::render_checkerboard(in, p, 10, 7, sq, 2));
    if (poses) poses->push_back(p);
  }
  return out;
}

}  // namespace

TEST(Intrinsics, RoundTripRecoversKnownCameraMatrix) {
  const eye::Intrinsics truth = truth_camera();
  const auto views = board_views(truth, 12, 1.0);
  eye::IntrinsicsParams p;
  const auto rep = eye::intrinsics_calibrate(views, p);
  EXPECT_EQ(rep.views_used, 12);
  EXPECT_LT(rep.in.rms_px, 0.2);
  EXPECT_NEAR(rep.in.k(0, 0), truth.k(0, 0), 0.005 * truth.k(0, 0));
  EXPECT_NEAR(rep.in.k(1, 1), truth.k(1, 1), 0.005 * truth.k(1, 1));
  // The principal point is the least determined: ~1 px spread with 12 views whose corners
  // carry ~0.1 px render noise (the convention itself is asserted by the corner test below).
  EXPECT_NEAR(rep.in.k(0, 2), truth.k(0, 2), 2.0);
  EXPECT_NEAR(rep.in.k(1, 2), truth.k(1, 2), 2.0);
  EXPECT_LT(std::abs(rep.in.dist[0]), 0.02);

  const std::string path = testing::TempDir() + "eye_intrinsics_roundtrip.yaml";
  eye::intrinsics_save(path, rep.in);
  const eye::Intrinsics back = eye::intrinsics_load(path);
  EXPECT_EQ(back.width_px, 640);
  EXPECT_EQ(back.height_px, 480);
  for (int i = 0; i < 9; ++i) EXPECT_NEAR(back.k(i / 3, i % 3), rep.in.k(i / 3, i % 3), 1e-9);
  ASSERT_EQ(back.dist.size(), rep.in.dist.size());
  EXPECT_NEAR(back.rms_px, rep.in.rms_px, 1e-9);
  std::remove(path.c_str());
}

// OpenCV's chessboard corners and our renderer share the pixel-centre convention.
TEST(Intrinsics, ChessboardCornersMatchRenderedTruth) {
  const eye::Intrinsics truth = truth_camera();
  std::vector<eye::CameraPose> poses;
  const auto views = board_views(truth, 4, 1.0, &poses);
  double sx = 0, sy = 0;
  int n = 0;
  for (size_t v = 0; v < views.size(); ++v) {
    std::vector<cv::Point2f> c;
    ASSERT_TRUE(cv::findChessboardCornersSB(views[v], cv::Size(9, 6), c, cv::CALIB_CB_ACCURACY));
    for (int k = 0; k < 54; ++k) {
      const cv::Point2d t =
          eye::camera_project(truth, poses[v], {(k % 9 + 1) * 0.025, (k / 9 + 1) * 0.025, 0});
      sx += c[static_cast<size_t>(k)].x - t.x;
      sy += c[static_cast<size_t>(k)].y - t.y;
      ++n;
    }
  }
  EXPECT_NEAR(sx / n, 0.0, 0.05);
  EXPECT_NEAR(sy / n, 0.0, 0.05);
}

TEST(Intrinsics, RefusesTooFewViews) {
  const auto views = board_views(truth_camera(), 4, 1.0);
  try {
    eye::intrinsics_calibrate(views, eye::IntrinsicsParams());
    FAIL() << "4 views accepted";
  } catch (const eye::Error &e) {
    EXPECT_NE(std::string(e.what()).find("too few views"), std::string::npos) << e.what();
  }
}

TEST(Intrinsics, RefusesPoorCoverage) {
  // All boards near the image centre: corners never reach the image's outer cells.
  const auto views = board_views(truth_camera(), 10, 0.0);
  try {
    eye::intrinsics_calibrate(views, eye::IntrinsicsParams());
    FAIL() << "centre-only views accepted";
  } catch (const eye::Error &e) {
    EXPECT_NE(std::string(e.what()).find("poor coverage"), std::string::npos) << e.what();
  }
}

TEST(Intrinsics, RefusesHighRms) {
  auto views = board_views(truth_camera(), 10, 1.0);
  eye::IntrinsicsParams p;
  p.max_rms_px = 1e-4;  // no real calibration reaches this
  try {
    eye::intrinsics_calibrate(views, p);
    FAIL() << "rms bound ignored";
  } catch (const eye::Error &e) {
    EXPECT_NE(std::string(e.what()).find("RMS reprojection error too high"), std::string::npos)
        << e.what();
  }
}

TEST(Intrinsics, RefusesImagesWithoutBoard) {
  std::vector<cv::Mat> blank(10, cv::Mat(480, 640, CV_8UC1, cv::Scalar(90)));
  EXPECT_THROW(eye::intrinsics_calibrate(blank, eye::IntrinsicsParams()), eye::Error);
}

// ChArUco: the board image from OpenCV (5x5-bit markers, 10x7 squares of 25 mm, 40 px per
// square) as a texture on the board plane: texel u covers board x in [u, u+1] * sq / 40.
TEST(Intrinsics, CharucoRoundTripRecoversKnownCameraMatrix) {
  const eye::Intrinsics truth = truth_camera();
  const double sq = 0.025;
  const int px_per_sq = 40;
  auto board =
      cv::aruco::CharucoBoard::create(10, 7, static_cast<float>(sq), static_cast<float>(0.7 * sq),
                                      cv::aruco::getPredefinedDictionary(cv::aruco::DICT_5X5_100));
  cv::Mat tex;
  board->draw(cv::Size(10 * px_per_sq, 7 * px_per_sq), tex, 0, 1);
  const double s = sq / px_per_sq;
  const cv::Matx33d tex_to_board(s, 0, 0.5 * s, 0, s, 0.5 * s, 0, 0, 1);
  std::vector<cv::Mat> views;
  std::vector<eye::CameraPose> poses;
  // The checkerboard poses 0.6x as far: markers of 17.5 mm need ~20 px; boards may leave the
  // image partly, which ChArUco (unlike a checkerboard) tolerates.
  board_views(truth, 12, 1.0, &poses, 0.6);
  for (const auto &p : poses) {
    cv::Mat img(truth.height_px, truth.width_px, CV_8UC1, cv::Scalar(128));
    eye::render_texture(img, tex, eye::render_plane_to_image(truth, p, 0.0) * tex_to_board, 2);
    views.push_back(img);
  }
  // Corner convention: OpenCV's interpolated ChArUco corners vs their true projections carry
  // +0.5 px (pixel centres at +0.5), which eye::intrinsics_calibrate removes.
  {
    std::vector<int> mids, cids;
    std::vector<std::vector<cv::Point2f>> mc;
    std::vector<cv::Point2f> cc;
    cv::aruco::detectMarkers(views[5], board->dictionary, mc, mids);
    ASSERT_GE(cv::aruco::interpolateCornersCharuco(mc, mids, views[5], board, cc, cids), 20);
    double sx = 0, sy = 0;
    for (size_t i = 0; i < cc.size(); ++i) {
      const auto &b = board->chessboardCorners[static_cast<size_t>(cids[i])];
      const cv::Point2d t = eye::camera_project(truth, poses[5], {b.x, b.y, 0});
      sx += cc[i].x - t.x;
      sy += cc[i].y - t.y;
    }
    EXPECT_NEAR(sx / cc.size() + eye::kArucoToOpencvPx, 0.0, 0.1);
    EXPECT_NEAR(sy / cc.size() + eye::kArucoToOpencvPx, 0.0, 0.1);
  }
  eye::IntrinsicsParams p;
  p.charuco = true;
  const auto rep = eye::intrinsics_calibrate(views, p);
  std::printf("charuco: %d views, rms %.3f px, fx %.2f fy %.2f cx %.2f cy %.2f\n", rep.views_used,
              rep.in.rms_px, rep.in.k(0, 0), rep.in.k(1, 1), rep.in.k(0, 2), rep.in.k(1, 2));
  EXPECT_GE(rep.views_used, 10);
  EXPECT_LT(rep.in.rms_px, 0.3);
  EXPECT_NEAR(rep.in.k(0, 0), truth.k(0, 0), 0.005 * truth.k(0, 0));
  EXPECT_NEAR(rep.in.k(1, 1), truth.k(1, 1), 0.005 * truth.k(1, 1));
  EXPECT_NEAR(rep.in.k(0, 2), truth.k(0, 2), 2.0);
  EXPECT_NEAR(rep.in.k(1, 2), truth.k(1, 2), 2.0);
}
