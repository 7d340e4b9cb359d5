// One frame in, the poses of the configured cars out: detect, keep the tags we know, locate.
// A car whose tag is not in this frame gets no pose (no stale poses).
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
  explicit Tracker(const RunConfig& c);
  // gray: CV_8UC1 of the calibrated size; throws eye::Error on another size or type.
  std::vector<CarPose> process(const cv::Mat& gray);
  // The frame with the tags, ids, vehicle names and poses drawn in (BGR).
  cv::Mat annotate(const cv::Mat& gray, const std::vector<CarPose>& poses) const;
  const RunConfig& config() const { return cfg_; }

 private:
  RunConfig cfg_;
  Detector det_;
  std::map<int, VehicleTag> by_tag_;
};

}  // namespace eye
