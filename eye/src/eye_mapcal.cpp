#include "eye_mapcal.hpp"

#include <opencv2/calib3d.hpp>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <set>

#include "eye_error.hpp"
#include "eye_locate.hpp"

namespace eye {

std::vector<RefTag> reftags_load(const std::string &path) {
  const autodrive::yaml::Section n(autodrive::yaml::load_file(path), "", path);
  const YAML::Node tags = n.list("tags", "must be a non-empty list");
  if (tags.size() == 0) n.fail_key("tags", "must be a non-empty list");
  n.reject_unknown();
  std::vector<RefTag> out;
  std::set<int> ids;
  for (size_t i = 0; i < tags.size(); ++i) {
    const autodrive::yaml::Section t(tags[i], "tags[" + std::to_string(i) + "]", path);
    RefTag r;
    r.id = t.get<int>("id");
    r.x_m = t.number("x_m");
    r.y_m = t.number("y_m");
    r.z_m = t.number("z_m", 0.0);
    r.yaw_rad = t.number("yaw_rad", 0.0);
    r.size_m = t.positive_up_to("size_m", 2.0, 0, true);
    t.reject_unknown();
    if (r.id < 0 || r.id > 586) t.fail_key("id", "must be a tag36h11 id 0..586");
    if (!ids.insert(r.id).second) t.fail_key("id", std::to_string(r.id) + " is listed twice");
    out.push_back(r);
  }
  return out;
}

std::array<cv::Point3d, 4> reftag_corners_map(const RefTag &r) {
  const auto tf = tag_corners_tagframe(r.size_m);
  const double c = std::cos(r.yaw_rad), s = std::sin(r.yaw_rad);
  std::array<cv::Point3d, 4> out;
  for (size_t i = 0; i < 4; ++i)
    out[i] = cv::Point3d(r.x_m + c * tf[i][0] - s * tf[i][1], r.y_m + s * tf[i][0] + c * tf[i][1],
                         r.z_m);
  return out;
}

MapCalib map_calibrate(const Intrinsics &in, const std::vector<RefTag> &refs,
                       const std::vector<std::vector<Detection>> &frames, int min_tags) {
  std::map<int, const RefTag *> by_id;
  for (const auto &r : refs) by_id[r.id] = &r;
  std::vector<cv::Point3d> obj;
  std::vector<cv::Point2d> img;
  std::vector<int> obj_id;
  std::set<int> seen;
  for (const auto &f : frames)
    for (const auto &d : f) {
      auto it = by_id.find(d.id);
      if (it == by_id.end()) continue;
      const auto c3 = reftag_corners_map(*it->second);
      for (size_t i = 0; i < 4; ++i) {
        obj.push_back(c3[i]);
        img.push_back(d.corners_px[i]);
        obj_id.push_back(d.id);
      }
      seen.insert(d.id);
    }
  MapCalib m;
  m.width_px = in.width_px;
  m.height_px = in.height_px;
  for (const auto &r : refs)
    if (!seen.count(r.id)) m.missing_ids.push_back(r.id);
  if (static_cast<int>(seen.size()) < min_tags)
    throw Error("calibrate-map: saw " + std::to_string(seen.size()) + " of " +
                std::to_string(refs.size()) + " reference tags, need at least " +
                std::to_string(min_tags));

  cv::Mat rvec, tvec;
  if (!cv::solvePnP(obj, img, cv::Mat(in.k), in.dist, rvec, tvec, false, cv::SOLVEPNP_SQPNP))
    throw Error("calibrate-map: solvePnP found no camera pose for the reference tags");
  cv::solvePnPRefineLM(obj, img, cv::Mat(in.k), in.dist, rvec, tvec);
  cv::Mat r;
  cv::Rodrigues(rvec, r);
  m.pose.r_cam_map = cv::Matx33d(r);
  m.pose.t_cam_map = cv::Vec3d(tvec);

  // Residuals: each observed corner's ray on its own tag's plane vs the known corner [mm].
  const auto norm = intrinsics_normalise(in, img);
  std::map<int, std::pair<double, int>> acc;
  double ss = 0;
  for (size_t i = 0; i < obj.size(); ++i) {
    cv::Vec2d xy;
    double e_mm = 1e9;
    if (camera_ray_to_plane(m.pose, norm[i], obj[i].z, &xy))
      e_mm = 1000.0 * std::hypot(xy[0] - obj[i].x, xy[1] - obj[i].y);
    ss += e_mm * e_mm;
    m.max_mm = std::max(m.max_mm, e_mm);
    acc[obj_id[i]].first += e_mm * e_mm;
    acc[obj_id[i]].second += 1;
  }
  m.rms_mm = std::sqrt(ss / static_cast<double>(obj.size()));
  for (const auto &[id, a] : acc) m.tags.push_back({id, std::sqrt(a.first / a.second)});
  return m;
}

// Each reference tag's corners on its own plane as one camera sees them (first detection).
static std::map<int, std::array<cv::Vec2d, 4>> corners_on_planes(
    const std::map<int, const RefTag *> &by_id, const Intrinsics &in, const CameraPose &pose,
    const std::vector<std::vector<Detection>> &frames) {
  std::map<int, std::array<cv::Vec2d, 4>> out;
  for (const auto &f : frames)
    for (const auto &d : f) {
      auto it = by_id.find(d.id);
      if (it == by_id.end() || out.count(d.id)) continue;
      const auto norm = intrinsics_normalise(
          in, std::vector<cv::Point2d>(d.corners_px.begin(), d.corners_px.end()));
      std::array<cv::Vec2d, 4> c;
      bool ok = true;
      for (size_t i = 0; i < 4; ++i)
        ok = ok && camera_ray_to_plane(pose, norm[i], it->second->z_m, &c[i]);
      if (ok) out[d.id] = c;
    }
  return out;
}

OverlapAgreement map_overlap_agreement(const std::vector<RefTag> &refs, const Intrinsics &in_a,
                                       const CameraPose &pose_a,
                                       const std::vector<std::vector<Detection>> &frames_a,
                                       const Intrinsics &in_b, const CameraPose &pose_b,
                                       const std::vector<std::vector<Detection>> &frames_b) {
  std::map<int, const RefTag *> by_id;
  for (const auto &r : refs) by_id[r.id] = &r;
  const auto a = corners_on_planes(by_id, in_a, pose_a, frames_a);
  const auto b = corners_on_planes(by_id, in_b, pose_b, frames_b);
  OverlapAgreement o;
  double ss = 0;
  int n = 0;
  for (const auto &[id, ca] : a) {
    auto it = b.find(id);
    if (it == b.end()) continue;
    double ss_tag = 0;
    for (size_t i = 0; i < 4; ++i) {
      const double e_mm = 1000.0 * cv::norm(ca[i] - it->second[i]);
      ss_tag += e_mm * e_mm;
      o.max_mm = std::max(o.max_mm, e_mm);
    }
    o.tags.push_back({id, std::sqrt(ss_tag / 4)});
    ss += ss_tag;
    n += 4;
  }
  if (n > 0) o.rms_mm = std::sqrt(ss / n);
  return o;
}

void mapcal_save(const std::string &path, const MapCalib &m) {
  YAML::Emitter e;
  e.SetDoublePrecision(12);
  e << YAML::BeginMap;
  e << YAML::Key << "width_px" << YAML::Value << m.width_px;
  e << YAML::Key << "height_px" << YAML::Value << m.height_px;
  e << YAML::Key << "r_cam_map" << YAML::Value << YAML::Flow << YAML::BeginSeq;
  for (int i = 0; i < 9; ++i) e << m.pose.r_cam_map(i / 3, i % 3);
  e << YAML::EndSeq;
  e << YAML::Key << "t_cam_map_m" << YAML::Value << YAML::Flow << YAML::BeginSeq
    << m.pose.t_cam_map[0] << m.pose.t_cam_map[1] << m.pose.t_cam_map[2] << YAML::EndSeq;
  const cv::Vec3d c = m.pose.centre_map();
  e << YAML::Key << "camera_centre_map_m" << YAML::Value << YAML::Flow << YAML::BeginSeq << c[0]
    << c[1] << c[2] << YAML::EndSeq;
  e << YAML::Key << "residual_rms_mm" << YAML::Value << m.rms_mm;
  e << YAML::Key << "residual_max_mm" << YAML::Value << m.max_mm;
  e << YAML::Key << "tags" << YAML::Value << YAML::BeginSeq;
  for (const auto &t : m.tags)
    e << YAML::Flow << YAML::BeginMap << YAML::Key << "id" << YAML::Value << t.id << YAML::Key
      << "rms_mm" << YAML::Value << t.rms_mm << YAML::EndMap;
  e << YAML::EndSeq;
  e << YAML::Key << "missing_ids" << YAML::Value << YAML::Flow << m.missing_ids;
  e << YAML::EndMap;
  std::ofstream f(path);
  if (!f) throw Error(path + ": cannot write file");
  f << "# autodrive-eye map calibration (calibrate-map): X_cam = r_cam_map * X_map + t_cam_map\n"
    << e.c_str() << "\n";
}

MapCalib mapcal_load(const std::string &path) {
  const autodrive::yaml::Section n(autodrive::yaml::load_file(path), "", path);
  MapCalib m;
  m.width_px = n.in_range("width_px", 16, 16384);
  m.height_px = n.in_range("height_px", 16, 16384);
  const auto r = n.numbers("r_cam_map", 9);
  const auto t = n.numbers("t_cam_map_m", 3);
  for (int i = 0; i < 9; ++i) m.pose.r_cam_map(i / 3, i % 3) = r[static_cast<size_t>(i)];
  m.pose.t_cam_map = cv::Vec3d(t[0], t[1], t[2]);
  const cv::Matx33d should_be_i = m.pose.r_cam_map * m.pose.r_cam_map.t();
  if (cv::norm(should_be_i - cv::Matx33d::eye()) > 1e-6 || cv::determinant(m.pose.r_cam_map) < 0)
    n.fail_key("r_cam_map", "is not a rotation matrix");
  m.rms_mm = n.number("residual_rms_mm", 0.0);
  m.max_mm = n.number("residual_max_mm", 0.0);
  // What map_calibrate found, kept in the file for people: not needed to run.
  n.allow({"camera_centre_map_m", "tags", "missing_ids"});
  n.reject_unknown();
  return m;
}

}  // namespace eye
