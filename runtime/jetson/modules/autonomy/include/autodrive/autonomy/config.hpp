// cfg_: the YAML configuration of autodrive-autonomy (see config/autonomy.example.yaml).
// Unknown keys and wrong types are errors naming the file and the key.
#pragma once
#include <autodrive_channels.h>

#include <string>

#include <autodrive/autonomy/autonomy_node.hpp>

namespace autodrive::autonomy {

struct ProgramConfig {
  std::string vehicle = AUTODRIVE_VEHICLE_DEFAULT;
  std::string lcm_url = AUTODRIVE_LCM_URL_DEFAULT;
  std::string out_dir = "out/autonomy";  // path.csv, route.csv, trajectory.csv
  double command_rate_hz = 50.0;
  double exit_after_finish_s = 1.0;  // keep publishing the stop this long, then exit
  NodeConfig node;
};

// Throws autodrive::yaml::Error ("<path>: <dotted.key>: <what>") on any problem.
ProgramConfig cfg_load(const std::string &path);

}  // namespace autodrive::autonomy
