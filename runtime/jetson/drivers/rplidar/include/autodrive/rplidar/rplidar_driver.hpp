// RPLIDAR A1 driver: serial I/O around autodrive::rplidar::Decoder. STOP, GET_HEALTH (RESET on
// error), SCAN, then publishes <VEH>_LIDAR each turn. Restarts the scan when nodes stop arriving
// and reopens the device when it disappears.
#pragma once

#include <atomic>
#include <cstdint>
#include <memory>
#include <string>

#include <autodrive/core/config.hpp>

namespace autodrive::rplidar {

struct DriverStatus {
  bool scanning = false;
  uint64_t opens = 0, disconnects = 0, scans_published = 0, scan_starts = 0;
  uint64_t nodes = 0, bad_nodes = 0;
  int last_health = -1;             // 0 good, 1 warning, 2 error, -1 unknown
  uint64_t resets = 0;              // RESET commands sent on a health error
  uint64_t resets_refused = 0;      // health errors not answered by a reset (limit reached)
  uint64_t unsolicited_health = 0;  // health packets while scanning: ignored
};

class Driver {
 public:
  explicit Driver(const autodrive::config::Config &config);
  ~Driver();
  std::string init_error() const;
  void run(const std::atomic<bool> &stop);
  DriverStatus status() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace autodrive::rplidar
