// A program's time: one clock for its stamps and for its timeouts and staleness, chosen in
// its config (`clock: wall|sim`, or --clock). Wall mode is the system clock (the car); sim
// mode follows the simulator's SIM_CLOCK, so that a HIL run is correct at any real-time
// factor. SIM_CLOCK is believed only in sim mode and only when it moves forward by at most
// kMaxSimStepUs: a forged tick (0, backwards, far future) is refused, counted and logged at a
// limited rate. A frozen simulator still fails safe: when SIM_CLOCK has not moved for
// kFrozenAfterUs of monotonic time the clock is frozen() and fresh() says stale for everything
// (a wall-clock backstop that only ever makes a judgement safer). The bridge's serial link
// timing (heartbeat, reconnects, link timeout) stays on monotonic_us(): that link is real.
#pragma once

#include <atomic>
#include <cstdint>
#include <optional>
#include <string>

namespace lcm {
class LCM;
}
namespace autodrive {
class sim_clock_t;
}

namespace autodrive::config {
enum class ClockMode { wall, sim };  // a program's clock: `clock: wall|sim` in its config
}

namespace autodrive::clock {

int64_t wall_us();       // system clock [us since the epoch]
int64_t monotonic_us();  // monotonic clock [us]: the real serial link's timing, and backstops

// "wall" or "sim" as a ClockMode; nullopt for anything else (programs name the bad input).
std::optional<autodrive::config::ClockMode> clock_mode_named(const std::string &name);

class Clock {
 public:
  explicit Clock(autodrive::config::ClockMode mode) : mode_(mode) {}
  // In sim mode, subscribes to SIM_CLOCK on `lcm` (the caller keeps handling it).
  void attach(lcm::LCM &lcm);
  // Now [us]: for stamps and timeouts: wall time, or the last SIM_CLOCK (0 before the first).
  int64_t now_us() const;
  bool sim() const { return mode_ == autodrive::config::ClockMode::sim; }
  // Whether now_us() means anything yet: wall mode, or a SIM_CLOCK has been taken.
  bool ready() const { return !sim() || have_sim_.load(); }
  static constexpr int64_t kMaxSimStepUs = 10000000;  // largest forward step of SIM_CLOCK [us]
  // SIM_CLOCK standing still this long [us, monotonic] is a frozen simulator. The simulator
  // ticks every 10 ms of sim time, so a run paced at 0.01x real time still moves it every 1 s.
  static constexpr int64_t kFrozenAfterUs = 5000000;
  // Sim mode: no SIM_CLOCK yet, or none that moved it forward in the last kFrozenAfterUs
  // before mono_us [us, monotonic_us()]. Never in wall mode.
  bool frozen(int64_t mono_us) const;
  bool frozen() const { return frozen(monotonic_us()); }
  // Whether something that happened at since_us [us, this clock] is at most limit_us old now,
  // on a clock that is not frozen (at mono_us [us, monotonic_us()]). A time in the future
  // (a sender's clock slightly ahead) counts as age 0.
  bool fresh(int64_t since_us, int64_t limit_us, int64_t mono_us) const;
  bool fresh(int64_t since_us, int64_t limit_us) const {
    return fresh(since_us, limit_us, monotonic_us());
  }
  // Takes a SIM_CLOCK tick; false (and counted) if refused: not forward, or too far forward.
  // mono_us: when it came [us, monotonic_us()] (the frozen() backstop; tests pass their own).
  bool set_sim_us(int64_t t_us, int64_t mono_us);
  bool set_sim_us(int64_t t_us) { return set_sim_us(t_us, monotonic_us()); }
  uint64_t sim_ticks_refused() const { return refused_.load(); }
  void on_sim_clock(const autodrive::sim_clock_t *m);

 private:
  autodrive::config::ClockMode mode_;
  std::atomic<int64_t> sim_us_{0};
  std::atomic<bool> have_sim_{false};
  std::atomic<int64_t> moved_mono_us_{0};  // when SIM_CLOCK last moved forward [us, monotonic]
  std::atomic<uint64_t> refused_{0};
};

}  // namespace autodrive::clock
