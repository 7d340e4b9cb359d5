#include <autodrive_channels.h>
#include "common/clock.hpp"

#include <autodrive/sim_clock_t.hpp>
#include <lcm/lcm-cpp.hpp>

#include <chrono>

namespace clk {

int64_t wall_us() {
  using namespace std::chrono;
  return duration_cast<microseconds>(system_clock::now().time_since_epoch()).count();
}

int64_t monotonic_us() {
  using namespace std::chrono;
  return duration_cast<microseconds>(steady_clock::now().time_since_epoch()).count();
}

namespace {
void on_sim_clock(const lcm::ReceiveBuffer *, const std::string &, const autodrive::sim_clock_t *m,
                  Clock *clock) {
  clock->set_sim_us(m->utime);
}
}  // namespace

void Clock::attach(lcm::LCM &lcm) {
  if (mode_ != cfg::ClockMode::sim) return;
  lcm.subscribeFunction(AUTODRIVE_CH_SIM_CLOCK, &on_sim_clock, this);
}

int64_t Clock::now_us() const {
  return mode_ == cfg::ClockMode::sim ? sim_us_.load() : wall_us();
}

}  // namespace clk
