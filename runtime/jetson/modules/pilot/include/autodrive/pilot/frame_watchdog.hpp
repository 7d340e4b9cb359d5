// The pilot's frame timeout on its clock (`clock: wall|sim`, autodrive::clock::Clock): no
// front-camera frame for timeout_ms of clock time stops the car. On a sim clock that is sim
// time, so a HIL run paced at 0.1x real time times out as one at full speed; a frozen sim clock
// (no SIM_CLOCK tick for Clock::kFrozenAfterUs of monotonic time) counts as silent too.
#pragma once

#include <autodrive/core/clock.hpp>

#include <cstdint>

namespace autodrive::pilot {

class FrameWatchdog {
 public:
  FrameWatchdog(const autodrive::clock::Clock &clock, int timeout_ms)
      : clock_(clock), timeout_us_(static_cast<int64_t>(timeout_ms) * 1000) {}
  void frame() {
    last_us_ = clock_.now_us();
    seen_ = true;
  }
  bool seen() const { return seen_; }
  // A frame was seen, and none for longer than the timeout (or the clock froze), at mono_us.
  bool silent(int64_t mono_us) const {
    return seen_ && !clock_.fresh(last_us_, timeout_us_, mono_us);
  }
  bool silent() const { return silent(autodrive::clock::monotonic_us()); }
  int64_t silent_ms() const { return (clock_.now_us() - last_us_) / 1000; }  // [ms, clock]

 private:
  const autodrive::clock::Clock &clock_;
  int64_t timeout_us_;
  int64_t last_us_ = 0;
  bool seen_ = false;
};

}  // namespace autodrive::pilot
