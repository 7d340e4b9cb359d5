#include <autodrive/rplidar/rplidar_decoder.hpp>

#include <algorithm>
#include <cmath>
#include <limits>

namespace autodrive::rplidar {

namespace {
// Largest angle step between consecutive nodes of a real scan [deg] (the A1 steps ~1 deg).
constexpr double kMaxStepDeg = 20.0;
// A turn's S node lies within this of the device's 0 deg [deg].
constexpr double kStartWindowDeg = 30.0;
// Fewest nodes in a real turn (the A1 sends ~360 or more); fewer = a faked S flag.
constexpr int kMinNodesPerTurn = 90;
}  // namespace

std::vector<uint8_t> request(uint8_t cmd) {
  return {kCmdSync, cmd};
}

bool Decoder::decode_node(const uint8_t *b, Node *out) {
  const bool s = b[0] & 0x01;
  const bool not_s = b[0] & 0x02;
  if (s == not_s) return false;
  if (!(b[1] & 0x01)) return false;
  const unsigned angle_q6 = (static_cast<unsigned>(b[1]) >> 1) | (static_cast<unsigned>(b[2]) << 7);
  if (angle_q6 >= 360u * 64u) return false;
  out->start = s;
  out->quality = static_cast<uint8_t>(b[0] >> 2);
  out->angle_deg = angle_q6 / 64.0;
  out->distance_mm = (static_cast<unsigned>(b[3]) | (static_cast<unsigned>(b[4]) << 8)) / 4.0;
  return true;
}

void encode_node(const Node &n, uint8_t out[5]) {
  const unsigned q = n.quality > 63 ? 63 : n.quality;
  out[0] = static_cast<uint8_t>((q << 2) | (n.start ? 0x01 : 0x02));
  const unsigned a = static_cast<unsigned>(std::lround(n.angle_deg * 64.0)) % (360u * 64u);
  out[1] = static_cast<uint8_t>(((a & 0x7F) << 1) | 0x01);
  out[2] = static_cast<uint8_t>(a >> 7);
  const unsigned d = static_cast<unsigned>(std::lround(n.distance_mm * 4.0)) & 0xFFFF;
  out[3] = static_cast<uint8_t>(d & 0xFF);
  out[4] = static_cast<uint8_t>(d >> 8);
}

void Decoder::reset() {
  mode_ = Mode::hunt;
  has_prev_ = false;
  resume_nodes_ = false;
  // Called from a callback inside process(): let process() drop the buffer when it returns.
  if (processing_)
    reset_requested_ = true;
  else
    buf_.clear();
}

void Decoder::feed(const uint8_t *data, std::size_t n) {
  buf_.insert(buf_.end(), data, data + n);
  process();
}

void Decoder::process() {
  std::size_t i = 0;  // consumed bytes
  processing_ = true;
  reset_requested_ = false;
  for (;;) {
    if (reset_requested_) break;
    const std::size_t avail = buf_.size() - i;
    const uint8_t *b = buf_.data() + i;
    if (mode_ == Mode::hunt) {
      if (avail < 2) break;
      if (b[0] != kAnsSync1 || b[1] != kAnsSync2) {
        ++i;
        ++stats_.skipped_bytes;
        continue;
      }
      if (avail < 7) break;
      const uint32_t word = static_cast<uint32_t>(b[2]) | (static_cast<uint32_t>(b[3]) << 8) |
                            (static_cast<uint32_t>(b[4]) << 16) |
                            (static_cast<uint32_t>(b[5]) << 24);
      const std::size_t len = word & 0x3FFFFFFFu;
      const unsigned send_mode = word >> 30;
      const uint8_t type = b[6];
      ++stats_.descriptors;
      i += 7;
      if (type == kAnsTypeMeasurement && len == 5 && send_mode == 1) {
        mode_ = Mode::nodes;
        has_prev_ = false;
        resume_nodes_ = false;
      } else if (send_mode == 0 && len <= 256) {
        // A single answer (health, info, ...): read its payload, then hunt again.
        if (type != kAnsTypeHealth && type != kAnsTypeDevInfo) ++stats_.bad_descriptors;
        mode_ = Mode::payload;
        payload_type_ = type;
        payload_len_ = len;
      } else {
        ++stats_.bad_descriptors;
        resume_nodes_ = false;
      }
      continue;
    }
    if (mode_ == Mode::payload) {
      if (avail < payload_len_) break;
      if (payload_type_ == kAnsTypeHealth && payload_len_ == 3 && on_health) {
        Health h;
        h.status = b[0];
        h.error_code = static_cast<uint16_t>(b[1] | (b[2] << 8));
        on_health(h);
      }
      i += payload_len_;
      // A single answer inside a scan stream (noise or forged) does not end the scan.
      mode_ = resume_nodes_ ? Mode::nodes : Mode::hunt;
      resume_nodes_ = false;
      continue;
    }
    // Mode::nodes. The standard node has no checksum, only 3 check bits, so a window that
    // starts mid-node passes them ~1 time in 5. A node is accepted only when the node after
    // it also passes and continues its angle (< kMaxStepDeg further on, clockwise), which a
    // misaligned window almost never does. Costs one node of latency.
    if (avail < 5) break;
    if (b[0] == kAnsSync1 && b[1] == kAnsSync2) {
      // A new descriptor inside the stream (the scan was restarted, or a single answer): parse
      // it; after a single answer's payload the node stream goes on.
      mode_ = Mode::hunt;
      resume_nodes_ = true;
      continue;
    }
    if (avail < 10) break;
    // Neighbouring nodes are a small step apart. The A1 turns clockwise and its angle grows
    // (the simulator's emulated A1 too); either direction is accepted, since a check on the
    // direction alone does not reject misaligned windows any better.
    auto follows = [](double from_deg, double to_deg) {
      const double d = std::fmod(to_deg - from_deg + 360.0, 360.0);
      return std::min(d, 360.0 - d) < kMaxStepDeg;
    };
    Node node, next;
    bool ok = decode_node(b, &node);
    if (ok) {
      // Continues the previous good node, or is continued by the next one (after a gap).
      const bool after_prev = has_prev_ && follows(prev_angle_deg_, node.angle_deg);
      const bool before_next = decode_node(b + 5, &next) && follows(node.angle_deg, next.angle_deg);
      ok = after_prev || before_next;
    }
    if (!ok) {
      ++stats_.bad_nodes;
      ++stats_.skipped_bytes;
      ++i;
      continue;
    }
    ++stats_.nodes;
    i += 5;
    has_prev_ = true;
    prev_angle_deg_ = node.angle_deg;
    if (on_node) on_node(node);
  }
  processing_ = false;
  if (reset_requested_) {
    buf_.clear();
    reset_requested_ = false;
    return;
  }
  buf_.erase(buf_.begin(), buf_.begin() + static_cast<std::ptrdiff_t>(i));
}

ScanAssembler::ScanAssembler(ScanParams p) : p_(std::move(p)) {
  clear(-1);
}

void ScanAssembler::clear(int64_t t_us) {
  ranges_.assign(360, std::numeric_limits<float>::infinity());
  intens_.assign(360, 0.0f);
  turn_start_us_ = t_us;
  nodes_in_turn_ = 0;
}

bool ScanAssembler::add(const Node &n, int64_t t_us, autodrive::lidar_scan_t *out) {
  bool emitted = false;
  // A new turn starts at a node with the S flag. The node format has no checksum, so a
  // corrupted byte can fake S mid-turn: S counts only near the device's 0 deg and after at
  // least kMinNodesPerTurn nodes. (If the real S node is lost, two turns merge into one scan:
  // still valid ranges, a longer scan_time_s.)
  const double from_zero_deg = std::min(n.angle_deg, 360.0 - n.angle_deg);
  const bool new_turn = n.start && from_zero_deg < kStartWindowDeg &&
                        (turn_start_us_ < 0 || nodes_in_turn_ >= kMinNodesPerTurn);
  if (new_turn) {
    // A full turn is behind us only if we saw its start; the first partial turn is dropped.
    if (turn_start_us_ >= 0 && nodes_in_turn_ > 0) {
      const double scan_time_s = (t_us - turn_start_us_) * 1e-6;
      out->utime = turn_start_us_;
      out->frame_id = p_.frame_id;
      out->angle_min_rad = 0.0f;
      out->angle_increment_rad = static_cast<float>(M_PI / 180.0);
      out->angle_max_rad = static_cast<float>(359.0 * M_PI / 180.0);
      out->scan_time_s = static_cast<float>(scan_time_s);
      out->time_increment_s = static_cast<float>(scan_time_s / 360.0);
      out->range_min_m = static_cast<float>(p_.range_min_m);
      out->range_max_m = static_cast<float>(p_.range_max_m);
      out->num_ranges = 360;
      out->ranges_m = ranges_;
      out->intensities = intens_;
      ++scans_;
      emitted = true;
    }
    clear(t_us);
  }
  ++nodes_in_turn_;
  // Distance 0 is the device's "no return". Quality is only reported (some units and the
  // simulator's emulation send 0 on good returns).
  if (n.distance_mm <= 0.0) return emitted;
  const double r_m = n.distance_mm / 1000.0;
  if (r_m < p_.range_min_m || r_m > p_.range_max_m) return emitted;
  // The device measures clockwise; REP-103 angles are counter-clockwise.
  double ccw_deg = p_.mount_yaw_rad * 180.0 / M_PI - n.angle_deg;
  ccw_deg = std::fmod(ccw_deg, 360.0);
  if (ccw_deg < 0) ccw_deg += 360.0;
  const int bin = static_cast<int>(std::lround(ccw_deg)) % 360;
  if (r_m < ranges_[bin]) {
    ranges_[bin] = static_cast<float>(r_m);
    intens_[bin] = n.quality;
  }
  return emitted;
}

}  // namespace autodrive::rplidar
