// Receive-side degradation of the V2V link for tests and demos: each received state is lost
// with probability loss, else delivered delay_us [us] after it arrived. Seeded, so a run
// repeats for the same arrival order.
#pragma once

#include <autodrive/v2v_state_t.hpp>

#include <cstdint>
#include <deque>
#include <random>
#include <vector>

namespace autodrive::marl {

class LinkDegrader {
 public:
  // Throws std::invalid_argument when loss is outside [0, 1] or delay_us < 0.
  LinkDegrader(double loss, int64_t delay_us, uint64_t seed);
  // A state received at now_us [us].
  void on_receive(const autodrive::v2v_state_t &s, int64_t now_us);
  // The states due at now_us, in arrival order.
  std::vector<autodrive::v2v_state_t> due(int64_t now_us);
  uint64_t lost() const { return lost_; }
  uint64_t received() const { return received_; }

 private:
  double loss_;
  int64_t delay_us_;
  std::mt19937_64 rng_;
  std::uniform_real_distribution<double> uniform_{0.0, 1.0};
  std::deque<std::pair<int64_t, autodrive::v2v_state_t>> queue_;  // (release time [us], state)
  uint64_t lost_ = 0, received_ = 0;
};

}  // namespace autodrive::marl
