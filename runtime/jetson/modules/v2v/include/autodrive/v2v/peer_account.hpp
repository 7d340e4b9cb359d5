// Per-peer account of one receiver, to measure what each V2V peer made the car do: for every
// peer it ever accepted, keyed by the peer's name and the serial of the certificate that signed
// its state (so a forger under a real car's name, with another certificate, is a peer of its
// own), the messages accepted, the time [s of the receiver's clock] the peer was in the fresh
// peer table, and the time it was the reason the car held or slowed (its gap limit was the
// binding one). tools/bench v2x reads it to charge held time to ghost cars, and to nothing else.
#pragma once

#include <autodrive/v2v_state_t.hpp>

#include <cstdint>
#include <map>
#include <string>
#include <utility>
#include <vector>

namespace autodrive::v2v {

struct PeerRecord {
  std::string name;
  uint64_t serial = 0;    // the signing certificate's serial
  uint64_t accepted = 0;  // states accepted [count]
  double in_table_s = 0;  // [s] in the fresh peer table
  double held_s = 0;      // [s] the reason the car held or slowed
};

class PeerAccount {
 public:
  // A state the verifier accepted from the certificate `serial`: the peer table keeps the
  // newest state per name, so the serial of the newest one (by sender stamp utime) is kept.
  void accepted(const autodrive::v2v_state_t &s, uint64_t serial);
  // One control step at t_us [us, the receiver's clock]: the fresh peers it used, and the
  // index among them of the one whose gap limited the speed (-1: none). The time since the
  // previous step is charged to the previous step's peers (its decision held until now).
  void step(int64_t t_us, const std::vector<autodrive::v2v_state_t> &fresh, int holding);
  // Every peer ever accepted, by name then serial.
  std::vector<PeerRecord> records() const;
  // One JSON array of the records (serials as decimal strings: 64 bits): the driver's report.
  std::string json() const;

 private:
  using Key = std::pair<std::string, uint64_t>;
  Key key_of(const autodrive::v2v_state_t &s) const;
  std::map<Key, PeerRecord> records_;
  std::map<std::string, std::pair<int64_t, uint64_t>> newest_;  // name -> (utime [us], serial)
  std::vector<Key> last_fresh_;
  int last_holding_ = -1;
  int64_t last_t_us_ = -1;
};

}  // namespace autodrive::v2v
