// Pure conversions between the Nano's wire messages (protocol.h) and the LCM types. No I/O, so
// the unit tests check every scale and bit directly.
#pragma once

#include <autodrive/imu_t.hpp>
#include <autodrive/vehicle_command_t.hpp>
#include <autodrive/vehicle_state_t.hpp>

#include <cstdint>
#include <string>

#include <autodrive/core/config.hpp>
#include "protocol.h"

namespace autodrive::bridge {

constexpr double kGravity_m_s2 = 9.80665;

// Host-side link counters that go into vehicle_state_t.
struct HostLinkStats {
  uint32_t frames_ok = 0;
  uint32_t bad_crc = 0;
  uint32_t dropped = 0;
};

void fill_state(const protocol_state_t &s, const autodrive::config::Vehicle &veh,
                const HostLinkStats &host, int64_t utime_us, autodrive::vehicle_state_t *out);

// Converts raw MPU-9250 LSB with the protocol.h scales; covariances are diagonal from config.
void fill_imu(const protocol_state_t &s, const autodrive::config::Bridge &br, int64_t utime_us,
              autodrive::imu_t *out);

// Returns "" if the command is usable, else what is wrong with it.
std::string command_problem(const autodrive::vehicle_command_t &c);
// "" if a STATE from the Nano is plausible (applied throttle and steering within
// [-PROTOCOL_MILLI, PROTOCOL_MILLI], a known mode and headlight level), else what is wrong; such a
// STATE is dropped.
std::string state_problem(const protocol_state_t &s);

// The COMMAND frame for the heartbeat. `fresh` is false when the LCM command stream is stale
// (or absent): then throttle is 0, steering centred and engaged cleared; lights are kept.
protocol_command_t make_command(const autodrive::vehicle_command_t *latest, bool fresh,
                                uint16_t seq);

}  // namespace autodrive::bridge
