// RPLIDAR A1 serial protocol decoder (no I/O). Host -> device requests are `A5 <cmd>`; every
// answer starts with a 7-byte response descriptor:
//   A5 5A | u32 LE: bits 0-29 data length [bytes], bits 30-31 send mode (0 single, 1 multiple)
//   | u8 data type (0x06 health, 0x04 device info, 0x81 scan measurement)
// GET_HEALTH (0x52) answers 3 bytes: u8 status (0 good, 1 warning, 2 error), u16 LE error code.
// SCAN (0x20) answers descriptor A5 5A 05 00 00 40 81, then 5-byte measurement nodes forever:
//   byte 0: bit 0 S (first node of a new turn), bit 1 !S (inverse of S), bits 2-7 quality
//   byte 1: bit 0 C (check bit, always 1), bits 1-7 angle_q6 bits 0-6
//   byte 2: angle_q6 bits 7-14            angle = angle_q6 / 64 [deg], clockwise seen from above
//   byte 3-4: u16 LE distance_q2          distance = distance_q2 / 4 [mm], 0 = no return
// A node whose S/!S or C bits are wrong (or angle >= 360 deg), or whose angle does not continue
// its neighbours', is corruption: the decoder drops one byte and tries again (resync), counting
// what it skipped. A node is delivered once the next 5 bytes are in (one node of latency).
#pragma once

#include <autodrive/lidar_scan_t.hpp>

#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace autodrive::rplidar {

enum : uint8_t {
  kCmdSync = 0xA5,
  kCmdStop = 0x25,
  kCmdReset = 0x40,
  kCmdScan = 0x20,
  kCmdGetInfo = 0x50,
  kCmdGetHealth = 0x52,
  kAnsSync1 = 0xA5,
  kAnsSync2 = 0x5A,
  kAnsTypeDevInfo = 0x04,
  kAnsTypeHealth = 0x06,
  kAnsTypeMeasurement = 0x81,
};

// The 2-byte request for a payload-less command.
std::vector<uint8_t> request(uint8_t cmd);

struct Node {
  bool start = false;        // first node of a new 360 deg turn
  uint8_t quality = 0;       // [0, 63], 0 = no valid return
  double angle_deg = 0.0;    // clockwise from the sensor's 0 [deg]
  double distance_mm = 0.0;  // 0 = no return [mm]
};

struct Health {
  uint8_t status = 0;  // 0 good, 1 warning, 2 error
  uint16_t error_code = 0;
};

struct DecoderStats {
  uint64_t nodes = 0;            // good measurement nodes
  uint64_t bad_nodes = 0;        // 5-byte windows failing the S/!S, C or angle checks
  uint64_t skipped_bytes = 0;    // bytes dropped while resyncing or hunting for a descriptor
  uint64_t descriptors = 0;      // response descriptors parsed
  uint64_t bad_descriptors = 0;  // descriptors with an unexpected length/type
};

// Byte-wise decoder of everything the device sends. Call feed() with any chunking.
class Decoder {
 public:
  std::function<void(const Node &)> on_node;
  std::function<void(const Health &)> on_health;

  void feed(const uint8_t *data, std::size_t n);
  // Back to hunting for a descriptor, dropping buffered bytes (after sending a new request).
  // Safe to call from on_node / on_health.
  void reset();
  const DecoderStats &stats() const { return stats_; }
  bool scanning() const { return mode_ == Mode::nodes; }

  // Decodes one 5-byte node; false if its check bits or angle are invalid.
  static bool decode_node(const uint8_t *b, Node *out);

 private:
  enum class Mode { hunt, payload, nodes };
  void process();
  Mode mode_ = Mode::hunt;
  uint8_t payload_type_ = 0;
  std::size_t payload_len_ = 0;
  std::vector<uint8_t> buf_;
  DecoderStats stats_;
  bool processing_ = false;  // inside process(): callbacks may call reset()
  bool reset_requested_ = false;
  bool has_prev_ = false;        // a good node was accepted in this scan stream
  bool resume_nodes_ = false;    // a descriptor interrupted the node stream: resume after it
  double prev_angle_deg_ = 0.0;  // its angle
};

// Encodes a node (for tests and synthetic streams).
void encode_node(const Node &n, uint8_t out[5]);

// Collects nodes into 360 one-degree bins and emits a lidar_scan_t at the end of each turn.
struct ScanParams {
  std::string frame_id = "laser";
  double mount_yaw_rad = 0.0;  // sensor 0 deg direction in base_link, CCW [rad]
  double range_min_m = 0.15;
  double range_max_m = 12.0;
};

class ScanAssembler {
 public:
  explicit ScanAssembler(ScanParams p);
  // `t_us`: receive time of the node. Returns true when a complete scan was written to `out`.
  bool add(const Node &n, int64_t t_us, autodrive::lidar_scan_t *out);
  uint64_t scans() const { return scans_; }

 private:
  void clear(int64_t t_us);
  ScanParams p_;
  std::vector<float> ranges_, intens_;
  int64_t turn_start_us_ = -1;
  int nodes_in_turn_ = 0;
  uint64_t scans_ = 0;
};

}  // namespace autodrive::rplidar
