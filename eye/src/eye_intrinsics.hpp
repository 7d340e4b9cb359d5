// Intrinsic calibration from checkerboard views, with refusal of degenerate image sets.
#pragma once
#include <opencv2/core.hpp>

#include <string>
#include <vector>

#include "eye_camera.hpp"

namespace eye {

// OpenCV 4.6's aruco marker and ChArUco corners put pixel centres at +0.5 like libapriltag
// (measured on the board's own drawing at 1:1: +0.49 px), unlike findChessboardCornersSB:
// ChArUco corners are shifted by this much [px] (asserted by eye.Intrinsics.Charuco*).
constexpr double kArucoToOpencvPx = -0.5;

struct IntrinsicsParams {
  bool charuco = false;  // ChArUco board (aruco DICT_5X5_100 markers) instead of a checkerboard
  double marker_ratio = 0.7;  // ChArUco: marker edge / square edge
  int inner_cols = 9;         // inner corners along the board's width (squares - 1)
  int inner_rows = 6;         // inner corners along its height
  double square_m = 0.025;    // square edge [m] (scales extrinsics only, not K)
  int min_views = 8;          // fewer usable views: refused
  double min_coverage = 0.5;  // fraction of a 4x4 grid over the image that corners must reach
  double max_rms_px = 1.0;    // a worse reprojection RMS: refused
  bool fix_k3 = true;         // k3 only for wide-angle lenses; free, it soaks up noise
};

struct IntrinsicsReport {
  Intrinsics in;
  int views_total = 0;  // images offered
  int views_used = 0;   // images where the board was found
  double coverage = 0;  // fraction of the 4x4 grid cells holding a corner
  cv::Size image_size;
  std::vector<int> used;                            // index of each used image in the input
  std::vector<std::vector<cv::Point2f>> corners;    // per used image: the corners found [px]
  std::vector<std::vector<cv::Point3f>> points;     // their places on the board [m]
  std::vector<bool> cells = std::vector<bool>(16);  // 4x4 grid cells (row-major) reached
  std::vector<double> view_rms_px;                  // per used image, after the calibration
};

// Finds the board in each image (CV_8UC1; a ChArUco view counts if >= 6 corners are seen):
// the corners and the coverage, no refusal yet (the coverage picture is drawn from this).
// Throws eye::Error on no images or images of different sizes.
IntrinsicsReport intrinsics_detect(const std::vector<cv::Mat> &gray_views,
                                   const IntrinsicsParams &p);
// Calibrates from a detection: fills rep.in and rep.view_rms_px (each image's reprojection
// RMS). Throws eye::Error with a clear reason on too few views, poor coverage or too high an RMS.
void intrinsics_solve(IntrinsicsReport &rep, const IntrinsicsParams &p);
// intrinsics_detect, then intrinsics_solve.
IntrinsicsReport intrinsics_calibrate(const std::vector<cv::Mat> &gray_views,
                                      const IntrinsicsParams &p);

}  // namespace eye
