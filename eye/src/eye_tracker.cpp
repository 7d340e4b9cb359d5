#include "eye_tracker.hpp"

#include <opencv2/imgproc.hpp>

#include <cstdio>

#include "eye_error.hpp"

namespace eye {

Tracker::Tracker(const RunConfig& c) : cfg_(c), det_(c.detector) {
  for (const auto& v : c.vehicles) by_tag_[v.tag_id] = v;
}

std::vector<CarPose> Tracker::process(const cv::Mat& gray) {
  if (gray.cols != cfg_.in.width_px || gray.rows != cfg_.in.height_px)
    throw Error("frame: size " + std::to_string(gray.cols) + "x" + std::to_string(gray.rows) +
                " differs from the calibrated " + std::to_string(cfg_.in.width_px) + "x" +
                std::to_string(cfg_.in.height_px) + " of " + cfg_.intrinsics_path);
  std::vector<CarPose> out;
  std::map<int, int> count;
  const auto dets = det_.detect(gray);
  for (const auto& d : dets) count[d.id]++;
  for (const auto& d : dets) {
    auto it = by_tag_.find(d.id);
    // A tag seen twice in one frame is ambiguous (a copy, a reflection): publish neither.
    if (it == by_tag_.end() || count[d.id] > 1) continue;
    if (auto p = locate_car(cfg_.in, cfg_.pose, cfg_.locate, it->second, d)) out.push_back(*p);
  }
  return out;
}

cv::Mat Tracker::annotate(const cv::Mat& gray, const std::vector<CarPose>& poses) const {
  cv::Mat bgr;
  cv::cvtColor(gray, bgr, cv::COLOR_GRAY2BGR);
  for (const auto& p : poses) {
    for (size_t i = 0; i < 4; ++i)
      cv::line(bgr, p.corners_px[i], p.corners_px[(i + 1) % 4], cv::Scalar(0, 255, 0), 2,
               cv::LINE_AA);
    // top edge of the print (tag x axis) in red
    cv::line(bgr, p.corners_px[2], p.corners_px[3], cv::Scalar(0, 0, 255), 2, cv::LINE_AA);
    char b[128];
    std::snprintf(b, sizeof b, "%s x=%.3f y=%.3f yaw=%.1fdeg", p.vehicle.c_str(), p.x_m, p.y_m,
                  p.yaw_rad * 180.0 / M_PI);
    cv::putText(bgr, b, p.corners_px[3] + cv::Point2d(0, -8), cv::FONT_HERSHEY_SIMPLEX, 0.5,
                cv::Scalar(0, 255, 255), 1, cv::LINE_AA);
  }
  return bgr;
}

}  // namespace eye
