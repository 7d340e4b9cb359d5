// A calibration set without a camera: the intrinsics board (IntrinsicsParams: a checkerboard of
// (inner_cols+1) x (inner_rows+1) squares) rendered through a configured camera model from many
// poses, spread so that the corners cover the image as calibrate-intrinsics asks
// (autodrive-eye make-board-images). And what a calibration tool shows its user: the coverage
// picture of the corners found.
#pragma once
#include <opencv2/core.hpp>

#include <vector>

#include "eye_camera.hpp"
#include "eye_intrinsics.hpp"

namespace eye {

struct BoardSetParams {
  int views = 16;              // images; the first 16 put the board once in each 4x4 grid cell
  double max_tilt_rad = 0.45;  // board tilt towards the camera, alternately about x and y
  double width_share = 0.25;   // the board spans about this share of the image width
  int ss = 2;                  // render samples per pixel side (anti-aliasing)
};

struct BoardView {
  cv::Mat image;            // CV_8UC1, the camera's size, with its lens distortion
  CameraPose board_to_cam;  // X_cam = r * X_board + t; board frame: its first square's corner
};

// Renders the board of p seen by camera `in` (its distortion included) from b.views poses: the
// board centre on the cells of a 4x4 grid over the image in turn (pulled in so the whole board
// stays in view), tilted by up to b.max_tilt_rad. Throws eye::Error for a ChArUco board (the
// renderer draws checkerboards) or a camera without a size.
std::vector<BoardView> boards_render(const Intrinsics &in, const IntrinsicsParams &p,
                                     const BoardSetParams &b);

// The coverage picture of a detection (intrinsics_detect): the image's 4x4 coverage grid with
// the cells the corners reached in green and the others in red, every corner found (a colour per
// image), and the coverage and RMS figures. BGR, the images' size.
cv::Mat intrinsics_coverage_image(const IntrinsicsReport &rep);

}  // namespace eye
