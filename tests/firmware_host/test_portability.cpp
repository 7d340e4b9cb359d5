// What could differ between the Nano (AVR: 8-bit, char signed, long 32 bit), this amd64 host
// and the Jetson (aarch64: char UNSIGNED, long 64 bit), checked on the protocol codec the
// three share. tools/test --aarch64 runs these under qemu-user on an aarch64 build; here they
// run under ASan + UBSan, whose alignment check catches a misaligned multi-byte load.
#include <gtest/gtest.h>

#include <climits>
#include <cstdint>
#include <cstring>
#include <vector>

#include "collected_frames.h"
#include "protocol.h"

namespace {

// Records the platform's facts in the test output (the aarch64 run shows char unsigned, long 8).
TEST(Portability, PlatformFacts) {
  const bool char_signed = CHAR_MIN < 0;
  RecordProperty("char_signed", char_signed ? "yes" : "no");
  RecordProperty("sizeof_long", static_cast<int>(sizeof(long)));
  std::printf("char is %s, sizeof(long) = %zu, sizeof(void*) = %zu\n",
              char_signed ? "signed" : "unsigned", sizeof(long), sizeof(void *));
  // The wire format never depends on these: every field is a fixed-width integer.
  EXPECT_EQ(sizeof(int16_t), 2u);
  EXPECT_EQ(sizeof(int32_t), 4u);
}

// char signedness: bytes >= 0x80 must mean the same on every machine. Frames made of such bytes
// (sync 0xA5, CRC bytes, negative fields) arrive through a `char` buffer, as a read() into
// char storage would hand them, and must parse to the same values everywhere.
TEST(Portability, HighBytesThroughCharBufferParseTheSame) {
  protocol_state_t s{};
  s.nano_time_us = 0xFEDCBA98u;
  s.enc_counts[0] = -1;
  s.enc_counts[1] = INT32_MIN;
  s.wheel_speed_mrad_s[0] = -32768;
  s.wheel_speed_mrad_s[1] = -129;
  s.throttle_milli = -1000;
  s.steering_milli = -1;
  s.accel_raw[2] = -8192;
  s.quat_q14[0] = -16384;
  s.battery_mv = 0xFFFFu;
  s.lights = 0xFFu;
  s.mode = 0x80u;
  s.faults = 0x8001u;
  s.frames_bad_crc = 0xFF80u;
  uint8_t payload[PROTOCOL_LEN_STATE];
  protocol_state_pack(&s, payload);
  uint8_t frame[PROTOCOL_MAX_FRAME];
  const size_t n = protocol_frame_encode(PROTOCOL_ID_STATE, 0xFFu, payload, PROTOCOL_LEN_STATE,
                                         frame, sizeof frame);
  ASSERT_EQ(n, PROTOCOL_LEN_STATE + PROTOCOL_OVERHEAD);

  std::vector<char> as_chars(n);
  std::memcpy(as_chars.data(), frame, n);
  std::vector<uint8_t> back(n);
  for (size_t i = 0; i < n; ++i) back[i] = static_cast<uint8_t>(as_chars[i]);

  protocol_parser_t p;
  protocol_parser_init(&p);
  CollectedFrames got;
  ASSERT_EQ(protocol_parser_feed(&p, back.data(), back.size(), collect_frame, &got), 1u);
  ASSERT_EQ(got.frames.size(), 1u);
  protocol_state_t d{};
  ASSERT_EQ(protocol_state_unpack(got.frames[0].payload, got.frames[0].len, &d), 0);
  EXPECT_EQ(d.nano_time_us, 0xFEDCBA98u);
  EXPECT_EQ(d.enc_counts[0], -1);
  EXPECT_EQ(d.enc_counts[1], INT32_MIN);
  EXPECT_EQ(d.wheel_speed_mrad_s[0], -32768);
  EXPECT_EQ(d.wheel_speed_mrad_s[1], -129);
  EXPECT_EQ(d.throttle_milli, -1000);
  EXPECT_EQ(d.steering_milli, -1);
  EXPECT_EQ(d.accel_raw[2], -8192);
  EXPECT_EQ(d.quat_q14[0], -16384);
  EXPECT_EQ(d.battery_mv, 0xFFFFu);
  EXPECT_EQ(d.lights, 0xFFu);
  EXPECT_EQ(d.mode, 0x80u);
  EXPECT_EQ(d.faults, 0x8001u);
  EXPECT_EQ(d.frames_bad_crc, 0xFF80u);
}

// The wire bytes themselves, written out from PROTOCOL.md (little-endian, two's complement):
// the same on the Nano, amd64 and aarch64 whatever their char or long.
TEST(Portability, CommandBytesAreThePublishedLayout) {
  protocol_command_t c{};
  c.seq = 0x8081u;
  c.throttle_milli = -1000;  // 0xFC18
  c.steering_milli = -2;     // 0xFFFE
  c.headlights = 2;
  c.indicators = 3;
  c.flags = PROTOCOL_CMD_ENGAGED;
  uint8_t out[PROTOCOL_LEN_COMMAND];
  protocol_command_pack(&c, out);
  const uint8_t want[PROTOCOL_LEN_COMMAND] = {0x81, 0x80, 0x18, 0xFC, 0xFE, 0xFF, 2, 3, 1};
  EXPECT_EQ(std::memcmp(out, want, sizeof want), 0);
}

// long sizes: 32-bit fields with bit 31 set survive a round trip (a decoder that assembled
// them in a `long` or an `int` shifted by 24 would sign-extend on a 64-bit long, or overflow).
TEST(Portability, Bit31FieldsRoundTrip) {
  const uint32_t values[] = {0x80000000u, 0xFFFFFFFFu, 0x7FFFFFFFu, 0x00000080u, 0x00008000u};
  for (uint32_t v : values) {
    protocol_hello_t h{};
    h.schema_hash = v;
    h.build_id = ~v;
    uint8_t buf[PROTOCOL_LEN_HELLO];
    protocol_hello_pack(&h, buf);
    protocol_hello_t d{};
    ASSERT_EQ(protocol_hello_unpack(buf, PROTOCOL_LEN_HELLO, &d), 0);
    EXPECT_EQ(d.schema_hash, v);
    EXPECT_EQ(d.build_id, static_cast<uint32_t>(~v));
    protocol_state_t s{};
    s.nano_time_us = v;
    s.enc_counts[0] = static_cast<int32_t>(v);
    uint8_t sb[PROTOCOL_LEN_STATE];
    protocol_state_pack(&s, sb);
    protocol_state_t sd{};
    ASSERT_EQ(protocol_state_unpack(sb, PROTOCOL_LEN_STATE, &sd), 0);
    EXPECT_EQ(sd.nano_time_us, v);
    EXPECT_EQ(sd.enc_counts[0], static_cast<int32_t>(v));
  }
}

// Unaligned access: the codec reads and writes payloads at any address (a frame's payload
// starts 5 bytes into the parser's buffer). Every offset 0..7 gives the same result; a
// decoder that cast the pointer to uint32_t* would fault on strict-alignment targets and is
// caught by UBSan's alignment check here.
TEST(Portability, PayloadAtEveryOffset) {
  protocol_state_t s{};
  s.nano_time_us = 0x12345678u;
  s.enc_counts[0] = -123456;
  s.enc_counts[1] = 654321;
  s.gyro_raw[1] = -300;
  s.last_cmd_seq = 0xBEEFu;
  uint8_t ref[PROTOCOL_LEN_STATE];
  protocol_state_pack(&s, ref);
  alignas(8) uint8_t storage[PROTOCOL_LEN_STATE + 16];
  for (size_t off = 0; off < 8; ++off) {
    uint8_t *at = storage + off;
    std::memset(storage, 0xCC, sizeof storage);
    protocol_state_pack(&s, at);
    EXPECT_EQ(std::memcmp(at, ref, PROTOCOL_LEN_STATE), 0) << "pack at offset " << off;
    protocol_state_t d{};
    ASSERT_EQ(protocol_state_unpack(at, PROTOCOL_LEN_STATE, &d), 0) << "offset " << off;
    EXPECT_EQ(d.nano_time_us, 0x12345678u) << "offset " << off;
    EXPECT_EQ(d.enc_counts[0], -123456) << "offset " << off;
    EXPECT_EQ(d.enc_counts[1], 654321) << "offset " << off;
    EXPECT_EQ(d.gyro_raw[1], -300) << "offset " << off;
    EXPECT_EQ(d.last_cmd_seq, 0xBEEFu) << "offset " << off;
    EXPECT_EQ(protocol_crc16(0xFFFFu, at, PROTOCOL_LEN_STATE),
              protocol_crc16(0xFFFFu, ref, PROTOCOL_LEN_STATE));
  }
}

}  // namespace
