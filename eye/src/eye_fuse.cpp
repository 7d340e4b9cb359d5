#include "eye_fuse.hpp"

#include <autodrive/angles.hpp>

#include <cmath>
#include <map>

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
  moved_now_.clear();
  for (size_t i = 0; i < trackers_.size(); ++i) {
    last_[i].clear();
    if (i >= frames.size() || frames[i].empty()) continue;
    last_[i] = trackers_[i]->process(frames[i]);
    if (health_[i].observe(utime, trackers_[i]->last_detections(), &last_[i]))
      moved_now_.push_back(i);
  }
  std::vector<CarPose> fused = fuse_poses(last_);
  // Handover: a car one camera sees is looked for at once by every other camera whose image
  // it is in, instead of waiting for that camera's next full scan.
  for (const auto &car : fused)
    for (size_t j = 0; j < trackers_.size(); ++j) {
      bool seen = false;
      for (const auto &p : last_[j]) seen = seen || p.vehicle == car.vehicle;
      if (seen) continue;
      for (const auto &v : cfg_[j].vehicles) {
        std::array<cv::Point2d, 4> c;
        if (v.name == car.vehicle &&
            project_car_tag(cfg_[j].in, cfg_[j].pose, cfg_[j].locate, v, car, 2.0, &c))
          trackers_[j]->hint(v.tag_id, c);
      }
    }
  return fused;
}

}  // namespace eye
