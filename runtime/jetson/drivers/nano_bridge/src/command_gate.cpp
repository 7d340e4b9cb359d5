#include <autodrive/nano_bridge/command_gate.hpp>

#include <cstdlib>

namespace autodrive::bridge {

namespace {
// Verified sources remembered for replay checks; only key holders can add one.
constexpr size_t kMaxSources = 64;
}  // namespace

const char *drop_name(Drop d) {
  switch (d) {
    case Drop::none: return "none";
    case Drop::unsigned_cmd: return "unsigned";
    case Drop::bad_mac: return "bad signature";
    case Drop::replay: return "replayed or out of the replay window";
    case Drop::not_holder: return "another source holds control";
    case Drop::idle: return "disengaged, without control";
  }
  return "?";
}

CommandGate::CommandGate(const autodrive::auth::Key &key, std::string vehicle,
                         int64_t replay_window_us, int64_t lease_us, int64_t start_wall_us)
    : key_(key),
      vehicle_(std::move(vehicle)),
      window_us_(replay_window_us),
      lease_us_(lease_us),
      start_wall_us_(start_wall_us) {}

Drop CommandGate::drop(Drop d, const std::string &source) {
  switch (d) {
    case Drop::unsigned_cmd: ++n_.dropped_unsigned; break;
    case Drop::bad_mac: ++n_.dropped_bad_mac; break;
    case Drop::replay: ++n_.dropped_replay; break;
    case Drop::not_holder: ++n_.dropped_not_holder; break;
    case Drop::none:
    case Drop::idle: break;
  }
  n_.last_dropped_source = source;
  return d;
}

bool CommandGate::expire(int64_t mono_us) {
  if (holder_.empty() || mono_us <= lease_until_us_) return false;
  holder_.clear();
  holder_authority_ = 0;
  ++n_.holder_changes;
  return true;
}

CommandGate::Verdict CommandGate::admit(const autodrive::vehicle_command_t &c, int64_t mono_us,
                                        int64_t wall_us) {
  Verdict v;
  switch (autodrive::auth::check_mac(key_, vehicle_, c)) {
    case autodrive::auth::MacCheck::unsigned_cmd:
      v.drop = drop(Drop::unsigned_cmd, c.source);
      return v;
    case autodrive::auth::MacCheck::bad_mac: v.drop = drop(Drop::bad_mac, c.source); return v;
    case autodrive::auth::MacCheck::ok: break;
  }
  // Authentic from here on. Replays: a counter must be new for its source (or, for a source
  // not heard since the start, newer than the start) and near our clock.
  auto it = last_counter_.find(c.source);
  if ((it != last_counter_.end() && c.counter <= it->second) || c.counter <= start_wall_us_ ||
      std::llabs(c.counter - wall_us) > window_us_) {
    v.drop = drop(Drop::replay, c.source);
    return v;
  }
  if (it == last_counter_.end()) {
    if (last_counter_.size() >= kMaxSources) last_counter_.erase(last_counter_.begin());
    last_counter_[c.source] = c.counter;
  } else {
    it->second = c.counter;
  }
  v.holder_changed = expire(mono_us);
  const bool is_holder = !holder_.empty() && c.source == holder_;
  const bool takes =
      !is_holder && c.engaged && (holder_.empty() || c.authority > holder_authority_);
  if (!is_holder && !takes) {
    // A disengaged command from a source without control asks for nothing (an idle teleop):
    // ignored, not counted. An engaged one wants to drive and may not.
    v.drop = c.engaged ? drop(Drop::not_holder, c.source) : Drop::idle;
    return v;
  }
  if (takes) {
    holder_ = c.source;
    holder_authority_ = c.authority;
    ++n_.holder_changes;
    v.holder_changed = true;
  }
  lease_until_us_ = mono_us + lease_us_;
  ++n_.applied;
  return v;
}

}  // namespace autodrive::bridge
