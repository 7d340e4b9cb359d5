// Nano bridge: the serial link to the Arduino Nano (or the simulator's / simavr's pty).
// Handshake (HELLO_REQUEST until a HELLO with our schema hash), telemetry -> <VEH>_STATE and
// <VEH>_IMU, <VEH>_COMMAND -> COMMAND frames: a fresh command at once, a flood capped by a token
// bucket, a heartbeat when no command went out for a period (command_pacer.hpp); engaged only
// while the LCM command stream is fresh (on the sim clock with clock: sim). Only commands the
// command gate admits (signed, not replayed, from the lease holder) count; the holder and the
// gate's counters go out on <VEH>_CONTROL. Reconnects by itself when the device disappears.
#pragma once

#include <atomic>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>

#include <autodrive/nano_bridge/command_gate.hpp>
#include <autodrive/core/config.hpp>

namespace autodrive::bridge {

enum class LinkState { no_device, handshaking, linked, refused };
const char *link_state_name(LinkState s);

// Counters [count] and the current link state, for tests, logs and the benchmark.
struct Status {
  LinkState state = LinkState::no_device;
  uint64_t opens = 0;        // successful device opens
  uint64_t disconnects = 0;  // device lost (hang-up, I/O error, removed)
  uint64_t hellos_sent = 0;
  uint64_t handshakes = 0;         // HELLOs accepted
  uint64_t refusals = 0;           // HELLOs refused (schema or version mismatch)
  uint64_t commands_sent = 0;      // COMMAND frames written
  uint64_t engaged_sent = 0;       // ... of which with the engaged flag
  uint64_t commands_at_once = 0;   // admitted commands written in the call that received them
  uint64_t commands_held = 0;      // admitted commands that found the token bucket empty
  uint64_t commands_rejected = 0;  // LCM commands with out-of-range fields
  uint64_t states_published = 0;
  uint64_t imu_published = 0;
  uint64_t nacks = 0;
  // Receive side: garbage on the link is counted (and logged at a limited rate).
  uint64_t rx_skipped_bytes = 0;  // bytes discarded while hunting for a frame
  uint64_t rx_bad_crc = 0;        // frames whose CRC failed
  uint64_t rx_bad_length = 0;     // length byte above PROTOCOL_MAX_PAYLOAD
  uint64_t rx_bad_payload = 0;    // good CRC but a HELLO/STATE/NACK that does not unpack
  std::string last_refusal;       // the refusal message (names both schemas)
  GateCounters control;           // the command gate's counters (as of the last CONTROL status)
  std::string holder;             // the source holding the control lease, "" when none
};

class NanoBridge {
 public:
  explicit NanoBridge(const autodrive::config::Config &config);
  ~NanoBridge();
  NanoBridge(const NanoBridge &) = delete;
  NanoBridge &operator=(const NanoBridge &) = delete;

  // "" when ready to run, else why not (e.g. LCM URL unusable).
  std::string init_error() const;
  // Runs until `stop` becomes true (checked at least every 20 ms).
  void run(const std::atomic<bool> &stop);
  Status status() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace autodrive::bridge
