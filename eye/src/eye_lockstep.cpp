#include "eye_lockstep.hpp"

#include <autodrive_channels.h>
#include <autodrive_lcm/subscribe.hpp>
#include <time.h>

#include <autodrive/eye_frame_done_t.hpp>
#include <chrono>
#include <cmath>
#include <cstdio>

#include "eye_error.hpp"
#include "eye_source.hpp"

namespace eye {

SimLockstep::SimLockstep(const std::string &lcm_url, double latency_ms)
    : lcm_(lcm_url_for_images(lcm_url)), latency_us_(std::llround(latency_ms * 1e3)) {
  if (!(latency_ms >= 0.0 && latency_ms <= 10000.0))
    throw Error("--sim-latency-ms " + std::to_string(latency_ms) + ": want 0..10000 ms");
  if (!lcm_.good()) throw Error("lcm: cannot open " + lcm_url + " (for SIM_CLOCK)");
  autodrive_lcm::subscribe<autodrive::sim_clock_t, SimLockstep, &SimLockstep::on_clock>(
      lcm_, AUTODRIVE_CH_SIM_CLOCK, this);
  thread_ = std::thread([this] { drain(); });
}

SimLockstep::~SimLockstep() {
  {
    std::lock_guard<std::mutex> lock(mu_);
    quit_ = true;
  }
  thread_.join();
}

void SimLockstep::drain() {
  auto next_ready = std::chrono::steady_clock::now();
  for (;;) {
    {
      std::lock_guard<std::mutex> lock(mu_);
      if (quit_) return;
      if (!started_ && std::chrono::steady_clock::now() >= next_ready) {
        done(lcm_, -1, 0);  // ready, no frame yet
        next_ready += std::chrono::duration_cast<std::chrono::steady_clock::duration>(
            std::chrono::duration<double>(kReadyPeriodS));
      }
    }
    lcm_.handleTimeout(50);
  }
}

void SimLockstep::on_clock(const autodrive::sim_clock_t *m) {
  std::lock_guard<std::mutex> lock(mu_);
  if (m->utime <= clock_us_) return;
  clock_us_ = m->utime;
  cv_.notify_all();
}

void SimLockstep::hold(int64_t capture_utime, const volatile std::sig_atomic_t *stop) {
  const int64_t release_us = capture_utime + latency_us_;
  std::unique_lock<std::mutex> lock(mu_);
  started_ = true;
  if (!holding_) return;
  auto give_up = std::chrono::steady_clock::now() + std::chrono::duration<double>(kGiveUpS);
  int64_t seen = clock_us_;
  while (clock_us_ < release_us && !*stop) {
    cv_.wait_for(lock, std::chrono::milliseconds(50));
    if (clock_us_ != seen) {  // the sim moves: it is slow, not gone
      seen = clock_us_;
      give_up = std::chrono::steady_clock::now() + std::chrono::duration<double>(kGiveUpS);
    } else if (std::chrono::steady_clock::now() > give_up) {
      ++given_up_;
      if (clock_us_ < 0) {
        holding_ = false;
        std::fprintf(stderr,
                     "autodrive-eye: WARNING: --sim-latency-ms: no " AUTODRIVE_CH_SIM_CLOCK
                     " for %.0f s (wall): the simulator is not in a lockstep mode; poses go "
                     "out as soon as they are made\n",
                     kGiveUpS);
      } else {
        std::fprintf(stderr,
                     "autodrive-eye: WARNING: " AUTODRIVE_CH_SIM_CLOCK
                     " stuck at %.3f s for %.0f s (wall): the poses of the frame of %.3f s go "
                     "out now\n",
                     clock_us_ * 1e-6, kGiveUpS, capture_utime * 1e-6);
      }
      return;
    }
  }
}

void SimLockstep::done(lcm::LCM &lcm, int64_t capture_utime, int poses) const {
  autodrive::eye_frame_done_t m;
  m.utime = capture_utime;
  m.latency_us = latency_us_;
  m.poses = static_cast<int16_t>(poses);
  lcm.publish(AUTODRIVE_CH_EYE_FRAME_DONE, &m);
}

void burn_cpu_ms(double ms) {
  const auto cpu_s = [] {
    timespec ts{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
  };
  const double until = cpu_s() + 1e-3 * ms;
  volatile double x = 0.0;
  while (cpu_s() < until)
    for (int i = 0; i < 1000; ++i) x = x + std::sqrt(static_cast<double>(i));
}

}  // namespace eye
