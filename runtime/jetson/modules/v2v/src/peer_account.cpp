#include <autodrive/v2v/peer_account.hpp>

#include <cstdio>

namespace autodrive::v2v {

void PeerAccount::accepted(const autodrive::v2v_state_t &s, uint64_t serial) {
  auto &r = records_[{s.vehicle, serial}];
  r.name = s.vehicle;
  r.serial = serial;
  ++r.accepted;
  auto it = newest_.find(s.vehicle);
  if (it == newest_.end() || s.utime >= it->second.first) newest_[s.vehicle] = {s.utime, serial};
}

PeerAccount::Key PeerAccount::key_of(const autodrive::v2v_state_t &s) const {
  const auto it = newest_.find(s.vehicle);
  return {s.vehicle, it == newest_.end() ? 0 : it->second.second};
}

void PeerAccount::step(int64_t t_us, const std::vector<autodrive::v2v_state_t> &fresh,
                       int holding) {
  if (last_t_us_ >= 0 && t_us > last_t_us_) {
    const double dt_s = (t_us - last_t_us_) * 1e-6;
    for (size_t k = 0; k < last_fresh_.size(); ++k) {
      auto &r = records_[last_fresh_[k]];
      r.name = last_fresh_[k].first;
      r.serial = last_fresh_[k].second;
      r.in_table_s += dt_s;
      if (static_cast<int>(k) == last_holding_) r.held_s += dt_s;
    }
  }
  last_t_us_ = t_us;
  last_fresh_.clear();
  for (const auto &s : fresh) last_fresh_.push_back(key_of(s));
  last_holding_ = holding;
}

std::vector<PeerRecord> PeerAccount::records() const {
  std::vector<PeerRecord> out;
  for (const auto &kv : records_) out.push_back(kv.second);
  return out;
}

namespace {

// A JSON string of name (a certificate's name, which the wire could fill with anything).
std::string json_string(const std::string &name) {
  std::string out = "\"";
  for (const char c : name) {
    if (c == '"' || c == '\\') {
      out += '\\';
      out += c;
    } else if (static_cast<unsigned char>(c) < 0x20) {
      char esc[8];
      std::snprintf(esc, sizeof esc, "\\u%04x",
                    static_cast<unsigned>(static_cast<unsigned char>(c)));
      out += esc;
    } else {
      out += c;
    }
  }
  return out + "\"";
}

}  // namespace

std::string PeerAccount::json() const {
  std::string out = "[";
  for (const auto &r : records()) {
    char buf[192];
    std::snprintf(buf, sizeof buf,
                  ",\"serial\":\"%llu\",\"accepted\":%llu,\"in_table_s\":%.3f,\"held_s\":%.3f}",
                  static_cast<unsigned long long>(r.serial),
                  static_cast<unsigned long long>(r.accepted), r.in_table_s, r.held_s);
    out += (out.size() > 1 ? ",{\"name\":" : "{\"name\":") + json_string(r.name) + buf;
  }
  return out + "]";
}

}  // namespace autodrive::v2v
