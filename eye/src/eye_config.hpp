// The `run` configuration file: calibration files, tag geometry, vehicles, detector, LCM.
#pragma once
#include <autodrive_channels.h>

#include <string>
#include <vector>

#include "eye_camera.hpp"
#include "eye_detect.hpp"
#include "eye_locate.hpp"

namespace eye {

struct TrackingParams {
  bool roi = true;      // search cars seen last frame only around their last tag
  int full_every = 10;  // scan the whole frame every this many frames
  double margin = 1.0;  // window = last tag box grown by this many tag sizes per side
};

struct RunConfig {
  std::string path;             // the config file itself
  std::string intrinsics_path;  // resolved against the config file's folder
  std::string map_path;
  std::string lcm_url = AUTODRIVE_LCM_URL_DEFAULT;
  Intrinsics in;
  CameraPose pose;
  LocateParams locate;
  DetectorParams detector;
  TrackingParams tracking;
  std::vector<VehicleTag> vehicles;
};

// Loads the config and the calibration files it names. Throws eye::Error naming the file and
// the field on anything missing or malformed.
RunConfig runconfig_load(const std::string &path);

}  // namespace eye
