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
// (multi-camera handover). With detector.threads 2 a second thread decodes a JPEG frame while
// the caller's searches the windows as their rows come in, and a whole-frame scan is split
// between the two threads, each with its own detector.
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
class RowDecoder;

// A frame for Tracker::track: decoded, or a JPEG that track() decodes (with detector.threads 2
// and cars tracked, row by row on the second thread while the windows are searched).
struct TrackInput {
  cv::Mat gray;                      // CV_8UC1, or empty
  std::shared_ptr<RowDecoder> jpeg;  // when gray is empty
};

class Tracker {
 public:
  explicit Tracker(const RunConfig &c);
  ~Tracker();
  Tracker(const Tracker &) = delete;
  Tracker &operator=(const Tracker &) = delete;
  // gray: CV_8UC1 of the calibrated size; throws eye::Error on another size or type.
  // track() then finish(): every car's pose of this frame.
  std::vector<CarPose> process(const cv::Mat &gray);
  // A frame in two parts, so that the tracked cars' poses can be published before the staggered
  // band is done (the band only looks for cars not tracked yet, ~half a frame's CPU at 720p).
  // track(): the tracked cars' windows and the hints (or the whole-frame scan when a track is
  // lost or none exists); returns those cars' poses. The frame is kept (shared, not copied)
  // until finish().
  std::vector<CarPose> track(const cv::Mat &gray) { return track(TrackInput{gray, nullptr}); }
  // The same for a frame that may still be a JPEG; throws eye::Error naming it if it does not
  // decode (the tracks stay as they were).
  std::vector<CarPose> track(const TrackInput &in);
  // The band of the frame track() took: the poses of cars it found that track() did not
  // return. A tag the band also finds elsewhere (a copy) ends
  // its track. No-op without a track() before it; track() calls it for a frame left unfinished.
  std::vector<CarPose> finish();
  // Another camera sees tag_id where this camera would see these corners [px]: look there in
  // the next frame (a hint that is not found does not force a full scan).
  void hint(int tag_id, const std::array<cv::Point2d, 4> &corners_px);
  // The frame with the tags, ids, vehicle names and poses drawn in (BGR).
  cv::Mat annotate(const cv::Mat &gray, const std::vector<CarPose> &poses) const;
  const RunConfig &config() const { return cfg_; }
  // The last frame track() took (decoded by finish()).
  const cv::Mat &last_frame() const { return last_gray_; }
  // Whether the last process() scanned the whole frame at once.
  bool last_was_full_scan() const { return last_full_; }
  // Every tag the last process() (or finish()) detected (known cars, reference tags, others).
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
  // The window [px] around a tag's corners, grown by margin tag sizes.
  static cv::Rect window_rect(const std::array<cv::Point2d, 4> &corners, double margin);
  // Detections of tag `id` in its window by `det`; rows: the decoder to wait on for the
  // window's rows (nullptr: gray is whole there). Throws eye::Error if the decode failed.
  static std::vector<Detection> scan_window(Detector &det, const cv::Mat &gray,
                                            const RowDecoder *rows, int id,
                                            const std::array<cv::Point2d, 4> &corners,
                                            double margin);
  // The detector's contrast threshold from the noise of this frame.
  void update_contrast(const cv::Mat &gray);
  // Between track() and finish().
  struct Pending {
    bool active = false;
    cv::Mat gray;                         // the frame (shared with the caller)
    std::vector<ScanRegion> band;         // the staggered band still to scan (empty: none)
    std::vector<Detection> found;         // the band's detections
    std::vector<Detection> tracked;       // track()'s detections (windows, hints or whole frame)
    std::shared_ptr<RowDecoder> decoder;  // the frame's JPEG, decoding on the second thread
  };
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
  Pending pending_;  // read by the worker's job: the destructor settles it first
  cv::Mat last_gray_;
};

// Same id found twice within one tag size (overlapping regions): one detection, the one with
// the larger decision margin. Copies farther apart stay (a tag seen twice gives no pose).
std::vector<Detection> merge_detections(const std::vector<Detection> &dets);

}  // namespace eye
