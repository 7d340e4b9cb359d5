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
  // libapriltag thresholds only where the local grey range (max - min over ~12x12 px) reaches
  // min_contrast (its qtp.min_white_black_diff); elsewhere it sees no edges. Image noise of
  // sigma s spans ~5-7 s over such a patch: below that every pixel of a flat region becomes an
  // edge and the quad search drowns in noise clusters (measured: sigma 6, decimate 1, 720p:
  // 187 ms per frame at 5 grey levels, 17 ms at 45, the same 400 of 400 tags found, still all at
  // 70). The tracker sets it to max(min_contrast, noise_k * the frame's estimated noise sigma):
  // 8 sigma sat on the cliff (sigma 5.2 estimated: 42; 35 still drowned), 10 is past it.
  int min_contrast = 5;   // [grey levels]
  double noise_k = 10.0;  // 0: min_contrast alone
  // Detector threads of a Tracker (each runs libapriltag on one thread). 2: the staggered band
  // (or half of a whole-frame scan) runs on a second thread beside the tracking windows, which
  // shortens a frame's latency on a machine with a core to spare; 1: everything on the caller's
  // thread (the benchmark's one-thread figures).
  int threads = 1;
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
  // The contrast libapriltag needs to see an edge [grey levels], from now on.
  void set_min_contrast(int grey);
  int min_contrast() const;

 private:
  DetectorParams params_;
  void *td_ = nullptr;   // apriltag_detector_t*
  void *fam_ = nullptr;  // apriltag_family_t*
};

// The standard deviation of the image noise [grey levels], robust to edges and texture: the
// median absolute response of the Laplacian-difference kernel [1 -2 1; -2 4 -2; 1 -2 1]
// (Immerkaer's noise operator, which cancels any locally linear shading; pure noise of sigma s
// gives N(0, 36 s^2)), over every row_step-th row, divided by 6 * 0.6745.
double estimate_noise_sigma(const cv::Mat &gray, int row_step = 4);

}  // namespace eye
