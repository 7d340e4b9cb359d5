#include "common/config.hpp"

#include <cmath>
#include <fstream>
#include <set>
#include <sstream>

namespace cfg {
namespace {

// Reads section keys with the dotted path kept for error messages.
class Section {
 public:
  Section(const YAML::Node &node, std::string path, const std::string &file)
      : node_(node), path_(std::move(path)), file_(file) {
    if (node_ && !node_.IsMap()) fail(path_, "expected a mapping");
  }

  [[noreturn]] void fail(const std::string &key, const std::string &what) const {
    throw Error(file_ + ": " + key + ": " + what);
  }

  std::string key(const std::string &k) const { return path_.empty() ? k : path_ + "." + k; }
  bool has(const std::string &k) const { return node_ && node_[k]; }

  template <typename T>
  T get(const std::string &k) const {
    used_.insert(k);
    if (!has(k)) fail(key(k), "missing key");
    return convert<T>(k);
  }
  template <typename T>
  T get(const std::string &k, T fallback) const {
    used_.insert(k);
    return has(k) ? convert<T>(k) : fallback;
  }
  double positive(const std::string &k, double fallback, bool required = false) const {
    double v = required ? get<double>(k) : get<double>(k, fallback);
    if (!(v > 0.0) || !std::isfinite(v)) fail(key(k), "must be a finite number > 0");
    return v;
  }
  int positive_int(const std::string &k, int fallback, bool required = false) const {
    int v = required ? get<int>(k) : get<int>(k, fallback);
    if (v <= 0) fail(key(k), "must be an integer > 0");
    return v;
  }
  Section child(const std::string &k) const {
    used_.insert(k);
    return Section(node_[k], key(k), file_);
  }
  // Any key not read is a typo or an unsupported option: refuse it rather than ignore it.
  void reject_unknown() const {
    if (!node_) return;
    for (const auto &kv : node_) {
      const std::string k = kv.first.as<std::string>();
      if (!used_.count(k)) fail(key(k), "unknown key");
    }
  }
  const YAML::Node &node() const { return node_; }

