#include "eye_locate.hpp"

#include <autodrive/angles.hpp>
#include <cmath>

namespace eye {

std::array<cv::Vec2d, 4> tag_corners_tagframe(double size_m) {
  const double h = size_m / 2;
  return {cv::Vec2d(-h, h), cv::Vec2d(-h, -h), cv::Vec2d(h, -h), cv::Vec2d(h, h)};
}

double fit_rigid2d(const std::vector<cv::Vec2d> &src, const std::vector<cv::Vec2d> &dst,
                   cv::Vec2d *t_m, double *yaw_rad) {
  const size_t n = src.size();
  cv::Vec2d cs(0, 0), cd(0, 0);
  for (size_t i = 0; i < n; ++i) {
    cs += src[i];
    cd += dst[i];
  }
  cs *= 1.0 / static_cast<double>(n);
  cd *= 1.0 / static_cast<double>(n);
  double sdot = 0, scross = 0;
  for (size_t i = 0; i < n; ++i) {
    const cv::Vec2d a = src[i] - cs, b = dst[i] - cd;
    sdot += a[0] * b[0] + a[1] * b[1];
    scross += a[0] * b[1] - a[1] * b[0];
  }
  const double yaw = std::atan2(scross, sdot);
  const double c = std::cos(yaw), s = std::sin(yaw);
  const cv::Vec2d t = cd - cv::Vec2d(c * cs[0] - s * cs[1], s * cs[0] + c * cs[1]);
  double ss = 0;
  for (size_t i = 0; i < n; ++i) {
    const cv::Vec2d r =
        cv::Vec2d(c * src[i][0] - s * src[i][1], s * src[i][0] + c * src[i][1]) + t - dst[i];
    ss += r.dot(r);
  }
  *t_m = t;
  *yaw_rad = yaw;
  return std::sqrt(ss / static_cast<double>(n));
}

std::optional<CarPose> locate_car(const Intrinsics &in, const CameraPose &pose,
                                  const LocateParams &p, const VehicleTag &v, const Detection &d) {
  const double z_tag_m = p.base_link_height_m + p.tag_offset_m[2];
  const std::vector<cv::Point2d> px(d.corners_px.begin(), d.corners_px.end());
  const std::vector<cv::Point2d> norm = intrinsics_normalise(in, px);
  const auto tagf = tag_corners_tagframe(p.tag_size_m);
  std::vector<cv::Vec2d> src(tagf.begin(), tagf.end()), dst(4);
  for (size_t i = 0; i < 4; ++i)
    if (!camera_ray_to_plane(pose, norm[i], z_tag_m, &dst[i])) return std::nullopt;
  cv::Vec2d t;
  double tag_yaw;
  const double rms = fit_rigid2d(src, dst, &t, &tag_yaw);
  if (!(rms <= p.max_fit_rms_m)) return std::nullopt;

  CarPose out;
  out.vehicle = v.name;
  out.tag_id = d.id;
  out.corners_px = d.corners_px;
  out.fit_rms_m = rms;
  const double yaw = autodrive::angle_wrap_rad(tag_yaw - v.tag_yaw_rad);
  // The tag sits at tag_offset in base_link: base = tag - R(yaw) offset.
  const double c = std::cos(yaw), s = std::sin(yaw);
  const double ox = p.tag_offset_m[0], oy = p.tag_offset_m[1];
  out.x_m = t[0] - (c * ox - s * oy);
  out.y_m = t[1] - (s * ox + c * oy);
  out.yaw_rad = yaw;

  // Covariance: a corner's noise on the roof plane is corner_sigma_px times the local scale
  // (depth / focal length), or what the fit residual shows if that is worse. Four corners:
  // the centre averages them; yaw is set by their spread (sum |src|^2 = 2 size^2).
  const cv::Vec3d tag_cam = pose.r_cam_map * cv::Vec3d(t[0], t[1], z_tag_m) + pose.t_cam_map;
  const double m_per_px = tag_cam[2] / std::sqrt(in.k(0, 0) * in.k(1, 1));
  const double sc_m = std::max(p.corner_sigma_px * m_per_px, rms);
  const double var_t = sc_m * sc_m / 4.0;
  const double var_yaw = sc_m * sc_m / (2.0 * p.tag_size_m * p.tag_size_m);
  // d(base)/d(yaw) = -R'(yaw) offset
  const double jx = s * ox + c * oy, jy = -(c * ox - s * oy);
  out.cov = {var_t + jx * jx * var_yaw,
             jx * jy * var_yaw,
             jx * var_yaw,
             jx * jy * var_yaw,
             var_t + jy * jy * var_yaw,
             jy * var_yaw,
             jx * var_yaw,
             jy * var_yaw,
             var_yaw};
  return out;
}

}  // namespace eye
