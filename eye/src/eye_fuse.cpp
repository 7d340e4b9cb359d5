#include "eye_fuse.hpp"

#include <autodrive/angles.hpp>

#include <algorithm>
#include <cmath>
#include <map>

#include "eye_error.hpp"
#include "eye_source.hpp"

namespace eye {

std::vector<CarPose> fuse_poses(const std::vector<std::vector<CarPose>> &per_camera) {
  std::map<std::string, std::vector<const CarPose *>> by_car;
  std::vector<std::string> order;
  for (const auto &cam : per_camera)
    for (const auto &p : cam) {
      if (!by_car.count(p.vehicle)) order.push_back(p.vehicle);
      by_car[p.vehicle].push_back(&p);
    }
  std::vector<CarPose> out;
  for (const auto &name : order) {
    const auto &ps = by_car[name];
    if (ps.size() == 1) {
      out.push_back(*ps[0]);
      continue;
    }
    cv::Matx33d info = cv::Matx33d::zeros();
    cv::Vec3d acc(0, 0, 0);
    const double yaw0 = ps[0]->yaw_rad;
    for (const CarPose *p : ps) {
      const cv::Matx33d c(p->cov.data());
      const cv::Matx33d ci = c.inv(cv::DECOMP_SVD);
      const cv::Vec3d x(p->x_m, p->y_m, yaw0 + autodrive::angle_wrap_rad(p->yaw_rad - yaw0));
      info += ci;
      acc += ci * x;
    }
    const cv::Matx33d cov = info.inv(cv::DECOMP_SVD);
    const cv::Vec3d x = cov * acc;
    CarPose f = *ps[0];
    f.x_m = x[0];
    f.y_m = x[1];
    f.yaw_rad = autodrive::angle_wrap_rad(x[2]);
    for (int i = 0; i < 9; ++i)
      f.cov[static_cast<size_t>(i)] = 0.5 * (cov(i / 3, i % 3) + cov(i % 3, i / 3));
    f.cameras = static_cast<int>(ps.size());
    out.push_back(f);
  }
  return out;
}

bool project_car_tag(const Intrinsics &in, const CameraPose &pose, const LocateParams &p,
                     const VehicleTag &v, const CarPose &car, double margin_px,
                     std::array<cv::Point2d, 4> *corners_px) {
  const double c = std::cos(car.yaw_rad), s = std::sin(car.yaw_rad);
  const double ox = p.tag_offset_m[0], oy = p.tag_offset_m[1];
  const double tx = car.x_m + c * ox - s * oy, ty = car.y_m + s * ox + c * oy;
  const double z = p.base_link_height_m + p.tag_offset_m[2];
  const double ty_rad = car.yaw_rad + v.tag_yaw_rad;
  const double ct = std::cos(ty_rad), st = std::sin(ty_rad);
  const auto tf = tag_corners_tagframe(p.tag_size_m);
  for (size_t i = 0; i < 4; ++i) {
    const cv::Vec3d m(tx + ct * tf[i][0] - st * tf[i][1], ty + st * tf[i][0] + ct * tf[i][1], z);
    if ((pose.r_cam_map * m + pose.t_cam_map)[2] <= 0) return false;
    const cv::Point2d q = camera_project(in, pose, m);
    if (!(q.x >= margin_px && q.y >= margin_px && q.x <= in.width_px - 1 - margin_px &&
          q.y <= in.height_px - 1 - margin_px))
      return false;
    (*corners_px)[i] = q;
  }
  return true;
}

MultiEye::MultiEye(const std::vector<RunConfig> &cameras,
                   const std::vector<std::vector<RefTag>> &refs, const HealthParams &hp)
    : cfg_(cameras), last_(cameras.size()) {
  for (size_t i = 0; i < cameras.size(); ++i) {
    trackers_.push_back(std::make_unique<Tracker>(cameras[i]));
    health_.emplace_back(cameras[i].camera_name, cameras[i].in, cameras[i].pose,
                         i < refs.size() ? refs[i] : std::vector<RefTag>{}, hp);
  }
}

std::vector<CarPose> MultiEye::process(const std::vector<cv::Mat> &frames, int64_t utime) {
  auto out = track(frames, utime);
  const auto late = finish();
  out.insert(out.end(), late.begin(), late.end());
  return out;
}

std::vector<CarPose> MultiEye::track(const std::vector<cv::Mat> &frames, int64_t utime) {
  std::vector<TrackInput> in;
  for (const auto &f : frames) in.push_back({f, nullptr});
  return track(in, utime);
}

std::vector<CarPose> MultiEye::track(const std::vector<TrackInput> &frames, int64_t utime) {
  utime_ = utime;
  for (size_t i = 0; i < trackers_.size(); ++i) {
    last_[i].clear();
    if (i >= frames.size() || (frames[i].gray.empty() && !frames[i].jpeg)) continue;
    try {
      last_[i] = trackers_[i]->track(frames[i]);
    } catch (const Error &e) {
      if (!frames[i].jpeg) throw;  // a decoded frame of the wrong size: the caller's error
      skipped_frames_log().event(cfg_[i].camera_name, std::string(e.what()) + " (frame skipped)");
      continue;
    }
    health_[i].inflate(&last_[i]);
  }
  std::vector<CarPose> fused = fuse_poses(last_);
  posed_.clear();
  for (const auto &car : fused) posed_.push_back(car.vehicle);
  hand_over(fused, last_);
  return fused;
}

std::vector<CarPose> MultiEye::finish() {
  moved_now_.clear();
  std::vector<std::vector<CarPose>> found(trackers_.size());
  for (size_t i = 0; i < trackers_.size(); ++i) {
    found[i] = trackers_[i]->finish();
    health_[i].inflate(&found[i]);
    last_[i].insert(last_[i].end(), found[i].begin(), found[i].end());
    if (health_[i].observe(utime_, trackers_[i]->last_detections(),
                           static_cast<int>(last_[i].size())))
      moved_now_.push_back(i);
  }
  std::vector<CarPose> fused;
  for (auto &car : fuse_poses(found))
    if (std::find(posed_.begin(), posed_.end(), car.vehicle) == posed_.end())
      fused.push_back(std::move(car));
  hand_over(fused, last_);
  return fused;
}

// Handover: a car one camera sees is looked for at once by every other camera whose image it is
// in, instead of waiting for that camera's next staggered band.
void MultiEye::hand_over(const std::vector<CarPose> &cars,
                         const std::vector<std::vector<CarPose>> &seen) {
  for (const auto &car : cars)
    for (size_t j = 0; j < trackers_.size(); ++j) {
      bool in_view = false;
      for (const auto &p : seen[j]) in_view = in_view || p.vehicle == car.vehicle;
      if (in_view) continue;
      for (const auto &v : cfg_[j].vehicles) {
        std::array<cv::Point2d, 4> c;
        if (v.name == car.vehicle &&
            project_car_tag(cfg_[j].in, cfg_[j].pose, cfg_[j].locate, v, car, 2.0, &c))
          trackers_[j]->hint(v.tag_id, c);
      }
    }
}

}  // namespace eye
