// One frame in, the poses of the configured cars out: detect, keep the tags we know, locate.
// A car whose tag is not in this frame gets no pose (no stale poses).
// Region-of-interest tracking (config `tracking`): a car seen in the previous frame is looked
// for only in a window around its last tag; the whole frame is scanned every full_every-th
// frame, whenever no car is being tracked, and at once when a tracked car is missing from its
// window, so windows save time but never lose a detection; new cars are found within
// full_every frames.
#pragma once
#include <opencv2/core.hpp>

#include <map>
#include <vector>

#include "eye_config.hpp"
#include "eye_detect.hpp"
#include "eye_locate.hpp"

namespace eye {

class Tracker {
 public:
  explicit Tracker(const RunConfig &c);
  // gray: CV_8UC1 of the calibrated size; throws eye::Error on another size or type.
  std::vector<CarPose> process(const cv::Mat &gray);
  // The frame with the tags, ids, vehicle names and poses drawn in (BGR).
  cv::Mat annotate(const cv::Mat &gray, const std::vector<CarPose> &poses) const;
  const RunConfig &config() const { return cfg_; }
  // Whether the last process() scanned the whole frame.
  bool last_was_full_scan() const { return last_full_; }

 private:
  std::vector<Detection> detect_windows(const cv::Mat &gray);
  RunConfig cfg_;
  Detector det_;
  Detector roi_det_;  // decimate 1: windows are small
  std::map<int, VehicleTag> by_tag_;
  std::map<int, std::array<cv::Point2d, 4>> last_corners_;  // tag id -> corners last frame
  long frame_ = 0;
  bool last_full_ = true;
};

}  // namespace eye
