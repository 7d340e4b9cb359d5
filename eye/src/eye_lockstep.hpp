// `autodrive-eye run --sim-latency-ms L`: the Eye in lockstep with the simulator
// (docs/design/clocks.md). Its latency is part of the twin: a frame captured at sim time t has
// its poses published when SIM_CLOCK reaches t + L (still stamped t, the capture time: the
// EKF's history places a late measurement where it belongs), then EYE_FRAME_DONE, on which
// `autodrive-sim --eye-sync` (stopped at t + L) runs on. So poses reach the bus at t + L of
// sim time however long the Eye takes in wall time.
#pragma once
#include <lcm/lcm-cpp.hpp>

#include <autodrive/sim_clock_t.hpp>
#include <condition_variable>
#include <csignal>
#include <cstdint>
#include <mutex>
#include <string>
#include <thread>

namespace eye {

class SimLockstep {
 public:
  // [s] of wall time without SIM_CLOCK reaching a frame's release: the sim is gone or paused,
  // the frame's poses go out anyway (autodrive-sim's client give-up rule, CLIENT_SYNC_LOST_S)
  static constexpr double kGiveUpS = 2.0;
  static constexpr double kReadyPeriodS = 0.2;  // [s] wall between "ready" announcements

  // Reads SIM_CLOCK on its own LCM instance (a thread drains it, so a clock message is never
  // lost behind image traffic) and, until the first hold(), says every kReadyPeriodS that the
  // Eye is ready (EYE_FRAME_DONE with utime -1: autodrive-sim --eye-sync waits for it before
  // its first frame). Make it once the frame sources are subscribed. latency_ms: the Eye's
  // processing time in sim time (the capture-to-pose figure of tools/bench eye, or a given
  // one), 0..10000. Throws eye::Error.
  SimLockstep(const std::string &lcm_url, double latency_ms);
  ~SimLockstep();
  SimLockstep(const SimLockstep &) = delete;
  SimLockstep &operator=(const SimLockstep &) = delete;

  // Waits until SIM_CLOCK reaches capture_utime + latency, *stop is set, or kGiveUpS pass
  // without it (counted; with no SIM_CLOCK ever seen, holding stops with a warning: the sim is
  // not in a lockstep mode).
  void hold(int64_t capture_utime, const volatile std::sig_atomic_t *stop);
  // EYE_FRAME_DONE on lcm for the frame captured at capture_utime (poses published for it).
  void done(lcm::LCM &lcm, int64_t capture_utime, int poses) const;

  int64_t latency_us() const { return latency_us_; }
  long given_up() const { return given_up_; }

 private:
  void on_clock(const autodrive::sim_clock_t *m);
  void drain();

  lcm::LCM lcm_;
  int64_t latency_us_;
  std::mutex mu_;
  std::condition_variable cv_;
  int64_t clock_us_ = -1;                                 // the newest SIM_CLOCK [us]; -1: none yet
  bool quit_ = false, holding_ = true, started_ = false;  // started_: a frame came
  long given_up_ = 0;
  std::thread thread_;
};

// `--cpu-delay-ms` (a test double: a slower Eye): spends ms of this thread's CPU time.
void burn_cpu_ms(double ms);

}  // namespace eye
