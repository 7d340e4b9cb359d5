#include "eye_camera.hpp"

#include <opencv2/calib3d.hpp>

#include <cmath>
#include <fstream>

#include "eye_error.hpp"

namespace eye {

cv::Vec3d CameraPose::centre_map() const {
  return -(r_cam_map.t() * t_cam_map);
}

Intrinsics intrinsics_load(const std::string &path) {
  const autodrive::yaml::Section n(autodrive::yaml::load_file(path), "", path);
  Intrinsics in;
  in.width_px = n.in_range("width_px", 16, 16384);
  in.height_px = n.in_range("height_px", 16, 16384);
  std::vector<double> k = n.numbers("k", 9);
  for (int i = 0; i < 9; ++i) in.k(i / 3, i % 3) = k[static_cast<size_t>(i)];
  if (!(in.k(0, 0) > 0 && in.k(1, 1) > 0) || in.k(2, 2) != 1.0 || in.k(1, 0) != 0 ||
      in.k(2, 0) != 0 || in.k(2, 1) != 0)
    n.fail_key("k", "is not a camera matrix [fx 0 cx; 0 fy cy; 0 0 1] with fx, fy > 0");
  in.dist = n.numbers("dist", 0);
  if (in.dist.size() != 4 && in.dist.size() != 5 && in.dist.size() != 8)
    n.fail_key("dist", "must have 4, 5 or 8 coefficients (plumb_bob k1 k2 p1 p2 [k3])");
  in.rms_px = n.number("rms_px", 0.0);
  in.views = n.get<int>("views", 0);
  n.allow({"pixel_convention"});  // a note for people, written by intrinsics_save
  n.reject_unknown();
  return in;
}

void intrinsics_save(const std::string &path, const Intrinsics &in) {
  YAML::Emitter e;
  e.SetDoublePrecision(12);
  e << YAML::BeginMap;
  e << YAML::Key << "width_px" << YAML::Value << in.width_px;
  e << YAML::Key << "height_px" << YAML::Value << in.height_px;
  e << YAML::Key << "k" << YAML::Value << YAML::Flow << YAML::BeginSeq;
  for (int i = 0; i < 9; ++i) e << in.k(i / 3, i % 3);
  e << YAML::EndSeq;
  e << YAML::Key << "dist" << YAML::Value << YAML::Flow << in.dist;
  e << YAML::Key << "rms_px" << YAML::Value << in.rms_px;
  e << YAML::Key << "views" << YAML::Value << in.views;
  e << YAML::Key << "pixel_convention" << YAML::Value
    << "opencv: centre of pixel (col,row) at (x,y)=(col,row)";
  e << YAML::EndMap;
  std::ofstream f(path);
  if (!f) throw Error(path + ": cannot write file");
  f << "# autodrive-eye camera intrinsics (calibrate-intrinsics)\n" << e.c_str() << "\n";
}

std::vector<cv::Point2d> intrinsics_normalise(const Intrinsics &in,
                                              const std::vector<cv::Point2d> &px) {
  std::vector<cv::Point2d> out;
  if (px.empty()) return out;
  // More iterations than the default 5: the Eye wants sub-millimetre agreement at the borders.
  cv::undistortPoints(px, out, cv::Mat(in.k), in.dist, cv::noArray(), cv::noArray(),
                      cv::TermCriteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 30, 1e-12));
  return out;
}

cv::Point2d camera_project(const Intrinsics &in, const CameraPose &pose, const cv::Vec3d &p_map) {
  std::vector<cv::Point3d> obj{cv::Point3d(p_map[0], p_map[1], p_map[2])};
  std::vector<cv::Point2d> img;
  cv::Mat r(pose.r_cam_map), rvec;
  cv::Rodrigues(r, rvec);
  cv::projectPoints(obj, rvec, cv::Mat(pose.t_cam_map), cv::Mat(in.k), in.dist, img);
  return img[0];
}

bool camera_ray_to_plane(const CameraPose &pose, const cv::Point2d &norm, double z_m,
                         cv::Vec2d *xy_m) {
  const cv::Vec3d d = pose.r_cam_map.t() * cv::Vec3d(norm.x, norm.y, 1.0);
  const cv::Vec3d c = pose.centre_map();
  if (std::abs(d[2]) < 1e-12) return false;
  const double s = (z_m - c[2]) / d[2];
  if (s <= 0) return false;
  *xy_m = cv::Vec2d(c[0] + s * d[0], c[1] + s * d[1]);
  return true;
}

}  // namespace eye
