// INTERIM: see interim/autodrive/v2v_peers.hpp (replaced by the city branch's autodrive_v2v).
#include <autodrive/v2v_peers.hpp>

namespace autodrive::v2v {

PeerTable::PeerTable(std::string self, int64_t stale_us)
    : self_(std::move(self)), stale_us_(stale_us) {}

void PeerTable::on_state(const autodrive::v2v_state_t &s, int64_t now_us) {
  (void)now_us;
  if (s.vehicle == self_) return;
  auto it = latest_.find(s.vehicle);
  if (it != latest_.end() && it->second.utime >= s.utime) return;  // out of order: keep newer
  latest_[s.vehicle] = s;
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

}  // namespace autodrive::v2v
