#include <autodrive/autonomy/mission.hpp>

namespace autodrive::autonomy {

const char *mission_state_name(MissionState s) {
  switch (s) {
    case MissionState::kMapping: return "MAPPING";
    case MissionState::kSaving: return "SAVING";
    case MissionState::kLocalising: return "LOCALISING";
    case MissionState::kPlanning: return "PLANNING";
    case MissionState::kDriving: return "DRIVING";
    case MissionState::kParked: return "PARKED";
    case MissionState::kFailed: return "FAILED";
  }
  return "?";
}

Mission::Mission(const MissionConfig &cfg, double now_s)
    : cfg_(cfg),
      state_(cfg.start_with_map ? MissionState::kLocalising : MissionState::kMapping),
      detail_(cfg.start_with_map ? "localising on the given map" : "mapping"),
      entered_s_(now_s) {}

void Mission::go(MissionState to, const std::string &why, double now_s) {
  history_.push_back(std::string(mission_state_name(state_)) + " -> " + mission_state_name(to) +
                     ": " + why);
  state_ = to;
  detail_ = why;
  entered_s_ = now_s;
}

void Mission::note(const std::string &what) {
  history_.push_back(std::string(mission_state_name(state_)) + ": " + what);
  detail_ = what;
}

bool Mission::mapping_done(double now_s) {
  if (state_ != MissionState::kMapping) return false;
  go(MissionState::kSaving, "map complete", now_s);
  return true;
}

bool Mission::saved(bool ok, const std::string &why, double now_s) {
  if (state_ != MissionState::kSaving) return false;
  go(ok ? MissionState::kLocalising : MissionState::kFailed, why, now_s);
  return true;
}

bool Mission::localised(double now_s) {
  if (state_ != MissionState::kLocalising) return false;
  go(MissionState::kPlanning, "localised", now_s);
  return true;
}

bool Mission::planned(bool ok, const std::string &why, double now_s) {
  if (state_ != MissionState::kPlanning) return false;
  go(ok ? MissionState::kDriving : MissionState::kFailed, why, now_s);
  return true;
}

bool Mission::blocked(const std::string &why, double now_s) {
  if (state_ != MissionState::kDriving) return false;
  if (++replans_ > cfg_.max_replans) {
    go(MissionState::kFailed, "too many replans; last: " + why, now_s);
  } else {
    go(MissionState::kPlanning, "replan: " + why, now_s);
  }
  return true;
}

bool Mission::arrived(bool within_tolerance, const std::string &why, double now_s) {
  if (state_ != MissionState::kDriving) return false;
  if (within_tolerance) {
    go(MissionState::kParked, why, now_s);
  } else if (++replans_ > cfg_.max_replans) {
    go(MissionState::kFailed, "stopped off the goal too often; last: " + why, now_s);
  } else {
    go(MissionState::kPlanning, "retry: " + why, now_s);
  }
  return true;
}

bool Mission::fail(const std::string &why, double now_s) {
  if (finished()) return false;
  go(MissionState::kFailed, why, now_s);
  return true;
}

void Mission::tick(double now_s) {
  double limit = 0;
  switch (state_) {
    case MissionState::kMapping: limit = cfg_.timeout_mapping_s; break;
    case MissionState::kLocalising: limit = cfg_.timeout_localising_s; break;
    case MissionState::kPlanning: limit = cfg_.timeout_planning_s; break;
    case MissionState::kDriving: limit = cfg_.timeout_driving_s; break;
    default: return;
  }
  if (now_s - entered_s_ > limit)
    go(MissionState::kFailed, std::string("timeout in ") + mission_state_name(state_), now_s);
}

}  // namespace autodrive::autonomy
