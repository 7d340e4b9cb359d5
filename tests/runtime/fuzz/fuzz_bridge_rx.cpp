// libFuzzer target: the runtime's receive path from the Nano. Bytes -> the proto parser ->
// HELLO / STATE / NACK unpack -> the bridge's checks and conversions (state_problem,
// fill_state, fill_imu), exactly what NanoBridge does with each frame.
// The input is a script so the fuzzer reaches the decoders instead of dying at the CRC:
//   op 0: n raw bytes (garbage, partial frames)                  [0, n, bytes...]
//   op 1: a frame with a valid CRC: id, len, payload              [1, id, len, payload...]
//         (bit 7 of the id byte set: the id is HELLO, STATE or NACK with its right length)
// Safety invariants (abort on violation): unpack succeeds exactly for the right length; a
// STATE that passes state_problem() converts to finite values with |throttle|, |steering|
// <= 1, a steering angle within the car's limit, a unit quaternion and a gyro rate inside
// the sensor's range; the parser never holds a complete frame.
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>

#include <autodrive/nano_bridge/bridge_convert.hpp>
#include "protocol.h"

namespace {

#define CHECK(cond) \
  do {              \
    if (!(cond)) {  \
      std::abort(); \
    }               \
  } while (0)

autodrive::config::Vehicle vehicle;
autodrive::config::Bridge bridge_cfg;

bool finite_within(double v, double bound) {
  return std::isfinite(v) && std::abs(v) <= bound;
}

void check_state(const protocol_frame_t &f) {
  protocol_state_t s{};
  const int r = protocol_state_unpack(f.payload, f.len, &s);
  CHECK((r == 0) == (f.len == PROTOCOL_LEN_STATE));
  if (r != 0 || !autodrive::bridge::state_problem(s).empty()) return;
  autodrive::vehicle_state_t vs{};
  autodrive::bridge::fill_state(s, vehicle, autodrive::bridge::HostLinkStats{}, 123, &vs);
  CHECK(finite_within(vs.throttle_applied, 1.0));
  CHECK(finite_within(vs.steering_applied, 1.0));
  CHECK(finite_within(vs.steering_angle_rad, vehicle.steering_limit_rad + 1e-6));
  CHECK(finite_within(vs.battery_voltage_v, 65.536));
  CHECK(vs.mode >= 0 && vs.mode <= PROTOCOL_MODE_FAILSAFE);
  CHECK(vs.headlights >= 0 && vs.headlights <= 2 && vs.indicators >= 0 && vs.indicators <= 3);
  for (int i = 0; i < 2; ++i) CHECK(finite_within(vs.wheel_speed_rad_s[i], 32.769));
  autodrive::imu_t imu{};
  autodrive::bridge::fill_imu(s, bridge_cfg, 123, &imu);
  double n2 = 0;
  for (double q : imu.orientation_wxyz) {
    CHECK(std::isfinite(q));
    n2 += q * q;
  }
  CHECK(std::abs(n2 - 1.0) < 1e-9);
  // int16 / 65.5 LSB per deg/s: at most 500.3 deg/s = 8.74 rad/s.
  for (double w : imu.angular_velocity_rad_s) CHECK(finite_within(w, 8.75));
  for (double a : imu.linear_acceleration_m_s2) CHECK(std::isfinite(a));
}

void on_frame(const protocol_frame_t *f, void *) {
  if (f->id == PROTOCOL_ID_HELLO) {
    protocol_hello_t h{};
    CHECK((protocol_hello_unpack(f->payload, f->len, &h) == 0) == (f->len == PROTOCOL_LEN_HELLO));
  } else if (f->id == PROTOCOL_ID_STATE) {
    check_state(*f);
  } else if (f->id == PROTOCOL_ID_NACK) {
    protocol_nack_t n{};
    CHECK((protocol_nack_unpack(f->payload, f->len, &n) == 0) == (f->len == PROTOCOL_LEN_NACK));
  }
}

const uint8_t kIds[] = {PROTOCOL_ID_HELLO, PROTOCOL_ID_STATE, PROTOCOL_ID_NACK};
uint8_t right_len(uint8_t id) {
  return id == PROTOCOL_ID_HELLO   ? PROTOCOL_LEN_HELLO
         : id == PROTOCOL_ID_STATE ? PROTOCOL_LEN_STATE
                                   : PROTOCOL_LEN_NACK;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  protocol_parser_t parser;
  protocol_parser_init(&parser);
  uint8_t seq = 0;
  size_t i = 0;
  while (i < size) {
    const uint8_t op = data[i++] % 2u;
    if (op == 0) {
      if (i >= size) break;
      size_t n = data[i++];
      if (n > size - i) n = size - i;
      protocol_parser_feed(&parser, data + i, n, on_frame, nullptr);
      i += n;
    } else {
      if (i + 2 > size) break;
      uint8_t id = data[i++], len = data[i++];
      if (id & 0x80u) {
        id = kIds[id % 3u];
        len = right_len(id);
      } else {
        id = kIds[id % 3u];
        len = static_cast<uint8_t>(len % (PROTOCOL_MAX_PAYLOAD + 1u));
      }
      uint8_t payload[PROTOCOL_MAX_PAYLOAD] = {0};
      const size_t avail = size - i < len ? size - i : len;
      std::memcpy(payload, data + i, avail);
      i += avail;
      uint8_t frame[PROTOCOL_MAX_FRAME];
      const size_t fn = protocol_frame_encode(id, seq++, payload, len, frame, sizeof frame);
      CHECK(fn > 0);
      protocol_parser_feed(&parser, frame, fn, on_frame, nullptr);
    }
    CHECK(parser.n < PROTOCOL_MAX_FRAME);
  }
  return 0;
}
