// autodrive-pilot's configuration (runtime/jetson/config/pilot_*.yaml), read strictly: unknown
// or missing keys and out-of-range numbers are refused naming the file and the dotted key.
#pragma once

#include <string>

#include <autodrive/core/clock.hpp>

#include <autodrive/pilot/speed_rule.hpp>

namespace autodrive::pilot {

struct PilotConfig {
  std::string lcm_url;
  std::string vehicle;
  std::string model;  // NAME.onnx; relative paths are relative to the config file
  // Optional key `clock: wall|sim` (default wall): the frame timeout's clock and SIM_CLOCK's use.
  autodrive::config::ClockMode clock = autodrive::config::ClockMode::wall;
  int frame_timeout_ms = 500;   // no front-camera frame for this long [ms, clock] -> stop
  double command_rate_hz = 50;  // commands at least this often while driving or stopped
  SpeedRuleConfig speed;
};

PilotConfig load_config(const std::string &path);

}  // namespace autodrive::pilot
