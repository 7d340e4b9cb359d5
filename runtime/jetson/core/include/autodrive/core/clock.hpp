// Time sources. Wall mode stamps messages with the system clock; sim mode follows the
// simulator's SIM_CLOCK (lockstep) so that runs are repeatable and faster than real time.
// Rates, timeouts and the serial heartbeat always run on the monotonic clock: the serial
// link is real whatever the clock source. SIM_CLOCK is believed only in sim mode and only
// when it moves forward by at most kMaxSimStepUs: a forged tick (0, backwards, far future)
// is refused, counted and logged at a limited rate.
#pragma once

#include <atomic>
#include <cstdint>
#include <string>

#include <autodrive/core/config.hpp>

namespace lcm {
class LCM;
}
namespace autodrive {
class sim_clock_t;
}

namespace autodrive::clock {

int64_t wall_us();       // system clock [us since the epoch]
int64_t monotonic_us();  // monotonic clock [us], for rates and timeouts

class Clock {
 public:
  explicit Clock(autodrive::config::ClockMode mode) : mode_(mode) {}
  // In sim mode, subscribes to SIM_CLOCK on `lcm` (the caller keeps handling it).
  void attach(lcm::LCM &lcm);
  // Stamp for outgoing messages [us]: wall time, or the last SIM_CLOCK (0 before the first).
  int64_t now_us() const;
  bool sim() const { return mode_ == autodrive::config::ClockMode::sim; }
  static constexpr int64_t kMaxSimStepUs = 10000000;  // largest forward step of SIM_CLOCK [us]
  // Takes a SIM_CLOCK tick; false (and counted) if refused: not forward, or too far forward.
  bool set_sim_us(int64_t t_us);
  uint64_t sim_ticks_refused() const { return refused_.load(); }
  void on_sim_clock(const autodrive::sim_clock_t *m);

 private:
  autodrive::config::ClockMode mode_;
  std::atomic<int64_t> sim_us_{0};
  std::atomic<bool> have_sim_{false};
  std::atomic<uint64_t> refused_{0};
};

}  // namespace autodrive::clock
