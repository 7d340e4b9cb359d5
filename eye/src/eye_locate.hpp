// From tag corners to a car pose: intersect each corner's ray with the roof plane (the tag's
// height above the floor, not the floor: no parallax), fit a 2D rigid transform to the tag's
// known corners, then step from the tag back to the car's base_link.
#pragma once

#include <autodrive_vehicle.h>
#include <opencv2/core.hpp>

#include <array>
#include <optional>
#include <string>
#include <vector>

#include "eye_camera.hpp"
#include "eye_detect.hpp"

namespace eye {

struct VehicleTag {
  std::string name;        // e.g. "NIGEL1"
  int tag_id = -1;         // tag36h11 id on its roof
  double tag_yaw_rad = 0;  // tag x axis (top of the print) relative to the car's x axis
};

struct LocateParams {
  double tag_size_m = AUTODRIVE_VEHICLE_TAG_SIZE_M;  // black border edge length [m]
  cv::Vec3d tag_offset_m = {AUTODRIVE_VEHICLE_TAG_POS_M_X, AUTODRIVE_VEHICLE_TAG_POS_M_Y,
                            AUTODRIVE_VEHICLE_TAG_POS_M_Z};  // tag centre in base_link [m]
  double base_link_height_m = 0.0;                           // base_link above the floor [m]
  double corner_sigma_px = 0.15;                             // corner noise for the covariance [px]
  double max_fit_rms_m = 0.01;                               // reject a fit worse than this [m]
};

struct CarPose {
  std::string vehicle;
  int tag_id = -1;
  double x_m = 0, y_m = 0, yaw_rad = 0;   // base_link on the map
  std::array<double, 9> cov{};            // x, y, yaw row-major [m^2, m rad, rad^2]
  double fit_rms_m = 0;                   // corner fit residual [m]
  std::array<cv::Point2d, 4> corners_px;  // for annotation
  int cameras = 1;                        // cameras whose poses were fused into this one
};

// Tag-frame corners [m] of a tag with black border size_m, in libapriltag order (bottom-left,
// bottom-right, top-right, top-left of the print). Tag frame: x towards the top of the print,
// y towards its left, z up out of the print.
std::array<cv::Vec2d, 4> tag_corners_tagframe(double size_m);

// The pose of the car carrying detection d, or nothing if the geometry is unusable (a corner
// ray misses the roof plane, or the four corners do not fit a square of the tag's size).
std::optional<CarPose> locate_car(const Intrinsics &in, const CameraPose &pose,
                                  const LocateParams &p, const VehicleTag &v, const Detection &d);

// 2D rigid fit dst ~ R(yaw) src + t over matching points; returns the RMS residual [m].
double fit_rigid2d(const std::vector<cv::Vec2d> &src, const std::vector<cv::Vec2d> &dst,
                   cv::Vec2d *t_m, double *yaw_rad);

}  // namespace eye
