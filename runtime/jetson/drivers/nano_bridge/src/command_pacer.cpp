#include <autodrive/nano_bridge/command_pacer.hpp>

#include <algorithm>
#include <cmath>

namespace autodrive::bridge {

CommandPacer::CommandPacer(int burst_frames, double rate_hz, int64_t heartbeat_period_us)
    : token_us_(std::max<int64_t>(1, std::llround(1e6 / rate_hz))),
      capacity_us_(std::max(1, burst_frames) * token_us_),
      heartbeat_us_(heartbeat_period_us) {}

void CommandPacer::restart(int64_t now_us) {
  credit_us_ = capacity_us_;
  refilled_at_us_ = now_us;
  last_frame_us_ = now_us - heartbeat_us_;
  held_ = false;
}

void CommandPacer::refill(int64_t now_us) {
  // Integer credit [us]: no rounding drift, so the cap holds exactly over any run length.
  if (now_us > refilled_at_us_)
    credit_us_ = std::min(capacity_us_, credit_us_ + (now_us - refilled_at_us_));
  refilled_at_us_ = std::max(refilled_at_us_, now_us);
}

bool CommandPacer::take(int64_t now_us) {
  refill(now_us);
  if (credit_us_ < token_us_) return false;
  credit_us_ -= token_us_;
  last_frame_us_ = now_us;
  held_ = false;
  return true;
}

bool CommandPacer::command(int64_t now_us) {
  if (take(now_us)) return true;
  held_ = true;
  return false;
}

bool CommandPacer::due(int64_t now_us) {
  if (held_ || now_us - last_frame_us_ >= heartbeat_us_) return take(now_us);
  return false;
}

int64_t CommandPacer::next_due_us() const {
  const int64_t token_at = refilled_at_us_ + std::max<int64_t>(0, token_us_ - credit_us_);
  const int64_t heartbeat_at = std::max(last_frame_us_ + heartbeat_us_, token_at);
  return held_ ? token_at : heartbeat_at;
}

}  // namespace autodrive::bridge
