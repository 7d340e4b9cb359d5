// V2V peer table: the latest v2v_state_t of every other car, as heard on the V2V channel.
// A state older than the stale limit [us] is dropped (and counted) when the fresh peers are
// asked for, so a car that went silent, or a link that lost it, is never believed for long.
// The time base is the receiver's clock (autodrive::clock::Clock): sim time (SIM_CLOCK) in
// HIL, else wall time; on a frozen sim clock every peer is stale.
#pragma once

#include <autodrive/core/clock.hpp>

#include <autodrive/v2v_state_t.hpp>

#include <cstdint>
#include <map>
#include <string>
#include <vector>

namespace autodrive::v2v {

class PeerTable {
 public:
  // self: this car's name (its own broadcast is ignored); stale_us: age limit [us].
  explicit PeerTable(std::string self, int64_t stale_us = 200000);

  // Keeps s as its sender's latest state (a state older than the one kept is ignored: UDP may
  // reorder). now_us is the receive time on the receiver's clock [us].
  void on_state(const autodrive::v2v_state_t &s, int64_t now_us);
  // Every peer whose latest state is at most stale_us old at now_us [us], in name order; the
  // others are removed and counted in dropped_stale().
  std::vector<autodrive::v2v_state_t> fresh(int64_t now_us);
  // The same at the clock's now; none (every peer dropped) while the clock is not ready or frozen.
  std::vector<autodrive::v2v_state_t> fresh(const autodrive::clock::Clock &clock);
  uint64_t dropped_stale() const { return dropped_stale_; }
  // States received from peers (own broadcasts and reordered ones not counted) [count].
  uint64_t received() const { return received_; }
  const std::string &self() const { return self_; }
  int64_t stale_us() const { return stale_us_; }

 private:
  std::string self_;
  int64_t stale_us_;
  std::map<std::string, autodrive::v2v_state_t> latest_;
  uint64_t dropped_stale_ = 0, received_ = 0;
};

// One line for a status log: "2 fresh peers (NIGEL2, NIGEL3), 4 stale states dropped".
std::string status_line(const std::vector<autodrive::v2v_state_t> &fresh, uint64_t dropped);

}  // namespace autodrive::v2v
