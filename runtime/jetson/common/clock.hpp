// Time sources. Wall mode stamps messages with the system clock; sim mode follows the
// simulator's SIM_CLOCK (lockstep) so that runs are repeatable and faster than real time.
// Rates, timeouts and the serial heartbeat always run on the monotonic clock: the serial
// link is real whatever the clock source.
#pragma once

#include <atomic>
#include <cstdint>
#include <string>

#include "common/config.hpp"

namespace lcm {
class LCM;
}

namespace clk {

int64_t wall_us();       // system clock [us since the epoch]
int64_t monotonic_us();  // monotonic clock [us], for rates and timeouts

class Clock {
 public:
  explicit Clock(cfg::ClockMode mode) : mode_(mode) {}
  // In sim mode, subscribes to SIM_CLOCK on `lcm` (the caller keeps handling it).
  void attach(lcm::LCM &lcm);
  // Stamp for outgoing messages [us]: wall time, or the last SIM_CLOCK (0 before the first).
  int64_t now_us() const;
  bool sim() const { return mode_ == cfg::ClockMode::sim; }
  void set_sim_us(int64_t t_us) { sim_us_.store(t_us); }

 private:
  cfg::ClockMode mode_;
  std::atomic<int64_t> sim_us_{0};
};

}  // namespace clk
