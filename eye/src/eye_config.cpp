#include "eye_config.hpp"

#include <filesystem>
#include <set>

#include "eye_error.hpp"
#include "eye_mapcal.hpp"
#include "eye_yaml.hpp"

namespace eye {

static std::string resolve(const std::string &base_file, const std::string &p) {
  const std::filesystem::path q(p);
  if (q.is_absolute()) return p;
  return (std::filesystem::path(base_file).parent_path() / q).string();
}

RunConfig runconfig_load(const std::string &path) {
  YAML::Node n = yaml_load_file(path);
  RunConfig c;
  c.path = path;
  c.intrinsics_path = resolve(path, yaml_string(n, "intrinsics", path));
  c.map_path = resolve(path, yaml_string(n, "map", path));
  if (n["lcm_url"]) c.lcm_url = yaml_string(n, "lcm_url", path);
  // Default: the simulated Nigel's tag (vehicle/nigel.params); a lab gives its printed size.
  c.locate.tag_size_m = AUTODRIVE_VEHICLE_TAG_SIZE_M;
  if (n["tag_size_m"]) c.locate.tag_size_m = yaml_double(n, "tag_size_m", path);
  if (!(c.locate.tag_size_m > 0)) throw Error(path + ": field 'tag_size_m' must be positive");
  // Nigel's roof tag offset comes from vehicle/nigel.params (tag_pos_m); a config gives it only
  // for a car of another kind.
  if (n["tag_offset_m"]) {
    const auto off = yaml_doubles(n, "tag_offset_m", path, 3);
    c.locate.tag_offset_m = cv::Vec3d(off[0], off[1], off[2]);
  }
  if (n["base_link_height_m"])
    c.locate.base_link_height_m = yaml_double(n, "base_link_height_m", path);
  if (n["corner_sigma_px"]) c.locate.corner_sigma_px = yaml_double(n, "corner_sigma_px", path);
  if (n["max_fit_rms_m"]) c.locate.max_fit_rms_m = yaml_double(n, "max_fit_rms_m", path);
  if (YAML::Node d = n["detector"]) {
    const std::string w = path + " (detector)";
    if (!d.IsMap()) throw Error(w + ": must be a mapping");
    if (d["decimate"]) c.detector.decimate = static_cast<float>(yaml_double(d, "decimate", w));
    if (d["sigma_px"]) c.detector.sigma_px = static_cast<float>(yaml_double(d, "sigma_px", w));
    if (d["refine_edges"]) c.detector.refine_edges = yaml_int(d, "refine_edges", w) != 0;
    if (d["sharpening"]) c.detector.sharpening = yaml_double(d, "sharpening", w);
    if (d["max_hamming"]) c.detector.max_hamming = yaml_int(d, "max_hamming", w);
    if (d["min_margin"])
      c.detector.min_margin = static_cast<float>(yaml_double(d, "min_margin", w));
    if (!(c.detector.decimate >= 1)) throw Error(w + ": field 'decimate' must be >= 1");
  }
  if (YAML::Node t = n["tracking"]) {
    const std::string w = path + " (tracking)";
    if (!t.IsMap()) throw Error(w + ": must be a mapping");
    if (t["roi"]) c.tracking.roi = yaml_int(t, "roi", w) != 0;
    if (t["full_every"]) c.tracking.full_every = yaml_int(t, "full_every", w);
    if (t["margin"]) c.tracking.margin = yaml_double(t, "margin", w);
    if (c.tracking.full_every < 1) throw Error(w + ": field 'full_every' must be >= 1");
    if (!(c.tracking.margin > 0)) throw Error(w + ": field 'margin' must be positive");
  }
  YAML::Node vs = yaml_need(n, "vehicles", path);
  if (!vs.IsSequence() || vs.size() == 0)
    throw Error(path + ": field 'vehicles' must be a non-empty list");
  std::set<int> ids;
  std::set<std::string> names;
  for (size_t i = 0; i < vs.size(); ++i) {
    const std::string w = path + " (vehicles[" + std::to_string(i) + "])";
    if (!vs[i].IsMap()) throw Error(w + ": each vehicle must be a mapping");
    VehicleTag v;
    v.name = yaml_string(vs[i], "name", w);
    v.tag_id = yaml_int(vs[i], "tag_id", w);
    if (vs[i]["tag_yaw_rad"]) v.tag_yaw_rad = yaml_double(vs[i], "tag_yaw_rad", w);
    if (v.name.empty()) throw Error(w + ": field 'name' is empty");
    if (v.tag_id < 0 || v.tag_id > 586) throw Error(w + ": field 'tag_id' must be 0..586");
    if (!ids.insert(v.tag_id).second) throw Error(w + ": field 'tag_id' is used twice");
    if (!names.insert(v.name).second) throw Error(w + ": field 'name' is used twice");
    c.vehicles.push_back(v);
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
