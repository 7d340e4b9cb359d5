// Shared helpers of the Eye tests: a RunConfig for a synthetic scene, and truth geometry.
#pragma once
#include <opencv2/imgcodecs.hpp>

#include <cmath>
#include <vector>

#include "eye_config.hpp"
#include "eye_render.hpp"
#include "eye_synth.hpp"

namespace eye_test {

inline eye::RunConfig config_for(const eye::SynthScene &s, const eye::CameraPose &pose) {
  eye::RunConfig c;
  c.in = s.in;
  c.pose = pose;
  c.locate = s.car;
  c.vehicles = {{"NIGEL1", 1, 0.0}, {"NIGEL2", 2, 0.0}};
  c.tracking.roi = false;  // golden frames are unrelated: scan every frame whole
  return c;
}

// Truth pixel corners of a car's roof tag (libapriltag order).
inline std::array<cv::Point2d, 4> truth_corners(const eye::SynthScene &s,
                                                const eye::SynthCar &car) {
  const double c = std::cos(car.yaw_rad), sn = std::sin(car.yaw_rad);
  const double tx = car.x_m + c * s.car.tag_offset_m[0], ty = car.y_m + sn * s.car.tag_offset_m[0];
  const double z = s.car.base_link_height_m + s.car.tag_offset_m[2];
  const auto tf = eye::tag_corners_tagframe(s.car.tag_size_m);
  std::array<cv::Point2d, 4> out;
  for (size_t i = 0; i < 4; ++i)
    out[i] = eye::camera_project(
        s.in, s.pose, {tx + c * tf[i][0] - sn * tf[i][1], ty + sn * tf[i][0] + c * tf[i][1], z});
  return out;
}

// A decompression bomb: a tiny real JPEG whose SOF header is patched to claim w x h px.
inline std::vector<uchar> jpeg_claiming(int w, int h) {
  std::vector<uchar> jpg;
  cv::imencode(".jpg", cv::Mat(8, 8, CV_8UC1, cv::Scalar(128)), jpg);
  for (size_t i = 0; i + 8 < jpg.size(); ++i)
    if (jpg[i] == 0xFF && (jpg[i + 1] == 0xC0 || jpg[i + 1] == 0xC2)) {
      jpg[i + 5] = static_cast<uchar>(h >> 8);
      jpg[i + 6] = static_cast<uchar>(h & 0xFF);
      jpg[i + 7] = static_cast<uchar>(w >> 8);
      jpg[i + 8] = static_cast<uchar>(w & 0xFF);
      break;
    }
  return jpg;
}

inline double angle_diff_rad(double a, double b) {
  return std::remainder(a - b, 2 * M_PI);
}

}  // namespace eye_test
