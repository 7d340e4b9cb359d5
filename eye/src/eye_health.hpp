// Health of one camera: frame rate, tags seen, and the residual of the reference tags that stay
// in view against the calibration. A camera that was bumped moves every reference tag off its
// calibrated place; when their residual stays above a threshold the camera is marked moved,
// warned about once, and its car poses carry an inflated covariance until it is recalibrated
// (the mark holds until the program restarts with a new map calibration).
#pragma once
#include <cstdint>
#include <deque>
#include <string>
#include <vector>

#include "eye_camera.hpp"
#include "eye_detect.hpp"
#include "eye_locate.hpp"
#include "eye_mapcal.hpp"

namespace eye {

struct HealthParams {
  double bump_threshold_mm = 3.0;  // reference-tag residual RMS that means "the camera moved" [mm]
  int bump_confirm = 3;  // over the threshold in this many frames with reference tags in a row
  double bump_cov_scale = 100.0;  // covariance factor of poses from a moved camera (10x sigma)
  double status_period_s = 1.0;   // EYE_CAMERA_STATUS period [s]
};

struct CameraStatus {
  std::string camera;
  int64_t utime = 0;       // capture time of the last frame [us]
  double fps_hz = 0;       // frame rate over the last frames (capture times) [Hz]
  long frames = 0;         // frames processed
  int tags_seen = 0;       // tags detected in the last frame
  int cars_seen = 0;       // cars posed in the last frame
  int ref_tags_seen = -1;  // reference tags in the last frame that had any (-1: none configured)
  double ref_rms_mm = -1;  // their corner residual on their planes [mm] (-1: not measured)
  double ref_rms_px = -1;  // their reprojection residual [px]
  bool moved = false;      // the reference tags drifted: recalibrate
  double cov_scale = 1.0;  // factor applied to this camera's pose covariances
};

class CameraHealth {
 public:
  CameraHealth(std::string camera, const Intrinsics &in, const CameraPose &pose,
               std::vector<RefTag> refs, HealthParams p = HealthParams());
  // One processed frame: its capture time, every tag detected (the reference tags among them
  // are measured: the tracker's staggered scan sees each within full_every frames), and the
  // car poses, inflated here if moved. Returns true once, at the frame the camera is found moved.
  bool observe(int64_t utime, const std::vector<Detection> &dets, std::vector<CarPose> *poses);
  // The same without poses to inflate: cars_seen is how many the frame posed.
  bool observe(int64_t utime, const std::vector<Detection> &dets, int cars_seen);
  // This camera's poses with the covariance its state calls for (inflated once moved).
  void inflate(std::vector<CarPose> *poses) const;
  const CameraStatus &status() const { return st_; }
  // Whether a status message is due at this capture time (then marks it sent).
  bool status_due(int64_t utime);

 private:
  std::string camera_;
  Intrinsics in_;
  CameraPose pose_;
  std::vector<RefTag> refs_;
  HealthParams p_;
  CameraStatus st_;
  std::deque<int64_t> times_;
  int over_ = 0;
  int64_t last_status_utime_ = 0;
};

}  // namespace eye
