// Synthetic frames with exact geometry: the calibration board set of autodrive-eye
// make-board-images (eye_boards), and the golden frames of the tests and the benchmark. Everything
// uses the Eye's pixel convention: the centre of pixel (col,row) is at (x,y) = (col,row) and the
// pixel covers the square [col-0.5,col+0.5] x [row-0.5,row+0.5]. Each output pixel is the
// box-filtered average of ss x ss point samples taken at the centres of its sub-squares, so edges
// are anti-aliased without any half-pixel shift. Lens distortion (the intrinsics' plumb_bob k1 k2
// p1 p2 k3) is rendered exactly where it matters: every sample point of the distorted image is
// taken back to its undistorted pixel (cv::undistortPoints at the pixel corners, bilinear inside a
// pixel: < 0.001 px for k1 -0.3) before the plane's homography is inverted.
#pragma once
#include <opencv2/core.hpp>

#include "eye_camera.hpp"

namespace eye {

// The printed tag36h11 bitmap of `id` from libapriltag's family codes, one pixel per cell
// (10 x 10 including the white border), 0 = black, 255 = white. Throws on a bad id.
cv::Mat render_tag_bitmap(int id);

// Homography taking (x, y) on the horizontal plane z = z_m of the map to undistorted pixels.
cv::Matx33d render_plane_to_image(const Intrinsics &in, const CameraPose &pose, double z_m);

// Undistorted pixel coordinates of every pixel corner of a distorted image: (h+1) x (w+1)
// CV_64FC2, entry (r, c) for the point (c - 0.5, r - 0.5). Empty for a distortion-free camera.
// Cached per camera (the last few intrinsics), so scenes may call it every frame.
const cv::Mat &render_undistort_grid(const Intrinsics &in);

// Paints texture `tex` (CV_8UC1) into `img` (CV_8UC1). h_tex_to_img maps texture coordinates
// (texel centres at integers, same convention) to undistorted image pixels; ss: samples per
// pixel side. `in`: the camera whose distortion is rendered (nullptr: none).
void render_texture(cv::Mat &img, const cv::Mat &tex, const cv::Matx33d &h_tex_to_img, int ss,
                    const Intrinsics *in = nullptr);

// Paints tag `id` whose black border is size_m wide, centred at (x_m, y_m) on plane z_m, its
// x axis (towards the top of the print) at yaw_rad from map x, seen through the camera's lens.
void render_tag(cv::Mat &img, const Intrinsics &in, const CameraPose &pose, int id, double size_m,
                double x_m, double y_m, double z_m, double yaw_rad, int ss);

// Paints a uniform rectangle (length_m along its x, width_m along its y) on plane z_m.
void render_rect(cv::Mat &img, const Intrinsics &in, const CameraPose &pose, uint8_t grey,
                 double length_m, double width_m, double x_m, double y_m, double z_m,
                 double yaw_rad, int ss);

// A camera at eye_m looking at target_m, with image "up" towards +up_m (REP-103 map frame).
CameraPose camera_look_at(const cv::Vec3d &eye_m, const cv::Vec3d &target_m, const cv::Vec3d &up_m);

// A checkerboard of cols x rows squares (square_m each) on the board plane z = 0, board
// frame -> camera by pose; renders into a w x h grey image, through the camera's lens.
cv::Mat render_checkerboard(const Intrinsics &in, const CameraPose &board_pose, int cols, int rows,
                            double square_m, int ss);

}  // namespace eye
