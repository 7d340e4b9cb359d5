#include "eye_config.hpp"

#include <filesystem>
#include <set>

#include "eye_error.hpp"
#include "eye_mapcal.hpp"

namespace eye {

static std::string resolve(const std::string &base_file, const std::string &p) {
  const std::filesystem::path q(p);
  if (q.is_absolute()) return p;
  return (std::filesystem::path(base_file).parent_path() / q).string();
}

RunConfig runconfig_load(const std::string &path) {
  const autodrive::yaml::Section n(autodrive::yaml::load_file(path), "", path);
  RunConfig c;
  c.path = path;
  // One camera (intrinsics, map) or several (cameras: [{name, intrinsics, map, source}]).
  if (n.has("cameras")) {
    const YAML::Node cs = n.list("cameras", "must be a non-empty list");
    if (cs.size() == 0) n.fail_key("cameras", "must be a non-empty list");
    std::set<std::string> cam_names;
    for (size_t i = 0; i < cs.size(); ++i) {
      const autodrive::yaml::Section cn(cs[i], "cameras[" + std::to_string(i) + "]", path);
      CameraConfig cc;
      cc.name = cn.get<std::string>("name");
      cc.intrinsics_path = resolve(path, cn.get<std::string>("intrinsics"));
      cc.map_path = resolve(path, cn.get<std::string>("map"));
      cc.source = cn.get<std::string>("source", "");
      cn.reject_unknown();
      if (cc.name.empty() || !cam_names.insert(cc.name).second)
        cn.fail_key("name", "is empty or used twice");
      c.cameras.push_back(cc);
    }
  } else {
    CameraConfig cc;
    cc.name = n.get<std::string>("camera_name", cc.name);
    cc.intrinsics_path = resolve(path, n.get<std::string>("intrinsics"));
    cc.map_path = resolve(path, n.get<std::string>("map"));
    c.cameras.push_back(cc);
  }
  c.intrinsics_path = c.cameras[0].intrinsics_path;
  c.map_path = c.cameras[0].map_path;
  c.camera_name = c.cameras[0].name;
  n.read("lcm_url", c.lcm_url);
  n.read_in_range("realtime_priority", c.realtime_priority, 0, 98);
  if (n.has("sim_latency_ms")) n.read_in_range("sim_latency_ms", c.sim_latency_ms, 0.0, 10000.0);
  // Default: the simulated Nigel's tag (vehicle/nigel.params); a lab gives its printed size.
  c.locate.tag_size_m = n.positive_up_to("tag_size_m", 2.0, AUTODRIVE_VEHICLE_TAG_SIZE_M);
  // Nigel's roof tag offset comes from vehicle/nigel.params (tag_pos_m); a config gives it only
  // for a car of another kind.
  if (n.has("tag_offset_m")) {
    const auto off = n.numbers("tag_offset_m", 3);
    c.locate.tag_offset_m = cv::Vec3d(off[0], off[1], off[2]);
  }
  n.read_in_range("base_link_height_m", c.locate.base_link_height_m, 0.0, 2.0);
  c.locate.corner_sigma_px = n.positive_up_to("corner_sigma_px", 20.0, c.locate.corner_sigma_px);
  c.locate.max_fit_rms_m = n.positive_up_to("max_fit_rms_m", 1.0, c.locate.max_fit_rms_m);
  if (n.has("detector")) {
    const auto d = n.child("detector");
    c.detector.decimate =
        static_cast<float>(d.in_range("decimate", 1.0, 8.0, double{c.detector.decimate}));
    c.detector.sigma_px =
        static_cast<float>(d.in_range("sigma_px", 0.0, 10.0, double{c.detector.sigma_px}));
    c.detector.refine_edges = d.in_range("refine_edges", 0, 1, int{c.detector.refine_edges}) != 0;
    d.read_in_range("sharpening", c.detector.sharpening, 0.0, 1.0);
    d.read_in_range("max_hamming", c.detector.max_hamming, 0, 3);
    c.detector.min_margin =
        static_cast<float>(d.in_range("min_margin", 0.0, 1000.0, double{c.detector.min_margin}));
    d.read_in_range("min_contrast", c.detector.min_contrast, 0, 255);
    d.read_in_range("noise_k", c.detector.noise_k, 0.0, 50.0);
    d.read_in_range("threads", c.detector.threads, 1, 2);
    d.reject_unknown();
  }
  if (n.has("tracking")) {
    const auto t = n.child("tracking");
    c.tracking.roi = t.in_range("roi", 0, 1, int{c.tracking.roi}) != 0;
    t.read_in_range("full_every", c.tracking.full_every, 1, 10000);
    c.tracking.margin = t.positive_up_to("margin", 20.0, c.tracking.margin);
    t.reject_unknown();
  }
  if (n.has("whole_field")) {
    const auto w = n.child("whole_field");
    c.whole_field.enabled = w.get<int>("enabled", c.whole_field.enabled) != 0;
    c.whole_field.plan.min_tag_px_decimated =
        w.positive("min_tag_px_decimated", c.whole_field.plan.min_tag_px_decimated);
    c.whole_field.plan.cell_px = w.positive_int("cell_px", c.whole_field.plan.cell_px);
    w.reject_unknown();
  }
  if (n.has("reference_tags"))
    c.reference_tags = reftags_load(resolve(path, n.get<std::string>("reference_tags")));
  if (n.has("health")) {
    const auto h = n.child("health");
    c.health.bump_threshold_mm = h.positive("bump_threshold_mm", c.health.bump_threshold_mm);
    c.health.bump_confirm = h.positive_int("bump_confirm", c.health.bump_confirm);
    c.health.bump_cov_scale = h.positive("bump_cov_scale", c.health.bump_cov_scale);
    c.health.status_period_s = h.positive("status_period_s", c.health.status_period_s);
    h.reject_unknown();
  }
  const YAML::Node vs = n.list("vehicles", "must be a non-empty list");
  if (vs.size() == 0) n.fail_key("vehicles", "must be a non-empty list");
  n.reject_unknown();
  std::set<int> ids;
  std::set<std::string> names;
  for (size_t i = 0; i < vs.size(); ++i) {
    const autodrive::yaml::Section v(vs[i], "vehicles[" + std::to_string(i) + "]", path);
    VehicleTag tag;
    tag.name = v.get<std::string>("name");
    tag.tag_id = v.get<int>("tag_id");
    tag.tag_yaw_rad = v.number("tag_yaw_rad", tag.tag_yaw_rad);
    v.reject_unknown();
    if (tag.name.empty()) v.fail_key("name", "is empty");
    if (tag.tag_id < 0 || tag.tag_id > 586) v.fail_key("tag_id", "must be 0..586");
    if (!ids.insert(tag.tag_id).second) v.fail_key("tag_id", "is used twice");
    if (!names.insert(tag.name).second) v.fail_key("name", "is used twice");
    c.vehicles.push_back(tag);
  }
  for (auto &cc : c.cameras) {
    cc.in = intrinsics_load(cc.intrinsics_path);
    const MapCalib m = mapcal_load(cc.map_path);
    if (m.width_px != cc.in.width_px || m.height_px != cc.in.height_px)
      throw Error(cc.map_path + ": image size " + std::to_string(m.width_px) + "x" +
                  std::to_string(m.height_px) + " differs from the intrinsics in " +
                  cc.intrinsics_path);
    cc.pose = m.pose;
  }
  c.in = c.cameras[0].in;
  c.pose = c.cameras[0].pose;
  return c;
}

RunConfig runconfig_camera(const RunConfig &c, size_t i) {
  RunConfig o = c;
  if (i < c.cameras.size()) {
    const CameraConfig &cc = c.cameras[i];
    o.in = cc.in;
    o.pose = cc.pose;
    o.camera_name = cc.name;
    o.intrinsics_path = cc.intrinsics_path;
    o.map_path = cc.map_path;
  }
  return o;
}

}  // namespace eye
