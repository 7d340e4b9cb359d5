#include "eye_tracker.hpp"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "eye_error.hpp"

namespace eye {

static DetectorParams roi_params(DetectorParams p) {
  p.decimate = 1.0f;
  return p;
}

Tracker::Tracker(const RunConfig &c) : cfg_(c), det_(c.detector), roi_det_(roi_params(c.detector)) {
  for (const auto &v : c.vehicles) by_tag_[v.tag_id] = v;
}

std::vector<Detection> Tracker::detect_windows(const cv::Mat &gray) {
  std::vector<Detection> out;
  const cv::Rect frame(0, 0, gray.cols, gray.rows);
  for (const auto &[id, c] : last_corners_) {
    double x0 = c[0].x, x1 = c[0].x, y0 = c[0].y, y1 = c[0].y;
    for (const auto &p : c) {
      x0 = std::min(x0, p.x);
      x1 = std::max(x1, p.x);
      y0 = std::min(y0, p.y);
      y1 = std::max(y1, p.y);
    }
    const double grow = cfg_.tracking.margin * std::max(x1 - x0, y1 - y0);
    const cv::Rect win = cv::Rect(cv::Point(static_cast<int>(std::floor(x0 - grow)),
                                            static_cast<int>(std::floor(y0 - grow))),
                                  cv::Point(static_cast<int>(std::ceil(x1 + grow)) + 1,
                                            static_cast<int>(std::ceil(y1 + grow)) + 1)) &
                         frame;
    if (win.area() == 0) continue;
    // Window pixel (c, r) is frame pixel (c + x, r + y): shifting corners is exact.
    for (auto d : roi_det_.detect(gray(win))) {
      if (d.id != id) continue;
      for (auto &p : d.corners_px) p += cv::Point2d(win.x, win.y);
      d.centre_px += cv::Point2d(win.x, win.y);
      out.push_back(d);
    }
  }
  return out;
}

std::vector<CarPose> Tracker::process(const cv::Mat &gray) {
  if (gray.cols != cfg_.in.width_px || gray.rows != cfg_.in.height_px)
    throw Error("frame: size " + std::to_string(gray.cols) + "x" + std::to_string(gray.rows) +
                " differs from the calibrated " + std::to_string(cfg_.in.width_px) + "x" +
                std::to_string(cfg_.in.height_px) + " of " + cfg_.intrinsics_path);
  std::vector<CarPose> out;
  std::map<int, int> count;
  last_full_ = !cfg_.tracking.roi || last_corners_.empty() ||
               frame_ % std::max(1, cfg_.tracking.full_every) == 0;
  ++frame_;
  std::vector<Detection> dets;
  if (!last_full_) {
    dets = detect_windows(gray);
    // A tracked car missing from its window (fast motion, occlusion): scan the whole frame
    // now rather than lose the frame; windows only ever save time, never detections.
    for (const auto &kv : last_corners_) {
      const int id = kv.first;
      if (std::none_of(dets.begin(), dets.end(), [id](const Detection &d) { return d.id == id; })) {
        last_full_ = true;
        break;
      }
    }
  }
  if (last_full_) dets = det_.detect(gray);
  last_corners_.clear();
  for (const auto &d : dets) count[d.id]++;
  for (const auto &d : dets) {
    auto it = by_tag_.find(d.id);
    // A tag seen twice in one frame is ambiguous (a copy, a reflection): publish neither.
    if (it == by_tag_.end() || count[d.id] > 1) continue;
    if (auto p = locate_car(cfg_.in, cfg_.pose, cfg_.locate, it->second, d)) {
      out.push_back(*p);
      last_corners_[d.id] = d.corners_px;
    }
  }
  return out;
}

cv::Mat Tracker::annotate(const cv::Mat &gray, const std::vector<CarPose> &poses) const {
  cv::Mat bgr;
  cv::cvtColor(gray, bgr, cv::COLOR_GRAY2BGR);
  for (const auto &p : poses) {
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
