// The bridge's command gate: which <VEH>_COMMAND may drive the car. A command passes only when
// it is signed with the car's key (autodrive::auth), its counter is newer than the last one of
// its source, newer than the gate's start and within the replay window of the wall clock, and
// its source holds the control lease. (Without the start rule a bridge that restarts, knowing
// no source's last counter, took a replay of any command of the last window as new.) Lease rules
// (after panda's "only the one who holds control may drive"):
//  - the holder renews the lease with every valid command, engaged or not;
//  - a free (or lapsed) lease goes to the first source that sends an engaged command;
//  - a person (AUTHORITY_PERSON: the teleop dead-man) takes a live lease from a machine with an
//    engaged command; a machine never takes a live lease from anyone.
// No I/O and no clock of its own: callers pass the times, so the unit tests drive every rule.
#pragma once

#include <autodrive/command_auth.hpp>
#include <autodrive/vehicle_command_t.hpp>

#include <cstdint>
#include <string>
#include <unordered_map>

namespace autodrive::bridge {

// idle: a valid disengaged command of a source without control (ignored, not counted).
enum class Drop { none, unsigned_cmd, bad_mac, replay, not_holder, idle };
const char *drop_name(Drop d);

struct GateCounters {
  int64_t applied = 0;
  int64_t dropped_unsigned = 0;
  int64_t dropped_bad_mac = 0;
  int64_t dropped_replay = 0;
  int64_t dropped_not_holder = 0;
  int32_t holder_changes = 0;
  std::string last_dropped_source;
};

class CommandGate {
 public:
  // replay_window_us: how far a counter may be from the wall clock [us]; lease_us: how long the
  // holder keeps control without a valid command [us]; start_wall_us: the wall clock when the
  // gate starts [us]: counters at or before it are refused as replays.
  CommandGate(const autodrive::auth::Key &key, std::string vehicle, int64_t replay_window_us,
              int64_t lease_us, int64_t start_wall_us);

  struct Verdict {
    Drop drop = Drop::none;       // none: apply the command
    bool holder_changed = false;  // the lease changed hands (or lapsed) on this call
  };
  // mono_us: monotonic clock (lease), wall_us: wall clock (counter window).
  Verdict admit(const autodrive::vehicle_command_t &c, int64_t mono_us, int64_t wall_us);
  // Lets a lapsed lease go; true when that changed the holder.
  bool expire(int64_t mono_us);

  const std::string &holder() const { return holder_; }
  int8_t holder_authority() const { return holder_authority_; }
  const GateCounters &counters() const { return n_; }

 private:
  Drop drop(Drop d, const std::string &source);

  autodrive::auth::Key key_;
  std::string vehicle_;
  int64_t window_us_, lease_us_, start_wall_us_;
  std::unordered_map<std::string, int64_t> last_counter_;  // per verified source
  std::string holder_;
  int8_t holder_authority_ = 0;
  int64_t lease_until_us_ = 0;
  GateCounters n_;
};

}  // namespace autodrive::bridge
