// tag36h11 detection with libapriltag, corners returned in the Eye's (OpenCV) pixel convention.
#pragma once
#include <opencv2/core.hpp>

#include <array>
#include <vector>

namespace eye {

// libapriltag puts the centre of pixel (col,row) at (col+0.5, row+0.5); the Eye (OpenCV, our
// renderer, calibrateCamera) puts it at (col,row). Corners are shifted by this much [px]
// (measured and asserted by tests/eye: eye.convention.*).
constexpr double kApriltagToOpencvPx = -0.5;

struct DetectorParams {
  float decimate = 2.0f;     // quad_decimate: detect quads at 1/decimate resolution
  float sigma_px = 0.0f;     // quad_sigma: Gaussian blur before quad detection [px]
  bool refine_edges = true;  // refit edges at full resolution (keeps sub-pixel corners)
  double sharpening = 0.25;  // decode_sharpening
  int max_hamming = 1;       // reject detections with more corrected bits than this
  float min_margin = 20.0f;  // reject detections with a lower decision margin
};

struct Detection {
  int id = -1;
  int hamming = 0;
  float margin = 0;
  // Corners of the black border [px, OpenCV convention], libapriltag order: bottom-left,
  // bottom-right, top-right, top-left of the printed tag.
  std::array<cv::Point2d, 4> corners_px;
  cv::Point2d centre_px;
};

// Owns a libapriltag detector for tag36h11, one thread. Not copyable.
class Detector {
 public:
  explicit Detector(const DetectorParams &p = DetectorParams());
  ~Detector();
  Detector(const Detector &) = delete;
  Detector &operator=(const Detector &) = delete;
  // gray: CV_8UC1 image. Throws eye::Error on another type.
  std::vector<Detection> detect(const cv::Mat &gray);
  // Detects in a region of the frame (corners in frame pixels) at its own decimation.
  std::vector<Detection> detect(const cv::Mat &gray, const cv::Rect &roi, float decimate);
  const DetectorParams &params() const { return params_; }

 private:
  DetectorParams params_;
  void *td_ = nullptr;   // apriltag_detector_t*
  void *fam_ = nullptr;  // apriltag_family_t*
};

}  // namespace eye
