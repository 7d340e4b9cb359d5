// Several cameras, one Eye: each car gets one pose per frame time. A car seen by several
// cameras gets their covariance-weighted (information) fusion; one seen by one camera keeps its
// pose. Cars another camera sees are hinted to the cameras that should see them too, so a car
// driving from one view into the next is handed over without a gap.
#pragma once
#include <opencv2/core.hpp>

#include <memory>
#include <string>
#include <vector>

#include "eye_config.hpp"
#include "eye_health.hpp"
#include "eye_tracker.hpp"

namespace eye {

// Information-weighted fusion per vehicle: P = (sum P_i^-1)^-1, x = P sum P_i^-1 x_i (yaw
// unwrapped around the first camera's); `cameras` counts the poses fused.
std::vector<CarPose> fuse_poses(const std::vector<std::vector<CarPose>> &per_camera);

// Pixel corners of a car's roof tag at this pose in a camera, libapriltag order; false if a
// corner is behind the camera or outside the image (by margin_px).
bool project_car_tag(const Intrinsics &in, const CameraPose &pose, const LocateParams &p,
                     const VehicleTag &v, const CarPose &car, double margin_px,
                     std::array<cv::Point2d, 4> *corners_px);

class MultiEye {
 public:
  // One run config per camera (same vehicles and tag geometry), each with its reference tags
  // for health (may be empty).
  MultiEye(const std::vector<RunConfig> &cameras, const std::vector<std::vector<RefTag>> &refs,
           const HealthParams &hp = HealthParams());
  // frames[i]: camera i's frame of this frame time (an empty Mat: none). Fused poses:
  // track() then finish().
  std::vector<CarPose> process(const std::vector<cv::Mat> &frames, int64_t utime);
  // The tracked cars' fused poses (Tracker::track of each camera), to publish at once; health
  // inflation as of the frames before.
  std::vector<CarPose> track(const std::vector<cv::Mat> &frames, int64_t utime);
  // The same for frames that may still be JPEGs (Tracker::track); a frame that does not decode
  // is logged (skipped_frames_log) and its camera has no frame this time.
  std::vector<CarPose> track(const std::vector<TrackInput> &frames, int64_t utime);
  // The rest of the frame time: each camera's staggered band and health. Fused poses of the
  // cars no camera tracked (a car track() returned is not returned again: one pose per frame
  // time; another camera's sighting of it joins its fusion from the next frame on).
  std::vector<CarPose> finish();
  size_t size() const { return trackers_.size(); }
  Tracker &tracker(size_t i) { return *trackers_[i]; }
  CameraHealth &health(size_t i) { return health_[i]; }
  // Per camera, the poses of the last frame time (after health inflation, before fusion).
  const std::vector<std::vector<CarPose>> &last_per_camera() const { return last_; }
  // Cameras found moved at the last frame time (warn once).
  const std::vector<size_t> &newly_moved() const { return moved_now_; }

 private:
  std::vector<RunConfig> cfg_;
  std::vector<std::unique_ptr<Tracker>> trackers_;
  std::vector<CameraHealth> health_;
  std::vector<std::vector<CarPose>> last_;
  std::vector<size_t> moved_now_;
  int64_t utime_ = 0;               // the frame time between track() and finish()
  std::vector<std::string> posed_;  // vehicles track() returned
  // Hints every other camera to look where it should see each of these cars.
  void hand_over(const std::vector<CarPose> &cars, const std::vector<std::vector<CarPose>> &seen);
};

}  // namespace eye
