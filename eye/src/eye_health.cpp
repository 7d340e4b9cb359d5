#include "eye_health.hpp"

#include <cmath>
#include <map>

namespace eye {

CameraHealth::CameraHealth(std::string camera, const Intrinsics &in, const CameraPose &pose,
                           std::vector<RefTag> refs, HealthParams p)
    : camera_(std::move(camera)), in_(in), pose_(pose), refs_(std::move(refs)), p_(p) {
  st_.camera = camera_;
  if (!refs_.empty()) st_.ref_tags_seen = 0;
}

bool CameraHealth::observe(int64_t utime, const std::vector<Detection> &dets,
                           std::vector<CarPose> *poses) {
  const bool newly_moved = observe(utime, dets, poses ? static_cast<int>(poses->size()) : 0);
  if (poses) inflate(poses);
  return newly_moved;
}

void CameraHealth::inflate(std::vector<CarPose> *poses) const {
  if (st_.moved)
    for (auto &c : *poses)
      for (auto &v : c.cov) v *= st_.cov_scale;
}

bool CameraHealth::observe(int64_t utime, const std::vector<Detection> &dets, int cars_seen) {
  st_.utime = utime;
  ++st_.frames;
  st_.tags_seen = static_cast<int>(dets.size());
  st_.cars_seen = cars_seen;
  times_.push_back(utime);
  while (times_.size() > 31) times_.pop_front();
  if (times_.size() >= 2 && times_.back() > times_.front())
    st_.fps_hz = 1e6 * static_cast<double>(times_.size() - 1) /
                 static_cast<double>(times_.back() - times_.front());
  bool newly_moved = false;
  if (!refs_.empty()) {
    std::map<int, const RefTag *> by_id;
    for (const auto &r : refs_) by_id[r.id] = &r;
    double ss_mm = 0, ss_px = 0;
    int n = 0, tags = 0;
    for (const auto &d : dets) {
      auto it = by_id.find(d.id);
      if (it == by_id.end()) continue;
      ++tags;
      const auto c3 = reftag_corners_map(*it->second);
      const std::vector<cv::Point2d> px(d.corners_px.begin(), d.corners_px.end());
      const auto norm = intrinsics_normalise(in_, px);
      for (size_t i = 0; i < 4; ++i) {
        cv::Vec2d xy;
        const double e_mm = camera_ray_to_plane(pose_, norm[i], c3[i].z, &xy)
                                ? 1000.0 * std::hypot(xy[0] - c3[i].x, xy[1] - c3[i].y)
                                : 1e6;
        const cv::Point2d e_px = camera_project(in_, pose_, {c3[i].x, c3[i].y, c3[i].z}) - px[i];
        ss_mm += e_mm * e_mm;
        ss_px += e_px.dot(e_px);
        ++n;
      }
    }
    if (n > 0) {
      st_.ref_tags_seen = tags;
      st_.ref_rms_mm = std::sqrt(ss_mm / n);
      st_.ref_rms_px = std::sqrt(ss_px / n);
      over_ = st_.ref_rms_mm > p_.bump_threshold_mm ? over_ + 1 : 0;
      if (!st_.moved && over_ >= p_.bump_confirm) {
        st_.moved = true;
        st_.cov_scale = p_.bump_cov_scale;
        newly_moved = true;
      }
    }
  }
  return newly_moved;
}

bool CameraHealth::status_due(int64_t utime) {
  if (last_status_utime_ != 0 && utime - last_status_utime_ < p_.status_period_s * 1e6 &&
      utime >= last_status_utime_)
    return false;
  last_status_utime_ = utime;
  return true;
}

}  // namespace eye
