// One frame in, the poses of the configured cars out: detect, keep the tags we know, locate.
// A car whose tag is not in this frame gets no pose (no stale poses).
// Whole-field detection (config `whole_field`): a full scan runs the detector at its coarse
// decimation over the frame and at finer decimation where the calibration says tags look small
// (eye_scanplan.hpp); tracking windows use the decimation their tag's size allows.
// Region-of-interest tracking (config `tracking`): a car seen in the previous frame is looked
// for only in a window around where its tag should be now (last corners moved by the last
// pixel velocity); a car missing there is looked for in a window three times as large, then
// in the whole frame at once, so windows save time but never lose a detection. New cars: the
// whole frame is scanned whenever no car is tracked; otherwise the periodic scan is staggered,
// one of full_every horizontal bands per frame (the cost spread evenly, no slow frames), so a
// new car is found within full_every frames, or at once when another camera hints where it is
// (multi-camera handover). With detector.threads 2 the band (or half of a whole-frame scan)
// runs on a second thread with its own detector while the windows run on the caller's.
#pragma once
#include <opencv2/core.hpp>

#include <map>
#include <memory>
#include <vector>

#include "eye_config.hpp"
#include "eye_detect.hpp"
#include "eye_locate.hpp"
#include "eye_scanplan.hpp"

namespace eye {

class DetectWorker;

class Tracker {
 public:
  explicit Tracker(const RunConfig &c);
  ~Tracker();
  Tracker(const Tracker &) = delete;
  Tracker &operator=(const Tracker &) = delete;
  // gray: CV_8UC1 of the calibrated size; throws eye::Error on another size or type.
  std::vector<CarPose> process(const cv::Mat &gray);
  // Another camera sees tag_id where this camera would see these corners [px]: look there in
  // the next frame (a hint that is not found does not force a full scan).
  void hint(int tag_id, const std::array<cv::Point2d, 4> &corners_px);
  // The frame with the tags, ids, vehicle names and poses drawn in (BGR).
  cv::Mat annotate(const cv::Mat &gray, const std::vector<CarPose> &poses) const;
  const RunConfig &config() const { return cfg_; }
  // Whether the last process() scanned the whole frame at once.
  bool last_was_full_scan() const { return last_full_; }
  // Every tag the last process() detected (known cars, reference tags, others), merged.
  const std::vector<Detection> &last_detections() const { return last_dets_; }
  // The regions of a full scan (whole frame at the coarse decimation, finer where tags are small).
  const ScanPlan &scan_plan() const { return plan_; }
  // The image noise [grey levels] last estimated, and the contrast the detector needs from it.
  double noise_sigma() const { return noise_sigma_; }
  int min_contrast() const { return det_.min_contrast(); }

 private:
  struct Track {
    std::array<cv::Point2d, 4> corners;  // last frame [px]
    cv::Point2d velocity_px{0, 0};       // centre motion over the last frame [px]
  };
  std::vector<Detection> scan_regions(Detector &det, const cv::Mat &gray,
                                      const std::vector<ScanRegion> &rs);
  // The whole-frame scan, in two halves on two threads when there is a second detector.
  std::vector<Detection> full_scan(const cv::Mat &gray);
  std::vector<Detection> scan_window(const cv::Mat &gray, int id,
                                     const std::array<cv::Point2d, 4> &corners, double margin);
  RunConfig cfg_;
  Detector det_;
  std::unique_ptr<Detector> det2_;      // the second thread's (detector.threads 2)
  std::unique_ptr<DetectWorker> work_;  // runs det2_ beside the caller's thread
  ScanPlan plan_;
  std::map<int, VehicleTag> by_tag_;
  std::map<int, Track> tracks_;                      // tag id -> last frame
  std::map<int, std::array<cv::Point2d, 4>> hints_;  // tag id -> corners, next frame
  std::vector<Detection> last_dets_;
  double noise_sigma_ = 0;
  long frame_ = 0;
  bool last_full_ = true;
};

// Same id found twice within one tag size (overlapping regions): one detection, the one with
// the larger decision margin. Copies farther apart stay (a tag seen twice gives no pose).
std::vector<Detection> merge_detections(const std::vector<Detection> &dets);

}  // namespace eye
