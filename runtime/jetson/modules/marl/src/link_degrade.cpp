#include <autodrive/marl/link_degrade.hpp>

#include <stdexcept>
#include <string>

namespace autodrive::marl {

LinkDegrader::LinkDegrader(double loss, int64_t delay_us, uint64_t seed)
    : loss_(loss), delay_us_(delay_us), rng_(seed) {
  if (!(loss >= 0.0 && loss <= 1.0))
    throw std::invalid_argument("--v2v-loss " + std::to_string(loss) + ": must be in [0, 1]");
  if (delay_us < 0)
    throw std::invalid_argument("--v2v-delay-ms " + std::to_string(delay_us / 1000) +
                                ": must be >= 0");
}

void LinkDegrader::on_receive(const autodrive::v2v_state_t &s, int64_t now_us) {
  ++received_;
  if (loss_ > 0.0 && uniform_(rng_) < loss_) {
    ++lost_;
    return;
  }
  queue_.emplace_back(now_us + delay_us_, s);
}

std::vector<autodrive::v2v_state_t> LinkDegrader::due(int64_t now_us) {
  std::vector<autodrive::v2v_state_t> out;
  while (!queue_.empty() && queue_.front().first <= now_us) {
    out.push_back(queue_.front().second);
    queue_.pop_front();
  }
  return out;
}

}  // namespace autodrive::marl
