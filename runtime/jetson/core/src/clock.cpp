#include <autodrive_channels.h>
#include <autodrive/core/clock.hpp>

#include <autodrive/sim_clock_t.hpp>
#include <autodrive_lcm/subscribe.hpp>
#include <lcm/lcm-cpp.hpp>

#include <autodrive/log_limiter.hpp>

#include <chrono>

namespace autodrive::clock {

int64_t wall_us() {
  using namespace std::chrono;
  return duration_cast<microseconds>(system_clock::now().time_since_epoch()).count();
}

int64_t monotonic_us() {
  using namespace std::chrono;
  return duration_cast<microseconds>(steady_clock::now().time_since_epoch()).count();
}

namespace {
autodrive::LogLimiter &refused_log() {
  static autodrive::LogLimiter log("refused SIM_CLOCK ticks");
  return log;
}
}  // namespace

void Clock::on_sim_clock(const autodrive::sim_clock_t *m) {
  const int64_t before = sim_us_.load();
  if (!set_sim_us(m->utime))
    refused_log().event(AUTODRIVE_CH_SIM_CLOCK,
                        fmt::format("tick {} us refused (clock at {} us; ticks must move "
                                    "forward by at most {} us)",
                                    m->utime, before, kMaxSimStepUs));
}

bool Clock::set_sim_us(int64_t t_us, int64_t mono_us) {
  const int64_t now = sim_us_.load();
  const bool first = !have_sim_.load();
  if (t_us < 0 || (!first && (t_us < now || t_us - now > kMaxSimStepUs))) {
    ++refused_;
    return false;
  }
  // A tick that repeats the time is believed but is no sign of life: a paused simulator that
  // keeps sending its time still freezes the clock.
  if (first || t_us > now) moved_mono_us_.store(mono_us);
  sim_us_.store(t_us);
  have_sim_.store(true);
  return true;
}

bool Clock::frozen(int64_t mono_us) const {
  if (!sim()) return false;
  return !have_sim_.load() || mono_us - moved_mono_us_.load() > kFrozenAfterUs;
}

bool Clock::fresh(int64_t since_us, int64_t limit_us, int64_t mono_us) const {
  if (!ready() || frozen(mono_us)) return false;
  return now_us() - since_us <= limit_us;
}

std::optional<autodrive::config::ClockMode> clock_mode_named(const std::string &name) {
  if (name == "wall") return autodrive::config::ClockMode::wall;
  if (name == "sim") return autodrive::config::ClockMode::sim;
  return std::nullopt;
}

void Clock::attach(lcm::LCM &lcm) {
  if (mode_ != autodrive::config::ClockMode::sim) return;
  autodrive_lcm::subscribe<autodrive::sim_clock_t, Clock, &Clock::on_sim_clock>(
      lcm, AUTODRIVE_CH_SIM_CLOCK, this);
}

int64_t Clock::now_us() const {
  return mode_ == autodrive::config::ClockMode::sim ? sim_us_.load() : wall_us();
}

}  // namespace autodrive::clock
