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
  c.intrinsics_path = resolve(path, n.get<std::string>("intrinsics"));
  c.map_path = resolve(path, n.get<std::string>("map"));
  n.read("lcm_url", c.lcm_url);
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
    d.reject_unknown();
  }
  if (n.has("tracking")) {
    const auto t = n.child("tracking");
    c.tracking.roi = t.in_range("roi", 0, 1, int{c.tracking.roi}) != 0;
    t.read_in_range("full_every", c.tracking.full_every, 1, 10000);
    c.tracking.margin = t.positive_up_to("margin", 20.0, c.tracking.margin);
    t.reject_unknown();
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
  c.in = intrinsics_load(c.intrinsics_path);
  const MapCalib m = mapcal_load(c.map_path);
  if (m.width_px != c.in.width_px || m.height_px != c.in.height_px)
    throw Error(c.map_path + ": image size " + std::to_string(m.width_px) + "x" +
                std::to_string(m.height_px) + " differs from the intrinsics in " +
                c.intrinsics_path);
  c.pose = m.pose;
  return c;
}

}  // namespace eye
