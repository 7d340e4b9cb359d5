// The `run` configuration file: calibration files, tag geometry, vehicles, detector, LCM.
#pragma once
#include <autodrive_channels.h>

#include <string>
#include <vector>

#include "eye_camera.hpp"
#include "eye_detect.hpp"
#include "eye_health.hpp"
#include "eye_locate.hpp"
#include "eye_mapcal.hpp"
#include "eye_scanplan.hpp"

namespace eye {

struct TrackingParams {
  bool roi = true;      // search cars seen last frame only around their last tag
  int full_every = 10;  // scan the whole frame every this many frames
  // window = last tag box grown by this many tag sizes per side: it must hold the tag's move
  // away from its predicted place (the last frame's motion) and its turn; 0.5 lost no tag of
  // the wide-angle bench (240 frames, 10 cars) nor of the pinhole drive, at half the pixels
  // of 1.0 (windows 5.0 -> 2.6 ms CPU per frame with 10 cars).
  double margin = 0.5;
};

struct WholeFieldParams {
  bool enabled = true;  // detector resolution per region from the expected tag size
  ScanPlanParams plan;
};

// One camera of the Eye: its calibration and where its frames come from.
struct CameraConfig {
  std::string name = "eye";
  std::string intrinsics_path, map_path;
  std::string source;  // e.g. "lcm:EYE_IMAGE" (empty: --source)
  Intrinsics in;
  CameraPose pose;
};

struct RunConfig {
  std::string path;             // the config file itself
  std::string intrinsics_path;  // resolved against the config file's folder
  std::string map_path;
  std::string lcm_url = AUTODRIVE_LCM_URL_DEFAULT;
  int realtime_priority = 0;  // SCHED_FIFO priority of `run`'s threads (0: ordinary)
  // lockstep with the simulator: poses out at capture + this, in sim time (eye_lockstep.hpp);
  // < 0: not in lockstep (run --sim-latency-ms overrides)
  double sim_latency_ms = -1.0;
  Intrinsics in;
  CameraPose pose;
  LocateParams locate;
  DetectorParams detector;
  TrackingParams tracking;
  WholeFieldParams whole_field;
  HealthParams health;
  std::vector<RefTag> reference_tags;  // in view of the cameras: health (may be empty)
  std::vector<VehicleTag> vehicles;
  std::string camera_name = "eye";    // of in / pose
  std::vector<CameraConfig> cameras;  // every camera; in / pose are cameras[0]'s
};

// The config of camera i alone (in, pose, names set from cameras[i]).
RunConfig runconfig_camera(const RunConfig &c, size_t i);

// Loads the config and the calibration files it names. Throws eye::Error naming the file and
// the field on anything missing or malformed.
RunConfig runconfig_load(const std::string &path);

}  // namespace eye
