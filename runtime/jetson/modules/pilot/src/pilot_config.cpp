#include <autodrive/pilot/pilot_config.hpp>

#include <autodrive/strict_yaml.hpp>

#include <filesystem>

namespace autodrive::pilot {

PilotConfig load_config(const std::string &path) {
  const autodrive::yaml::Section top(autodrive::yaml::load_file(path), "", path);
  PilotConfig c;
  c.lcm_url = top.get<std::string>("lcm_url");
  c.vehicle = top.get<std::string>("vehicle");
  c.model = top.get<std::string>("model");
  if (!c.model.empty() && std::filesystem::path(c.model).is_relative())
    c.model = (std::filesystem::path(path).parent_path() / c.model).lexically_normal().string();
  const auto clock = top.get<std::string>("clock", "wall");
  if (const auto mode = autodrive::clock::clock_mode_named(clock))
    c.clock = *mode;
  else
    top.fail("clock", "must be 'wall' or 'sim', got '" + clock + "'");
  c.frame_timeout_ms = top.in_range<int>("frame_timeout_ms", 50, 5000);
  c.command_rate_hz = top.in_range<double>("command_rate_hz", 20.0, 200.0);
  const auto s = top.child("speed");
  SpeedRuleConfig &r = c.speed;
  r.set_speed_m_s = s.in_range<double>("set_speed_m_s", 0.0, 1.0);
  r.min_speed_m_s = s.in_range<double>("min_speed_m_s", 0.0, r.set_speed_m_s);
  r.feedforward_per_m_s = s.in_range<double>("feedforward_per_m_s", 0.0, 20.0);
  r.kp_per_m_s = s.in_range<double>("kp_per_m_s", 0.0, 50.0);
  r.ki_per_m = s.in_range<double>("ki_per_m", 0.0, 50.0);
  r.max_throttle = s.in_range<double>("max_throttle", 0.0, 1.0);
  s.reject_unknown();
  top.reject_unknown();
  return c;
}

}  // namespace autodrive::pilot
