// Runtime configuration from YAML. Every key is required unless its comment says otherwise; a
// missing or malformed key throws autodrive::config::Error naming the file and the dotted key.
#pragma once

#include <autodrive/core/clock.hpp>
#include <autodrive/strict_yaml.hpp>
#include <autodrive_vehicle.h>
#include <yaml-cpp/yaml.h>

#include "encoder.h"

#include <array>
#include <stdexcept>
#include <string>
#include <vector>

namespace autodrive::config {

using Error = autodrive::yaml::Error;

// The car: its name from the config, its figures from vehicle/nigel.params (generated
// <autodrive_vehicle.h>) and the firmware's encoder resolution; a config cannot change them.
struct Vehicle {
  std::string name;  // e.g. "NIGEL1": channel prefix
  double wheelbase_m = AUTODRIVE_VEHICLE_WHEELBASE_M;
  double track_m = AUTODRIVE_VEHICLE_TRACK_M;
  double wheel_radius_m = AUTODRIVE_VEHICLE_WHEEL_RADIUS_M;
  double steering_limit_rad = AUTODRIVE_VEHICLE_STEER_LIMIT_RAD;  // steering = 1.0 maps to this
  int encoder_counts_per_rev = ENCODER_COUNTS_PER_REV;
};

struct Bridge {
  std::string device;          // serial device or pty symlink
  int baud = 500000;           // [bit/s]
  double heartbeat_hz = 50.0;  // COMMAND frames per second while no command arrives
  // The token bucket of COMMAND frames (nano_bridge/command_pacer.hpp): a fresh command goes
  // at once while a token is left; a flood is capped at command_rate_hz. Optional keys. A
  // 16-byte COMMAND frame is 320 us of line at 500 kBd: 100 Hz is 3.2 % of the line, and a
  // burst of 4 frames (64 bytes) half the Nano's 128-byte receive ring.
  int command_burst_frames = 4;    // bucket depth [frames], 1..8
  double command_rate_hz = 100.0;  // refill [frames/s], heartbeat_hz..500
  int command_timeout_ms = 200;    // older LCM command -> disengage
  int hello_retry_ms = 200;        // HELLO_REQUEST period while handshaking
  int refused_retry_ms = 5000;     // HELLO_REQUEST period after a schema mismatch
  int reconnect_ms = 500;          // reopen period while the device is missing
  int link_timeout_ms = 500;       // no frame for this long -> handshake again
  int telemetry_period_ms = 10;    // sent to the Nano in CONFIG; 0 = do not send CONFIG
  int failsafe_timeout_ms = 100;   // sent in CONFIG
  int servo_trim_us = 0;           // sent in CONFIG
  // clock sim: one frame per SIM_CLOCK tick, and a command stamped later than the sim clock
  // applies from that sim time (repeatable HIL with autodrive-sim --lockstep-frames)
  bool sync_to_sim_clock = false;
  // clock sim (optional, default false): the command path (lease, freshness, token bucket,
  // heartbeat) on SIM_CLOCK instead of the monotonic clock. Off by default: autodrive-sim
  // --lockstep-client paces itself on the bridge's bytes, and a sim-time heartbeat lets it run
  // ahead of the other components.
  bool sim_clock_commands = false;
  // Command authentication (bridge/command_gate.hpp). Optional keys: the key file (default
  // autodrive::auth::default_key_path(vehicle), created by tools/keys), how far a command's
  // counter may be from the wall clock, and how long the holder keeps control without commands.
  std::string command_key_file;
  int replay_window_ms = 1000;
  int command_lease_ms = 500;
  std::string imu_frame_id = "imu_link";
  double imu_orientation_var_rad2 = 0.0;  // diagonal of the covariances
  double imu_gyro_var_rad2_s2 = 0.0;
  double imu_accel_var_m2_s4 = 0.0;
};

struct Lidar {
  std::string device;
  int baud = 115200;
  std::string frame_id = "laser";
  double mount_yaw_rad = 0.0;  // added to every ray angle (CCW)
  double range_min_m = 0.15;
  double range_max_m = 12.0;
};

struct Camera {
  std::string source;        // /dev/videoN, a GStreamer pipeline (contains '!') or a video file
  std::string channel;       // suffix of the image channel, e.g. "_CAM_FRONT" (<VEH>_CAM_FRONT)
  std::string info_channel;  // suffix of its intrinsics channel, e.g. "_CAM_FRONT_INFO"
  std::string frame_id = "camera_front";
  double rate_hz = 30.0;
  int width_px = 640;
  int height_px = 480;
  int jpeg_quality = 85;
  std::array<double, 9> k{};  // camera matrix [px]
  std::vector<double> d;      // plumb_bob k1 k2 p1 p2 k3
  bool loop_file = true;      // restart a video file at its end
  // Optional: how long opening the source may take [ms] before it is reported and retried (a
  // GStreamer pipeline whose element is missing or whose camera is unplugged never opens).
  int open_timeout_ms = 5000;
};

struct Estimator {
  double rate_hz = 100.0;            // ODOM / POSE_MAP publish rate
  double odom_speed_std_m_s = 0.02;  // wheel speed noise
  double yaw_rate_std_rad_s = 0.02;  // IMU gyro z noise
  double eye_pos_std_m = 0.01;       // used when the Eye covariance is zero
  double eye_yaw_std_rad = 0.02;
  double process_pos_std_m = 0.01;    // per sqrt(s)
  double process_yaw_std_rad = 0.02;  // per sqrt(s)
  int history_ms = 1000;              // how late an Eye pose may arrive and still be fused
  // Input checks. An Eye pose whose squared Mahalanobis distance to the estimate exceeds
  // pose_gate_chi2 (3 degrees of freedom; 16.3 = 99.9 %) is rejected and counted. After
  // pose_reacquire_s without an accepted pose, a run of mutually consistent poses re-places
  // the car (the Eye's re-acquisition after a long gap; a forged stream cannot do this while
  // the real Eye keeps being accepted).
  double pose_gate_chi2 = 16.3;
  double pose_reacquire_s = 5.0;      // [s]
  double max_speed_m_s = 10.0;        // encoder speed above this is a glitch: dropped
  double max_yaw_rate_rad_s = 17.45;  // gyro z above this (1000 deg/s, the IMU's range): dropped
  bool use_imu = true;
  // Optional: the car's map pose (x [m], y [m], yaw [rad]) at start, where it was placed, and
  // how sure of it the one who placed it is (1 sigma; default: the Eye's noise). The map filter
  // starts there instead of waiting for the Eye's first fix, so POSE_MAP (and V2V) exist
  // without an Eye; Eye poses, when they come, correct it. Without it the map filter publishes
  // nothing until its first Eye pose.
  bool has_initial_pose_map = false;
  std::array<double, 3> initial_pose_map{};
  double initial_pos_std_m = 0.0;    // 0: eye_pos_std_m
  double initial_yaw_std_rad = 0.0;  // 0: eye_yaw_std_rad
};

struct Config {
  std::string file;
  std::string lcm_url;
  ClockMode clock = ClockMode::wall;
  Vehicle vehicle;
  bool has_bridge = false, has_lidar = false, has_estimator = false;
  Bridge bridge;
  Lidar lidar;
  Estimator estimator;
  std::vector<Camera> cameras;
  // V2V (optional keys): broadcast rate [Hz] of v2v_state_t (0: off), the age [ms] beyond which
  // a peer's state is dropped, and the route this car drives (its intent; "" when none, the
  // runtime's --route overrides it).
  double v2v_hz = 20.0;
  int v2v_stale_ms = 200;
  std::string route;
};

// Loads and validates the file. Throws autodrive::config::Error("<file>: <key>: <what is wrong>").
Config load(const std::string &path);
// Same, from YAML text (tests); `name` stands for the file in error messages.
Config parse(const std::string &yaml_text, const std::string &name);

}  // namespace autodrive::config
