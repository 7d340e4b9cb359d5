// Camera model of the Eye: intrinsics (pinhole + plumb_bob distortion) and the camera pose in
// the map frame, with YAML load/save. Pixel convention everywhere in the Eye is OpenCV's: the
// centre of pixel (col, row) is at (x, y) = (col, row), so pixel col covers [col-0.5, col+0.5].
#pragma once
#include <opencv2/core.hpp>

#include <string>
#include <vector>

namespace eye {

struct Intrinsics {
  int width_px = 0;
  int height_px = 0;
  cv::Matx33d k = cv::Matx33d::eye();  // camera matrix [px]
  std::vector<double> dist;            // k1 k2 p1 p2 k3 [unitless]
  double rms_px = 0.0;                 // reprojection RMS of the calibration [px]
  int views = 0;                       // images used by the calibration
};

// Camera pose: X_cam = r_cam_map * X_map + t_cam_map [m]. Map frame: x, y on the floor, z up.
struct CameraPose {
  cv::Matx33d r_cam_map = cv::Matx33d::eye();
  cv::Vec3d t_cam_map = {0, 0, 0};
  cv::Vec3d centre_map() const;  // camera centre in the map frame [m]
};

Intrinsics intrinsics_load(const std::string &path);
void intrinsics_save(const std::string &path, const Intrinsics &in);

// Undistorted, normalised image coordinates (x/z, y/z) of pixel points.
std::vector<cv::Point2d> intrinsics_normalise(const Intrinsics &in,
                                              const std::vector<cv::Point2d> &px);
// Pixel of a map point (with distortion).
cv::Point2d camera_project(const Intrinsics &in, const CameraPose &pose, const cv::Vec3d &p_map);
// Intersects the ray of a normalised image point with the horizontal plane z = z_m [m].
// Returns false if the ray is parallel to or points away from the plane.
bool camera_ray_to_plane(const CameraPose &pose, const cv::Point2d &norm, double z_m,
                         cv::Vec2d *xy_m);

}  // namespace eye
