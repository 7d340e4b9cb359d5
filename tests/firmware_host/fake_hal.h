// A host fake of the firmware HAL: records every output, serves IMU samples and a battery
// voltage the test sets, and parses what the core transmits back into frames.
#pragma once

#include <cstdint>
#include <vector>

#include "nano_core.h"
#include "protocol.h"

class FakeHal {
 public:
  FakeHal() {
    hal_.ctx = this;
    hal_.motor_set = [](void *c, uint8_t d, uint8_t rev, uint8_t b) {
      auto *h = static_cast<FakeHal *>(c);
      h->duty = d;
      h->reverse = rev;
      h->brake = b;
      ++h->motor_calls;
    };
    hal_.servo_set_us = [](void *c, uint16_t us) { static_cast<FakeHal *>(c)->servo_us = us; };
    hal_.lamps_set = [](void *c, uint8_t l) { static_cast<FakeHal *>(c)->lamps = l; };
    hal_.imu_read = [](void *c, nano_core_imu_raw_t *out) {
      auto *h = static_cast<FakeHal *>(c);
      ++h->imu_reads;
      if (h->imu_absent) return -1;
      *out = h->imu;
      return 0;
    };
    hal_.battery_read_mv = [](void *c) { return static_cast<FakeHal *>(c)->battery_mv; };
    hal_.serial_write = [](void *c, const uint8_t *d, uint8_t n) {
      auto *h = static_cast<FakeHal *>(c);
      h->tx_bytes += n;
      protocol_parser_feed(&h->rx_parser_, d, n, &FakeHal::OnFrame, h);
    };
    protocol_parser_init(&rx_parser_);
    imu.accel[2] = PROTOCOL_ACCEL_LSB_PER_G;  // level and still
  }
  const nano_core_hal_t *hal() const { return &hal_; }

  // What the core transmitted, decoded (every frame must pass CRC to appear here).
  std::vector<protocol_frame_t> frames;
  std::vector<protocol_frame_t> Take(uint8_t id) {
    std::vector<protocol_frame_t> out, rest;
    for (auto &f : frames) (f.id == id ? out : rest).push_back(f);
    frames = rest;
    return out;
  }
  const protocol_stats_t &tx_stats() const { return rx_parser_.stats; }

  uint8_t duty = 0xEE, reverse = 0xEE, brake = 0xEE, lamps = 0xEE;
  uint16_t servo_us = 0;
  unsigned motor_calls = 0, imu_reads = 0;
  size_t tx_bytes = 0;
  bool imu_absent = false;
  nano_core_imu_raw_t imu{};
  uint16_t battery_mv = 11800;

 private:
  static void OnFrame(const protocol_frame_t *f, void *ctx) {
    static_cast<FakeHal *>(ctx)->frames.push_back(*f);
  }
  nano_core_hal_t hal_{};
  protocol_parser_t rx_parser_{};
};