 private:
  template <typename T>
  T convert(const std::string &k) const {
    try {
      return node_[k].template as<T>();
    } catch (const YAML::Exception &) {
      std::ostringstream s;
      s << "bad value";
      if (node_[k].IsScalar()) s << " '" << node_[k].Scalar() << "'";
      fail(key(k), s.str());
    }
  }
  YAML::Node node_;
  std::string path_;
  const std::string &file_;
  mutable std::set<std::string> used_;
};

Vehicle parse_vehicle(const Section &s) {
  Vehicle v;
  v.name = s.get<std::string>("name");
  if (v.name.empty()) s.fail(s.key("name"), "must not be empty");
  v.wheelbase_m = s.positive("wheelbase_m", 0, true);
  v.track_m = s.positive("track_m", 0, true);
  v.wheel_radius_m = s.positive("wheel_radius_m", 0, true);
  v.steering_limit_rad = s.positive("steering_limit_rad", 0, true);
  v.encoder_counts_per_rev = s.positive_int("encoder_counts_per_rev", 0, true);
  s.reject_unknown();
  return v;
}

Bridge parse_bridge(const Section &s) {
  Bridge b;
  b.device = s.get<std::string>("device");
  b.baud = s.positive_int("baud", 0, true);
  b.heartbeat_hz = s.positive("heartbeat_hz", 0, true);
  b.command_timeout_ms = s.positive_int("command_timeout_ms", 0, true);
  b.hello_retry_ms = s.positive_int("hello_retry_ms", b.hello_retry_ms);
  b.refused_retry_ms = s.positive_int("refused_retry_ms", b.refused_retry_ms);
  b.reconnect_ms = s.positive_int("reconnect_ms", b.reconnect_ms);
  b.link_timeout_ms = s.positive_int("link_timeout_ms", b.link_timeout_ms);
  b.telemetry_period_ms = s.get<int>("telemetry_period_ms", b.telemetry_period_ms);
  if (b.telemetry_period_ms != 0 && (b.telemetry_period_ms < 5 || b.telemetry_period_ms > 1000))
    s.fail(s.key("telemetry_period_ms"), "must be 0 (do not configure) or 5..1000");
  b.failsafe_timeout_ms = s.get<int>("failsafe_timeout_ms", b.failsafe_timeout_ms);
  if (b.failsafe_timeout_ms < 20 || b.failsafe_timeout_ms > 150)
    s.fail(s.key("failsafe_timeout_ms"), "must be 20..150 (firmware range)");
  b.servo_trim_us = s.get<int>("servo_trim_us", b.servo_trim_us);
  if (b.servo_trim_us < -200 || b.servo_trim_us > 200)
    s.fail(s.key("servo_trim_us"), "must be -200..200");
  if (s.has("imu")) {
    Section imu = s.child("imu");
    b.imu_frame_id = imu.get<std::string>("frame_id", b.imu_frame_id);
    b.imu_orientation_var_rad2 = imu.get<double>("orientation_var_rad2", 0.0);
    b.imu_gyro_var_rad2_s2 = imu.get<double>("gyro_var_rad2_s2", 0.0);
    b.imu_accel_var_m2_s4 = imu.get<double>("accel_var_m2_s4", 0.0);
    for (double v : {b.imu_orientation_var_rad2, b.imu_gyro_var_rad2_s2, b.imu_accel_var_m2_s4})
      if (!(v >= 0.0) || !std::isfinite(v)) imu.fail(s.key("imu"), "variances must be >= 0");
    imu.reject_unknown();
  }
  s.reject_unknown();
  return b;
}

Lidar parse_lidar(const Section &s) {
  Lidar l;
  l.device = s.get<std::string>("device");
  l.baud = s.positive_int("baud", 0, true);
  l.frame_id = s.get<std::string>("frame_id", l.frame_id);
  l.mount_yaw_rad = s.get<double>("mount_yaw_rad", 0.0);
  l.range_min_m = s.positive("range_min_m", l.range_min_m);
  l.range_max_m = s.positive("range_max_m", l.range_max_m);
  if (l.range_max_m <= l.range_min_m) s.fail(s.key("range_max_m"), "must exceed range_min_m");
  s.reject_unknown();
  return l;
}

Camera parse_camera(const Section &s) {
  Camera c;
  c.source = s.get<std::string>("source");
  c.channel = s.get<std::string>("channel");
  c.frame_id = s.get<std::string>("frame_id", c.frame_id);
  c.rate_hz = s.positive("rate_hz", 0, true);
  c.width_px = s.positive_int("width_px", c.width_px);
  c.height_px = s.positive_int("height_px", c.height_px);
  c.jpeg_quality = s.positive_int("jpeg_quality", c.jpeg_quality);
  if (c.jpeg_quality > 100) s.fail(s.key("jpeg_quality"), "must be 1..100");
  c.loop_file = s.get<bool>("loop_file", c.loop_file);
  // Intrinsics: from the pinhole figures of the Nigel camera unless given.
  const double fx = c.width_px / (2.0 * std::tan(0.5 * 62.2 * M_PI / 180.0));
  c.k = {fx, 0, c.width_px / 2.0, 0, fx, c.height_px / 2.0, 0, 0, 1};
  if (s.has("k")) {
    auto k = s.get<std::vector<double>>("k");
    if (k.size() != 9) s.fail(s.key("k"), "must have 9 numbers (row-major camera matrix)");
    std::copy(k.begin(), k.end(), c.k.begin());
  }
  c.d = s.get<std::vector<double>>("d", std::vector<double>(5, 0.0));
  s.reject_unknown();
  return c;
}

Estimator parse_estimator(const Section &s) {
  Estimator e;
  e.rate_hz = s.positive("rate_hz", 0, true);
  e.odom_speed_std_m_s = s.positive("odom_speed_std_m_s", e.odom_speed_std_m_s);
  e.yaw_rate_std_rad_s = s.positive("yaw_rate_std_rad_s", e.yaw_rate_std_rad_s);
  e.eye_pos_std_m = s.positive("eye_pos_std_m", e.eye_pos_std_m);
  e.eye_yaw_std_rad = s.positive("eye_yaw_std_rad", e.eye_yaw_std_rad);
  e.process_pos_std_m = s.positive("process_pos_std_m", e.process_pos_std_m);
  e.process_yaw_std_rad = s.positive("process_yaw_std_rad", e.process_yaw_std_rad);
  e.history_ms = s.positive_int("history_ms", e.history_ms);
  e.use_imu = s.get<bool>("use_imu", e.use_imu);
  s.reject_unknown();
  return e;
}

Config from_node(const YAML::Node &root, const std::string &file) {
  if (!root || !root.IsMap()) throw Error(file + ": expected a YAML mapping at the top level");
  Section top(root, "", file);
  Config c;
  c.file = file;
  c.lcm_url = top.get<std::string>("lcm_url");
  const auto clock = top.get<std::string>("clock");
  if (clock == "wall")
    c.clock = ClockMode::wall;
  else if (clock == "sim")
    c.clock = ClockMode::sim;
  else
    top.fail("clock", "must be 'wall' or 'sim', got '" + clock + "'");
  c.vehicle = parse_vehicle(top.child("vehicle"));
  if (!top.has("vehicle")) top.fail("vehicle", "missing key");
  if ((c.has_bridge = top.has("bridge"))) c.bridge = parse_bridge(top.child("bridge"));
  if ((c.has_lidar = top.has("lidar"))) c.lidar = parse_lidar(top.child("lidar"));
  if ((c.has_estimator = top.has("estimator")))
    c.estimator = parse_estimator(top.child("estimator"));
  if (top.has("cameras")) {
    const YAML::Node cams = root["cameras"];
    top.get<YAML::Node>("cameras");
    if (!cams.IsSequence()) top.fail("cameras", "expected a list");
    for (std::size_t i = 0; i < cams.size(); ++i)
      c.cameras.push_back(
          parse_camera(Section(cams[i], "cameras[" + std::to_string(i) + "]", file)));
  }
  top.reject_unknown();
  return c;
}

}  // namespace

Config parse(const std::string &yaml_text, const std::string &name) {
  YAML::Node root;
  try {
    root = YAML::Load(yaml_text);
  } catch (const YAML::Exception &e) {
    throw Error(name + ": not valid YAML: " + e.what());
  }
  return from_node(root, name);
}

Config load(const std::string &path) {
  std::ifstream in(path);
  if (!in) throw Error(path + ": cannot open the config file");
  std::stringstream ss;
  ss << in.rdbuf();
  return parse(ss.str(), path);
}

}  // namespace cfg
