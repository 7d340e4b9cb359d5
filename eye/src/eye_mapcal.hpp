// Map calibration: the camera pose in the map frame from reference tags at known map
// coordinates, with residuals in millimetres on each tag's own plane.
#pragma once
#include <array>
#include <string>
#include <vector>

#include "eye_camera.hpp"
#include "eye_detect.hpp"

namespace eye {

struct RefTag {
  int id = -1;
  double x_m = 0, y_m = 0, z_m = 0;  // tag centre on the map [m] (z: height above the floor)
  double yaw_rad = 0;                // tag x axis (top of the print) from map x [rad]
  double size_m = 0;                 // black border edge [m]
};

struct TagResidual {
  int id = -1;
  double rms_mm = 0;  // corner residual on the tag's plane [mm]
};

struct MapCalib {
  CameraPose pose;
  int width_px = 0, height_px = 0;
  double rms_mm = 0, max_mm = 0;  // over all reference corners seen
  std::vector<TagResidual> tags;
  std::vector<int> missing_ids;  // reference tags never detected
};

// Map coordinates of a reference tag's corners, libapriltag order (bottom-left, bottom-right,
// top-right, top-left of the print).
std::array<cv::Point3d, 4> reftag_corners_map(const RefTag &r);

// Reads the reference tag list:  tags: [{id, x_m, y_m, z_m, yaw_rad, size_m}, ...]
std::vector<RefTag> reftags_load(const std::string &path);

// Solves the camera pose from the detections of one or more frames of a fixed camera. Throws
// eye::Error if fewer than min_tags distinct reference tags are seen.
MapCalib map_calibrate(const Intrinsics &in, const std::vector<RefTag> &refs,
                       const std::vector<std::vector<Detection>> &frames, int min_tags = 3);

// How two calibrated cameras agree where they overlap: for each reference tag both see, the
// RMS distance [mm] between its corners as camera A and as camera B put them on the tag's own
// plane (rays of the detected corners through each camera's calibration).
struct OverlapAgreement {
  std::vector<TagResidual> tags;    // shared tags, their A-vs-B corner distance RMS [mm]
  double rms_mm = -1, max_mm = -1;  // over all shared corners (-1: no shared tag)
};
OverlapAgreement map_overlap_agreement(const std::vector<RefTag> &refs, const Intrinsics &in_a,
                                       const CameraPose &pose_a,
                                       const std::vector<std::vector<Detection>> &frames_a,
                                       const Intrinsics &in_b, const CameraPose &pose_b,
                                       const std::vector<std::vector<Detection>> &frames_b);

void mapcal_save(const std::string &path, const MapCalib &m);
// Throws eye::Error naming the file and the field if it is missing or malformed.
MapCalib mapcal_load(const std::string &path);

}  // namespace eye
