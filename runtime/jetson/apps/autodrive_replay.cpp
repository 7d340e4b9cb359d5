// autodrive-replay: runs the runtime's estimator on a recorded LCM log (file://, as fast as it
// goes) and writes its ODOM and POSE_MAP to a new log. The estimator's time is the logged
// messages' stamps, so the outputs are those of the run, whatever the machine's speed.
#include <CLI/CLI.hpp>

#include <cstdio>
#include <filesystem>
#include <string>

#include <autodrive/core/config.hpp>
#include <autodrive/estimator/estimator_node.hpp>

int main(int argc, char **argv) {
  CLI::App cli{
      "autodrive-replay: the runtime's estimator (EKF) on a recorded LCM log; ODOM and "
      "POSE_MAP of the replay go to --out (an LCM log)"};
  std::string config_path, in_path, out_path;
  cli.add_option("-c,--config", config_path, "runtime config (its vehicle and estimator sections)")
      ->required();
  cli.add_option("--in", in_path, "recorded LCM log (STATE, IMU, POSE_EYE of the vehicle)")
      ->required();
  cli.add_option("--out", out_path, "LCM log to write the replay's outputs to")->required();
  CLI11_PARSE(cli, argc, argv);
  if (!std::filesystem::is_regular_file(in_path)) {
    std::fprintf(stderr, "autodrive-replay: %s: no such log\n", in_path.c_str());
    return 2;
  }
  autodrive::config::Config config;
  try {
    config = autodrive::config::load(config_path);
  } catch (const autodrive::config::Error &e) {
    std::fprintf(stderr, "autodrive-replay: %s\n", e.what());
    return 2;
  }
  config.lcm_url = "file://" + std::filesystem::absolute(in_path).string() + "?speed=0";
  // The log's Eye poses were checked by the car that recorded it (and the stored logs predate
  // signed poses): the replay takes them as logged.
  autodrive::estimator::EstimatorNode node(
      config, "file://" + std::filesystem::absolute(out_path).string() + "?mode=w",
      autodrive::estimator::EyePoseAuth::trust_recorded_log);
  if (const std::string e = node.init_error(); !e.empty()) {
    std::fprintf(stderr, "autodrive-replay: %s\n", e.c_str());
    return 2;
  }
  const long n = node.replay();
  std::printf("autodrive-replay: %ld messages of %s replayed into %s\n", n, in_path.c_str(),
              out_path.c_str());
  return 0;
}
