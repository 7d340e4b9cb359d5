// mission_: the parking mission's state machine, pure logic (no I/O, time passed in):
//   MAPPING -> SAVING -> LOCALISING -> PLANNING -> DRIVING -> PARKED
//   DRIVING -> PLANNING on a blocked path (replan) or when the stop is off the goal (retry);
//   any state -> FAILED on an error, a state timeout or too many replans.
// State numbers are those of mission_status_t.
#pragma once
#include <string>
#include <vector>

namespace autodrive::autonomy {

enum class MissionState : int {
  kMapping = 0,
  kSaving,
  kLocalising,
  kPlanning,
  kDriving,
  kParked,
  kFailed
};

const char *mission_state_name(MissionState s);

struct MissionConfig {
  bool start_with_map = false;  // true: skip MAPPING/SAVING (a saved map was given)
  int max_replans = 8;
  double timeout_mapping_s = 60, timeout_localising_s = 20, timeout_planning_s = 30,
         timeout_driving_s = 180;
};

class Mission {
 public:
  explicit Mission(const MissionConfig &cfg, double now_s = 0.0);
  MissionState state() const { return state_; }
  bool finished() const {
    return state_ == MissionState::kParked || state_ == MissionState::kFailed;
  }
  const std::string &detail() const { return detail_; }
  int replans() const { return replans_; }
  double entered_s() const { return entered_s_; }
  const std::vector<std::string> &history() const { return history_; }  // "A -> B: why"

  // Events; each returns false (and changes nothing) when it does not apply to the state.
  bool mapping_done(double now_s);
  bool saved(bool ok, const std::string &why, double now_s);
  bool localised(double now_s);
  bool planned(bool ok, const std::string &why, double now_s);
  bool blocked(const std::string &why, double now_s);
  bool arrived(bool within_tolerance, const std::string &why, double now_s);
  bool fail(const std::string &why, double now_s);
  // Progress within the current state (e.g. a mapping-route leg): history and detail, no change.
  void note(const std::string &what);
  // Fails the mission when the current state has lasted longer than its timeout.
  void tick(double now_s);

 private:
  void go(MissionState to, const std::string &why, double now_s);
  MissionConfig cfg_;
  MissionState state_;
  std::string detail_;
  double entered_s_;
  int replans_ = 0;
  std::vector<std::string> history_;
};

}  // namespace autodrive::autonomy
