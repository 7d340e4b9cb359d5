// INTERIM stand-in of the V2V peer table owned by the `city` branch (runtime/jetson/v2v/,
// library autodrive_v2v, owned by the city branch), to its interface, so that
// autodrive-marl builds and is tested before that branch is merged. Deleted on the merge
// (then autodrive-marl links autodrive_v2v): see runtime/jetson/marl/README.md.
#pragma once

#include <autodrive/v2v_state_t.hpp>

#include <cstdint>
#include <map>
#include <string>
#include <vector>

namespace autodrive::v2v {

// The latest state of every other car; a state older than stale_us [us] is dropped (counted).
class PeerTable {
 public:
  explicit PeerTable(std::string self, int64_t stale_us = 200000);
  void on_state(const autodrive::v2v_state_t &s, int64_t now_us);  // ignores self
  std::vector<autodrive::v2v_state_t> fresh(int64_t now_us);
  uint64_t dropped_stale() const { return dropped_stale_; }

 private:
  std::string self_;
  int64_t stale_us_;
  std::map<std::string, autodrive::v2v_state_t> latest_;
  uint64_t dropped_stale_ = 0;
};

}  // namespace autodrive::v2v
