#include <autodrive/core/config.hpp>

#include <autodrive/core/clock.hpp>
#include <autodrive/instance.hpp>

#include <autodrive_channels.h>

#include <cmath>

namespace autodrive::config {
namespace {

using autodrive::yaml::Section;

constexpr int kMinBaud = 1200, kMaxBaud = 4000000;  // [bit/s]

Vehicle parse_vehicle(const Section &s) {
  Vehicle v;
  v.name = s.get<std::string>("name");
  if (v.name.empty()) s.fail(s.key("name"), "must not be empty");
  // The car's figures have one place: a config that sets one would silently disagree with it.
  for (const char *k :
       {"wheelbase_m", "track_m", "wheel_radius_m", "steering_limit_rad", "encoder_counts_per_rev"})
    if (s.has(k))
      s.fail(s.key(k),
             "is a figure of the car: it comes from vehicle/nigel.params (and the firmware's "
             "encoder resolution), not from a config");
  s.reject_unknown();
  return v;
}

Bridge parse_bridge(const Section &s) {
  Bridge b;
  b.device = s.get<std::string>("device");
  // Ranges that keep the failsafe meaningful: a command older than 500 ms is never obeyed,
  // and the heartbeat is fast enough for the Nano's failsafe (20..150 ms) yet bounded.
  b.baud = s.in_range("baud", kMinBaud, kMaxBaud);
  b.heartbeat_hz = s.in_range("heartbeat_hz", 10.0, 500.0);
  b.command_timeout_ms = s.in_range("command_timeout_ms", 1, 500);
  b.hello_retry_ms = s.in_range("hello_retry_ms", 10, 10000, b.hello_retry_ms);
  b.refused_retry_ms = s.in_range("refused_retry_ms", 10, 60000, b.refused_retry_ms);
  b.reconnect_ms = s.in_range("reconnect_ms", 10, 60000, b.reconnect_ms);
  b.link_timeout_ms = s.in_range("link_timeout_ms", 50, 10000, b.link_timeout_ms);
  b.telemetry_period_ms = s.get<int>("telemetry_period_ms", b.telemetry_period_ms);
  if (b.telemetry_period_ms != 0 && (b.telemetry_period_ms < 5 || b.telemetry_period_ms > 1000))
    s.fail(s.key("telemetry_period_ms"), "must be 0 (do not configure) or 5..1000");
  b.failsafe_timeout_ms = s.get<int>("failsafe_timeout_ms", b.failsafe_timeout_ms);
  if (b.failsafe_timeout_ms < 20 || b.failsafe_timeout_ms > 150)
    s.fail(s.key("failsafe_timeout_ms"), "must be 20..150 (firmware range)");
  // Two heartbeats per Nano failsafe period at least, or a healthy link trips the failsafe.
  if (1000.0 / b.heartbeat_hz > b.failsafe_timeout_ms / 2.0)
    s.fail(s.key("heartbeat_hz"),
           std::to_string(b.heartbeat_hz) + " is too slow for failsafe_timeout_ms " +
               std::to_string(b.failsafe_timeout_ms) +
               ": must be >= " + std::to_string(2000.0 / b.failsafe_timeout_ms) +
               " (two frames per failsafe period)");
  b.command_burst_frames = s.in_range("command_burst_frames", 1, 8, b.command_burst_frames);
  b.command_rate_hz = s.in_range("command_rate_hz", 1.0, 500.0, b.command_rate_hz);
  if (b.command_rate_hz < b.heartbeat_hz)
    s.fail(s.key("command_rate_hz"), "must be >= heartbeat_hz (" + std::to_string(b.heartbeat_hz) +
                                         "): a heartbeat takes a token too");
  b.servo_trim_us = s.get<int>("servo_trim_us", b.servo_trim_us);
  b.sync_to_sim_clock = s.get<bool>("sync_to_sim_clock", b.sync_to_sim_clock);
  b.sim_clock_commands = s.get<bool>("sim_clock_commands", b.sim_clock_commands);
  if (b.sim_clock_commands && b.sync_to_sim_clock)
    s.fail(s.key("sim_clock_commands"), "and sync_to_sim_clock exclude each other");
  b.command_key_file = s.get<std::string>("command_key_file", "");
  b.replay_window_ms = s.positive_int("replay_window_ms", b.replay_window_ms);
  if (b.replay_window_ms > 10000)
    s.fail(s.key("replay_window_ms"), "must be 1..10000 (a replayed command must go stale fast)");
  b.command_lease_ms = s.positive_int("command_lease_ms", b.command_lease_ms);
  if (b.command_lease_ms > 5000) s.fail(s.key("command_lease_ms"), "must be 1..5000");
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
  l.baud = s.in_range("baud", kMinBaud, kMaxBaud);
  l.frame_id = s.get<std::string>("frame_id", l.frame_id);
  l.mount_yaw_rad = s.in_range("mount_yaw_rad", -M_PI, M_PI, 0.0);
  l.range_min_m = s.positive_up_to("range_min_m", 5.0, l.range_min_m);
  l.range_max_m = s.positive_up_to("range_max_m", 40.0, l.range_max_m);
  if (l.range_max_m <= l.range_min_m) s.fail(s.key("range_max_m"), "must exceed range_min_m");
  s.reject_unknown();
  return l;
}

Camera parse_camera(const Section &s) {
  Camera c;
  c.source = s.get<std::string>("source");
  // The camera's channel pair comes from the channel table: image and its _INFO.
  const std::string channel = s.get<std::string>("channel");
  if ("_" + channel == AUTODRIVE_CH_CAM_FRONT_SUFFIX) {
    c.channel = AUTODRIVE_CH_CAM_FRONT_SUFFIX;
    c.info_channel = AUTODRIVE_CH_CAM_FRONT_INFO_SUFFIX;
  } else if ("_" + channel == AUTODRIVE_CH_CAM_REAR_SUFFIX) {
    c.channel = AUTODRIVE_CH_CAM_REAR_SUFFIX;
    c.info_channel = AUTODRIVE_CH_CAM_REAR_INFO_SUFFIX;
  } else {
    s.fail(s.key("channel"),
           "must be CAM_FRONT or CAM_REAR (lcm_types/channels.yaml), got '" + channel + "'");
  }
  c.frame_id = s.get<std::string>("frame_id", c.frame_id);
  c.rate_hz = s.positive_up_to("rate_hz", 240.0, 0, true);
  c.width_px = s.in_range("width_px", 16, 8192, c.width_px);
  c.height_px = s.in_range("height_px", 16, 8192, c.height_px);
  c.jpeg_quality = s.in_range("jpeg_quality", 1, 100, c.jpeg_quality);
  c.loop_file = s.get<bool>("loop_file", c.loop_file);
  c.open_timeout_ms = s.in_range("open_timeout_ms", 100, 60000, c.open_timeout_ms);
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
  e.rate_hz = s.positive_up_to("rate_hz", 1000.0, 0, true);
  e.odom_speed_std_m_s = s.positive_up_to("odom_speed_std_m_s", 10.0, e.odom_speed_std_m_s);
  e.yaw_rate_std_rad_s = s.positive_up_to("yaw_rate_std_rad_s", 10.0, e.yaw_rate_std_rad_s);
  e.eye_pos_std_m = s.positive_up_to("eye_pos_std_m", 10.0, e.eye_pos_std_m);
  e.eye_yaw_std_rad = s.positive_up_to("eye_yaw_std_rad", M_PI, e.eye_yaw_std_rad);
  e.process_pos_std_m = s.positive_up_to("process_pos_std_m", 10.0, e.process_pos_std_m);
  e.process_yaw_std_rad = s.positive_up_to("process_yaw_std_rad", M_PI, e.process_yaw_std_rad);
  e.history_ms = s.in_range("history_ms", 1, 10000, e.history_ms);
  s.read_in_range("pose_gate_chi2", e.pose_gate_chi2, 1.0, 1000.0);
  s.read_in_range("pose_reacquire_s", e.pose_reacquire_s, 0.5, 600.0);
  s.read_in_range("max_speed_m_s", e.max_speed_m_s, 0.1, 50.0);
  s.read_in_range("max_yaw_rate_rad_s", e.max_yaw_rate_rad_s, 0.1, 100.0);
  e.use_imu = s.get<bool>("use_imu", e.use_imu);
  if ((e.has_initial_pose_map = s.has("initial_pose_map"))) {
    const auto v = s.numbers("initial_pose_map", 3);
    for (int i = 0; i < 3; ++i) e.initial_pose_map[i] = v[i];
  }
  e.initial_pos_std_m = s.positive_up_to("initial_pos_std_m", 10.0, e.eye_pos_std_m);
  e.initial_yaw_std_rad = s.positive_up_to("initial_yaw_std_rad", M_PI, e.eye_yaw_std_rad);
  s.reject_unknown();
  return e;
}

Config from_node(const YAML::Node &root, const std::string &file) {
  if (!root || !root.IsMap()) throw Error(file + ": expected a YAML mapping at the top level");
  Section top(root, "", file);
  Config c;
  c.file = file;
  c.lcm_url = top.get<std::string>("lcm_url");
  // Two sessions on one machine: AUTODRIVE_INSTANCE moves the default bus and the simulator's
  // ptys (<autodrive/instance.hpp>).
  autodrive::Instance session(0);
  try {
    session = autodrive::instance();
  } catch (const autodrive::InstanceError &e) {
    throw Error(file + ": " + e.what());
  }
  c.lcm_url = session.lcm_url(c.lcm_url);
  const auto clock = top.get<std::string>("clock");
  if (const auto mode = autodrive::clock::clock_mode_named(clock))
    c.clock = *mode;
  else
    top.fail("clock", "must be 'wall' or 'sim', got '" + clock + "'");
  c.vehicle = parse_vehicle(top.child("vehicle"));
  if (!top.has("vehicle")) top.fail("vehicle", "missing key");
  if ((c.has_bridge = top.has("bridge"))) c.bridge = parse_bridge(top.child("bridge"));
  c.bridge.device = session.sim_path(c.bridge.device);
  if (c.has_bridge && c.bridge.sync_to_sim_clock && c.clock != ClockMode::sim)
    top.fail("bridge.sync_to_sim_clock", "needs clock: sim (it sends on SIM_CLOCK ticks)");
  if (c.has_bridge && c.bridge.sim_clock_commands && c.clock != ClockMode::sim)
    top.fail("bridge.sim_clock_commands", "needs clock: sim");
  if ((c.has_lidar = top.has("lidar"))) c.lidar = parse_lidar(top.child("lidar"));
  c.lidar.device = session.sim_path(c.lidar.device);
  if ((c.has_estimator = top.has("estimator")))
    c.estimator = parse_estimator(top.child("estimator"));
  if (top.has("cameras")) {
    const YAML::Node cams = top.list("cameras", "expected a list");
    for (std::size_t i = 0; i < cams.size(); ++i)
      c.cameras.push_back(
          parse_camera(Section(cams[i], "cameras[" + std::to_string(i) + "]", file)));
  }
  c.v2v_hz = top.number("v2v_hz", c.v2v_hz);
  if (c.v2v_hz < 0 || c.v2v_hz > 100) top.fail("v2v_hz", "must be in [0, 100] Hz (0: off)");
  c.v2v_stale_ms = top.in_range("v2v_stale_ms", 10, 10000, c.v2v_stale_ms);
  c.route = top.get<std::string>("route", c.route);
  top.reject_unknown();
  return c;
}

}  // namespace

Config parse(const std::string &yaml_text, const std::string &name) {
  return from_node(autodrive::yaml::load_string(yaml_text, name), name);
}

Config load(const std::string &path) {
  return from_node(autodrive::yaml::load_file(path), path);
}

}  // namespace autodrive::config
