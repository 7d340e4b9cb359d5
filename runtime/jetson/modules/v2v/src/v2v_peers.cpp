#include <autodrive/v2v/v2v_peers.hpp>

#include <utility>

namespace autodrive::v2v {

PeerTable::PeerTable(std::string self, int64_t stale_us)
    : self_(std::move(self)), stale_us_(stale_us) {}

void PeerTable::on_state(const autodrive::v2v_state_t &s, int64_t now_us) {
  (void)now_us;  // age is judged from the sender's stamp, on the shared (sim or wall) clock
  if (s.vehicle == self_ || s.vehicle.empty()) return;
  auto it = latest_.find(s.vehicle);
  if (it != latest_.end() && s.utime < it->second.utime) return;  // reordered: keep the newer
  latest_[s.vehicle] = s;
  ++received_;
}

std::vector<autodrive::v2v_state_t> PeerTable::fresh(int64_t now_us) {
  std::vector<autodrive::v2v_state_t> out;
  for (auto it = latest_.begin(); it != latest_.end();) {
    if (now_us - it->second.utime > stale_us_) {
      ++dropped_stale_;
      it = latest_.erase(it);
    } else {
      out.push_back(it->second);
      ++it;
    }
  }
  return out;
}

std::vector<autodrive::v2v_state_t> PeerTable::fresh(const autodrive::clock::Clock &clock) {
  if (clock.ready() && !clock.frozen()) return fresh(clock.now_us());
  dropped_stale_ += latest_.size();
  latest_.clear();
  return {};
}

std::string status_line(const std::vector<autodrive::v2v_state_t> &fresh, uint64_t dropped) {
  std::string names;
  for (const auto &s : fresh) names += (names.empty() ? "" : ", ") + s.vehicle;
  return std::to_string(fresh.size()) + " fresh peer(s)" +
         (names.empty() ? "" : " (" + names + ")") + ", " + std::to_string(dropped) +
         " stale state(s) dropped";
}

}  // namespace autodrive::v2v
