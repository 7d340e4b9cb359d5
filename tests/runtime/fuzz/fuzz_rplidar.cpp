// libFuzzer target: the RPLIDAR A1 decoder and scan assembler (runtime/jetson/drivers/rplidar), fed
// what a noisy or hostile serial line can carry. The input is a script:
//   op 0: n raw bytes, fed in one chunk                        [0, n, bytes...]
//   op 1: a valid scan descriptor (A5 5A 05 00 00 40 81)        [1]
//   op 2: a health answer: status, error code                    [2, status, lo, hi]
//   op 3: a well-formed node (check bits right): S, quality, angle_q6, distance_q2 [3, 7 bytes]
//   op 4: decoder reset (the driver sends a new request)        [4]
// Safety invariants (abort on violation): every delivered node has an angle in [0, 360) deg,
// a finite distance >= 0 and a quality <= 63; a published scan has 360 ranges, each inf or within
// [range_min_m, range_max_m], finite times >= 0; the counters never run backwards.
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <vector>

#include <autodrive/rplidar/rplidar_decoder.hpp>

namespace {

#define CHECK(cond) \
  do {              \
    if (!(cond)) {  \
      std::abort(); \
    }               \
  } while (0)

int64_t t_us = 0;

struct Run {
  autodrive::rplidar::Decoder dec;
  autodrive::rplidar::ScanAssembler asm_{autodrive::rplidar::ScanParams{"laser", 0.3, 0.15, 12.0}};
  uint64_t scans = 0, healths = 0;
  Run() {
    dec.on_node = [this](const autodrive::rplidar::Node &n) {
      CHECK(std::isfinite(n.angle_deg) && n.angle_deg >= 0.0 && n.angle_deg < 360.0);
      CHECK(std::isfinite(n.distance_mm) && n.distance_mm >= 0.0);
      CHECK(n.quality <= 63);
      autodrive::lidar_scan_t s;
      t_us += 250;
      if (asm_.add(n, t_us, &s)) check_scan(s);
    };
    dec.on_health = [this](const autodrive::rplidar::Health &) { ++healths; };
  }
  void check_scan(const autodrive::lidar_scan_t &s) {
    ++scans;
    CHECK(s.num_ranges == 360);
    CHECK(s.ranges_m.size() == 360 && s.intensities.size() == 360);
    for (int i = 0; i < 360; ++i) {
      const float r = s.ranges_m[static_cast<size_t>(i)];
      CHECK(std::isinf(r) || (r >= s.range_min_m && r <= s.range_max_m));
      CHECK(s.intensities[static_cast<size_t>(i)] >= 0.0f &&
            s.intensities[static_cast<size_t>(i)] <= 63.0f);
    }
    CHECK(std::isfinite(s.scan_time_s) && s.scan_time_s >= 0.0f);
    CHECK(std::isfinite(s.time_increment_s) && s.time_increment_s >= 0.0f);
  }
};

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  Run run;
  autodrive::rplidar::DecoderStats before{};
  size_t i = 0;
  while (i < size) {
    const uint8_t op = data[i++] % 5u;
    std::vector<uint8_t> bytes;
    if (op == 0) {
      if (i >= size) break;
      size_t n = data[i++];
      if (n > size - i) n = size - i;
      bytes.assign(data + i, data + i + n);
      i += n;
    } else if (op == 1) {
      bytes = {0xA5, 0x5A, 0x05, 0x00, 0x00, 0x40, 0x81};
    } else if (op == 2) {
      if (i + 3 > size) break;
      bytes = {0xA5, 0x5A, 0x03, 0x00, 0x00, 0x00, 0x06, data[i], data[i + 1], data[i + 2]};
      i += 3;
    } else if (op == 3) {
      if (i + 7 > size) break;
      autodrive::rplidar::Node n;
      n.start = data[i] & 1u;
      n.quality = static_cast<uint8_t>(data[i + 1] % 64u);
      const unsigned angle_q6 = (data[i + 2] | (data[i + 3] << 8)) % (360u * 64u);
      n.angle_deg = angle_q6 / 64.0;
      n.distance_mm = (data[i + 4] | (data[i + 5] << 8)) / 4.0;
      uint8_t out[5];
      autodrive::rplidar::encode_node(n, out);
      bytes.assign(out, out + 5);
      i += 7;
    } else {
      run.dec.reset();
      continue;
    }
    run.dec.feed(bytes.data(), bytes.size());
    const autodrive::rplidar::DecoderStats &now = run.dec.stats();
    CHECK(now.nodes >= before.nodes && now.bad_nodes >= before.bad_nodes &&
          now.skipped_bytes >= before.skipped_bytes && now.descriptors >= before.descriptors);
    before = now;
  }
  return 0;
}
