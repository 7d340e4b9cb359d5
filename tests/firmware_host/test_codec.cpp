// The serial protocol codec: CRC, pack/unpack round trips, length checks, the schema string
// against PROTOCOL_LEN_*, and a randomized stream of good, corrupted, truncated frames and
// garbage through the byte-wise parser.
#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <map>
#include <random>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "collected_frames.h"
#include "protocol.h"

namespace {

std::vector<uint8_t> Encode(uint8_t id, uint8_t seq, const std::vector<uint8_t> &payload) {
  std::vector<uint8_t> out(PROTOCOL_MAX_FRAME);
  size_t n = protocol_frame_encode(id, seq, payload.data(), static_cast<uint8_t>(payload.size()),
                                   out.data(), out.size());
  out.resize(n);
  return out;
}

TEST(Crc, KnownVectors) {
  // CRC-16/CCITT-FALSE check value of "123456789" is 0x29B1 (the catalogue's check value).
  const char *check = "123456789";
  EXPECT_EQ(protocol_crc16(0xFFFFu, reinterpret_cast<const uint8_t *>(check), 9), 0x29B1u);
  EXPECT_EQ(protocol_crc16(0xFFFFu, nullptr, 0), 0xFFFFu);
  const uint8_t a = 'A';
  EXPECT_EQ(protocol_crc16(0xFFFFu, &a, 1), 0xB915u);
  // Incremental use equals one pass.
  const uint8_t *c = reinterpret_cast<const uint8_t *>(check);
  EXPECT_EQ(protocol_crc16(protocol_crc16(0xFFFFu, c, 4), c + 4, 5), 0x29B1u);
}

TEST(Frame, LayoutByteByByte) {
  std::vector<uint8_t> f = Encode(PROTOCOL_ID_HELLO_REQUEST, 0x42, {});
  ASSERT_EQ(f.size(), PROTOCOL_OVERHEAD);
  EXPECT_EQ(f[0], 0xA5);
  EXPECT_EQ(f[1], 0x5A);
  EXPECT_EQ(f[2], 0);
  EXPECT_EQ(f[3], 0x03);
  EXPECT_EQ(f[4], 0x42);
  const uint8_t hdr[] = {0x00, 0x03, 0x42};
  uint16_t crc = protocol_crc16(0xFFFFu, hdr, 3);
  EXPECT_EQ(f[5], crc & 0xFF);  // little-endian CRC
  EXPECT_EQ(f[6], crc >> 8);
}

// The worked examples and the hash quoted in PROTOCOL.md: if this fails after a deliberate
// protocol change, update PROTOCOL.md with the new bytes.
TEST(Frame, ProtocolDocExamples) {
  EXPECT_EQ(Encode(PROTOCOL_ID_HELLO_REQUEST, 0, {}),
            (std::vector<uint8_t>{0xA5, 0x5A, 0x00, 0x03, 0x00, 0xCF, 0x99}));
  protocol_command_t c{7, 500, -250, 1, 0, PROTOCOL_CMD_ENGAGED};
  std::vector<uint8_t> p(PROTOCOL_LEN_COMMAND);
  protocol_command_pack(&c, p.data());
  EXPECT_EQ(Encode(PROTOCOL_ID_COMMAND, 7, p),
            (std::vector<uint8_t>{0xA5, 0x5A, 0x09, 0x01, 0x07, 0x07, 0x00, 0xF4, 0x01, 0x06, 0xFF,
                                  0x01, 0x00, 0x01, 0xF5, 0xE3}));
  EXPECT_EQ(protocol_schema_hash(), 0x265771ABu) << "schema changed: update PROTOCOL.md section 5";
  EXPECT_EQ(std::string(PROTOCOL_SCHEMA).size(), 715u);
}

TEST(Frame, EncodeRejectsOversizeAndSmallBuffers) {
  uint8_t payload[PROTOCOL_MAX_PAYLOAD + 1] = {0};
  uint8_t out[PROTOCOL_MAX_FRAME + 8];
  EXPECT_EQ(protocol_frame_encode(1, 0, payload, PROTOCOL_MAX_PAYLOAD + 1, out, sizeof out), 0u);
  EXPECT_EQ(protocol_frame_encode(1, 0, payload, 10, out, 10 + PROTOCOL_OVERHEAD - 1), 0u);
  EXPECT_EQ(protocol_frame_encode(1, 0, payload, 10, out, 10 + PROTOCOL_OVERHEAD),
            10u + PROTOCOL_OVERHEAD);
  EXPECT_EQ(protocol_frame_encode(1, 0, payload, PROTOCOL_MAX_PAYLOAD, out, sizeof out),
            PROTOCOL_MAX_FRAME);
}

TEST(Messages, CommandRoundTripAndLength) {
  protocol_command_t c{0xBEEF, -1000, 734, 2, 3, PROTOCOL_CMD_ENGAGED};
  uint8_t p[PROTOCOL_LEN_COMMAND];
  protocol_command_pack(&c, p);
  EXPECT_EQ(p[0], 0xEF);
  EXPECT_EQ(p[1], 0xBE);
  EXPECT_EQ(p[2], 0x18);  // -1000 = 0xFC18
  EXPECT_EQ(p[3], 0xFC);
  protocol_command_t d{};
  ASSERT_EQ(protocol_command_unpack(p, PROTOCOL_LEN_COMMAND, &d), 0);
  EXPECT_EQ(d.seq, c.seq);
  EXPECT_EQ(d.throttle_milli, c.throttle_milli);
  EXPECT_EQ(d.steering_milli, c.steering_milli);
  EXPECT_EQ(d.headlights, c.headlights);
  EXPECT_EQ(d.indicators, c.indicators);
  EXPECT_EQ(d.flags, c.flags);
  EXPECT_EQ(protocol_command_unpack(p, PROTOCOL_LEN_COMMAND - 1, &d), -1);
  EXPECT_EQ(protocol_command_unpack(p, PROTOCOL_LEN_COMMAND + 1, &d), -1);
}

TEST(Messages, ConfigHelloNackRoundTrip) {
  protocol_config_t c{-200, 1000, 150}, c2{};
  uint8_t pc[PROTOCOL_LEN_CONFIG];
  protocol_config_pack(&c, pc);
  ASSERT_EQ(protocol_config_unpack(pc, PROTOCOL_LEN_CONFIG, &c2), 0);
  EXPECT_EQ(c2.servo_trim_us, -200);
  EXPECT_EQ(c2.telemetry_period_ms, 1000);
  EXPECT_EQ(c2.failsafe_timeout_ms, 150);
  EXPECT_EQ(protocol_config_unpack(pc, 5, &c2), -1);

  protocol_hello_t h{1, 2, 3, PROTOCOL_VERSION, 0xDEADBEEFu, 0x01020304u}, h2{};
  uint8_t ph[PROTOCOL_LEN_HELLO];
  protocol_hello_pack(&h, ph);
  EXPECT_EQ(ph[4], 0xEF);
  EXPECT_EQ(ph[7], 0xDE);
  ASSERT_EQ(protocol_hello_unpack(ph, PROTOCOL_LEN_HELLO, &h2), 0);
  EXPECT_EQ(h2.fw_major, 1);
  EXPECT_EQ(h2.fw_minor, 2);
  EXPECT_EQ(h2.fw_patch, 3);
  EXPECT_EQ(h2.schema_hash, 0xDEADBEEFu);
  EXPECT_EQ(h2.build_id, 0x01020304u);
  EXPECT_EQ(protocol_hello_unpack(ph, 0, &h2), -1);

  protocol_nack_t k{PROTOCOL_ID_COMMAND, PROTOCOL_NACK_OUT_OF_RANGE, 777}, k2{};
  uint8_t pk[PROTOCOL_LEN_NACK];
  protocol_nack_pack(&k, pk);
  ASSERT_EQ(protocol_nack_unpack(pk, PROTOCOL_LEN_NACK, &k2), 0);
  EXPECT_EQ(k2.rejected_id, PROTOCOL_ID_COMMAND);
  EXPECT_EQ(k2.reason, PROTOCOL_NACK_OUT_OF_RANGE);
  EXPECT_EQ(k2.seq, 777);
  EXPECT_EQ(protocol_nack_unpack(pk, 3, &k2), -1);
}

TEST(Messages, StateRoundTripEveryField) {
  protocol_state_t s{};
  // Distinct values in every field so a swapped or misplaced field shows.
  s.nano_time_us = 0xF1E2D3C4u;
  s.enc_counts[0] = -123456789;
  s.enc_counts[1] = 987654321;
  s.wheel_speed_mrad_s[0] = -13600;
  s.wheel_speed_mrad_s[1] = 13601;
  s.throttle_milli = -999;
  s.steering_milli = 998;
  for (int i = 0; i < 3; ++i) {
    s.accel_raw[i] = static_cast<int16_t>(-100 - i);
    s.gyro_raw[i] = static_cast<int16_t>(200 + i);
    s.mag_raw[i] = static_cast<int16_t>(-300 - i);
  }
  for (int i = 0; i < 4; ++i) s.quat_q14[i] = static_cast<int16_t>(16384 - 1000 * i);
  s.battery_mv = 11100;
  s.lights = 0xA5;
  s.mode = PROTOCOL_MODE_FAILSAFE;
  s.faults = 0x7F;
  s.last_cmd_seq = 65535;
  s.frames_ok = 1;
  s.frames_bad_crc = 2;
  s.frames_dropped = 3;
  uint8_t p[PROTOCOL_LEN_STATE];
  protocol_state_pack(&s, p);
  EXPECT_EQ(p[0], 0xC4);  // nano_time_us little-endian at offset 0
  EXPECT_EQ(p[3], 0xF1);
  EXPECT_EQ(p[46], 11100 & 0xFF);  // battery_mv at offset 46
  EXPECT_EQ(p[48], 0xA5);          // lights at 48
  EXPECT_EQ(p[49], PROTOCOL_MODE_FAILSAFE);
  EXPECT_EQ(p[58], 3);  // frames_dropped at 58
  protocol_state_t d{};
  ASSERT_EQ(protocol_state_unpack(p, PROTOCOL_LEN_STATE, &d), 0);
  EXPECT_EQ(0, std::memcmp(&s, &d, sizeof s));
  EXPECT_EQ(protocol_state_unpack(p, PROTOCOL_LEN_STATE - 1, &d), -1);
}

TEST(Messages, RangeChecks) {
  protocol_command_t c{1, 1000, -1000, 2, 3, PROTOCOL_CMD_ENGAGED};
  EXPECT_TRUE(protocol_command_valid(&c));
  c.throttle_milli = 1001;
  EXPECT_FALSE(protocol_command_valid(&c));
  c.throttle_milli = -1001;
  EXPECT_FALSE(protocol_command_valid(&c));
  c.throttle_milli = 0;
  c.steering_milli = -1001;
  EXPECT_FALSE(protocol_command_valid(&c));
  c.steering_milli = 0;
  c.headlights = 3;
  EXPECT_FALSE(protocol_command_valid(&c));
  c.headlights = 0;
  c.indicators = 4;
  EXPECT_FALSE(protocol_command_valid(&c));
  c.indicators = 0;
  c.flags = 0x02;
  EXPECT_FALSE(protocol_command_valid(&c));
  protocol_config_t k{0, 10, 100};
  EXPECT_TRUE(protocol_config_valid(&k));
  k.failsafe_timeout_ms = 151;
  EXPECT_FALSE(protocol_config_valid(&k));
  k.failsafe_timeout_ms = 19;
  EXPECT_FALSE(protocol_config_valid(&k));
  k.failsafe_timeout_ms = 100;
  k.telemetry_period_ms = 4;
  EXPECT_FALSE(protocol_config_valid(&k));
  k.telemetry_period_ms = 1001;
  EXPECT_FALSE(protocol_config_valid(&k));
  k.telemetry_period_ms = 10;
  k.servo_trim_us = 201;
  EXPECT_FALSE(protocol_config_valid(&k));
  k.servo_trim_us = -201;
  EXPECT_FALSE(protocol_config_valid(&k));
}

// Parses PROTOCOL_SCHEMA ("v1;01 command:u16 seq,...;...") and sums the field sizes.
TEST(Schema, StringMatchesLengthsAndIds) {
  const std::string schema = PROTOCOL_SCHEMA;
  std::stringstream ss(schema);
  std::string part;
  ASSERT_TRUE(std::getline(ss, part, ';'));
  EXPECT_EQ(part, "v" + std::to_string(PROTOCOL_VERSION));
  const std::map<std::string, size_t> size_of = {{"u8", 1},  {"i8", 1},  {"u16", 2},
                                                 {"i16", 2}, {"u32", 4}, {"i32", 4}};
  const std::map<std::string, std::pair<int, size_t>> expect = {
      {"command", {PROTOCOL_ID_COMMAND, PROTOCOL_LEN_COMMAND}},
      {"config", {PROTOCOL_ID_CONFIG, PROTOCOL_LEN_CONFIG}},
      {"hello_request", {PROTOCOL_ID_HELLO_REQUEST, PROTOCOL_LEN_HELLO_REQUEST}},
      {"hello", {PROTOCOL_ID_HELLO, PROTOCOL_LEN_HELLO}},
      {"state", {PROTOCOL_ID_STATE, PROTOCOL_LEN_STATE}},
      {"nack", {PROTOCOL_ID_NACK, PROTOCOL_LEN_NACK}}};
  std::map<std::string, bool> seen;
  while (std::getline(ss, part, ';')) {
    if (part.empty()) continue;
    size_t sp = part.find(' '), colon = part.find(':');
    ASSERT_NE(sp, std::string::npos) << part;
    ASSERT_NE(colon, std::string::npos) << part;
    int id = std::stoi(part.substr(0, sp), nullptr, 16);
    std::string name = part.substr(sp + 1, colon - sp - 1);
    size_t total = 0;
    std::stringstream fs(part.substr(colon + 1));
    std::string field;
    while (std::getline(fs, field, ',')) {
      std::string type = field.substr(0, field.find(' '));
      ASSERT_TRUE(size_of.count(type)) << "unknown type '" << type << "' in " << part;
      total += size_of.at(type);
    }
    ASSERT_TRUE(expect.count(name)) << "message not in protocol.h: " << name;
    EXPECT_EQ(id, expect.at(name).first) << name;
    EXPECT_EQ(total, expect.at(name).second) << name;
    EXPECT_LE(total, PROTOCOL_MAX_PAYLOAD) << name;
    seen[name] = true;
  }
  EXPECT_EQ(seen.size(), expect.size());
}

TEST(Schema, HashIsFnv1aOfTheString) {
  uint32_t h = 2166136261u;
  for (char c : std::string(PROTOCOL_SCHEMA)) {
    h ^= static_cast<uint8_t>(c);
    h *= 16777619u;
  }
  EXPECT_EQ(protocol_schema_hash(), h);
  EXPECT_NE(h, 0u);
}

TEST(Parser, ByteByByteAndCounters) {
  protocol_parser_t p;
  protocol_parser_init(&p);
  CollectedFrames got;
  std::vector<uint8_t> stream;
  for (uint8_t s = 0; s < 5; ++s) {
    auto f = Encode(PROTOCOL_ID_COMMAND, static_cast<uint8_t>(s * 2), std::vector<uint8_t>(9, s));
    stream.insert(stream.end(), f.begin(), f.end());
  }
  for (uint8_t b : stream) protocol_parser_feed(&p, &b, 1, collect_frame, &got);
  ASSERT_EQ(got.frames.size(), 5u);
  EXPECT_EQ(got.frames[3].seq, 6);
  EXPECT_EQ(got.frames[3].payload[0], 3);
  EXPECT_EQ(p.stats.frames_ok, 5u);
  EXPECT_EQ(p.stats.frames_dropped, 4u);  // seq 0,2,4,6,8: one gap of one each time
  EXPECT_EQ(p.stats.bad_crc, 0u);
}

TEST(Parser, BadCrcAndOversizeLengthCounted) {
  protocol_parser_t p;
  protocol_parser_init(&p);
  CollectedFrames got;
  auto good = Encode(PROTOCOL_ID_CONFIG, 1, std::vector<uint8_t>(6, 7));
  auto bad = good;
  bad[7] ^= 0x10;
  const uint8_t oversize[] = {0xA5, 0x5A, 200};
  protocol_parser_feed(&p, bad.data(), bad.size(), collect_frame, &got);
  protocol_parser_feed(&p, oversize, sizeof oversize, collect_frame, &got);
  protocol_parser_feed(&p, good.data(), good.size(), collect_frame, &got);
  ASSERT_EQ(got.frames.size(), 1u);
  EXPECT_EQ(p.stats.bad_crc, 1u);
  EXPECT_EQ(p.stats.bad_length, 1u);
}

// Valid frames mixed with bit flips, truncation and garbage. Every untouched frame must come
// out; frames the parser accepts that were never sent (false accepts) are counted.
TEST(Parser, RandomizedStreamResync) {
  uint64_t stat_bad_crc = 0, stat_bad_len = 0, stat_skipped = 0, stream_bytes = 0;
  uint64_t total_frames = 0, untouched = 0, recovered = 0, false_accepts = 0, completed = 0,
           flipped = 0, truncated = 0, garbage_runs = 0, garbage_bytes = 0;
  for (uint32_t seed = 1; seed <= 8; ++seed) {
    std::mt19937 rng(seed);
    std::vector<uint8_t> stream;
    std::vector<std::vector<uint8_t>> expected;  // encoded untouched frames, in order
    std::set<std::vector<uint8_t>> sent;         // every frame as encoded before damage
    for (int i = 0; i < 3000; ++i) {
      uint8_t len = static_cast<uint8_t>(2 + rng() % (PROTOCOL_MAX_PAYLOAD - 1));
      std::vector<uint8_t> payload(len);
      for (auto &b : payload) b = static_cast<uint8_t>(rng());
      payload[0] = static_cast<uint8_t>(i);  // tag so a match is unambiguous
      payload[1] = static_cast<uint8_t>(i >> 8);
      auto f = Encode(static_cast<uint8_t>(rng()), static_cast<uint8_t>(i), payload);
      ++total_frames;
      uint32_t r = rng() % 100;
      const std::vector<uint8_t> orig = f;
      sent.insert(orig);
      if (r < 15) {  // 1-3 bit flips anywhere in the frame (the same bit twice undoes itself)
        int nflip = 1 + static_cast<int>(rng() % 3);
        for (int k = 0; k < nflip; ++k)
          f[rng() % f.size()] ^= static_cast<uint8_t>(1u << (rng() % 8));
      }
      if (r < 15 && f != orig) {
        ++flipped;
      } else if (r >= 15 && r < 25) {  // cut short
        f.resize(1 + rng() % (f.size() - 1));
        ++truncated;
      } else {
        if (r < 40) {  // garbage before an untouched frame, with sync bytes on purpose
          size_t n = 1 + rng() % 40;
          for (size_t k = 0; k < n; ++k) {
            uint32_t g = rng() % 8;
            stream.push_back(g == 0 ? 0xA5 : g == 1 ? 0x5A : static_cast<uint8_t>(rng()));
          }
          ++garbage_runs;
          garbage_bytes += n;
        }
        expected.push_back(f);
        ++untouched;
      }
      stream.insert(stream.end(), f.begin(), f.end());
    }
    protocol_parser_t p;
    protocol_parser_init(&p);
    CollectedFrames got;
    // Feed in random chunk sizes like a UART driver would.
    for (size_t pos = 0; pos < stream.size();) {
      size_t n = std::min<size_t>(1 + rng() % 32, stream.size() - pos);
      protocol_parser_feed(&p, stream.data() + pos, n, collect_frame, &got);
      pos += n;
    }
    stat_bad_crc += p.stats.bad_crc;
    stat_bad_len += p.stats.bad_length;
    stat_skipped += p.stats.skipped_bytes;
    stream_bytes += stream.size();
    size_t e = 0;
    for (const auto &fr : got.frames) {
      std::vector<uint8_t> re =
          Encode(fr.id, fr.seq, std::vector<uint8_t>(fr.payload, fr.payload + fr.len));
      if (e < expected.size() && re == expected[e]) {
        ++e;
        ++recovered;
      } else {
        ++false_accepts;
        if (sent.count(re)) ++completed;  // a damaged frame whose content is genuine
      }
    }
    EXPECT_EQ(e, expected.size()) << "seed " << seed << ": an untouched frame was lost";
  }
  std::cout << "[stream] frames sent " << total_frames << ", untouched " << untouched
            << ", recovered " << recovered << ", bit-flipped " << flipped << ", truncated "
            << truncated << ", garbage runs " << garbage_runs << " (" << garbage_bytes
            << " bytes), falsely accepted " << false_accepts << " (of which " << completed
            << " are damaged frames with genuine content: cut inside the CRC and completed by the"
            << " next byte, a 1/256 event; " << (false_accepts - completed)
            << " carry content never sent)" << std::endl;
  std::cout << "[stream] resync: " << (untouched - recovered)
            << " untouched frames lost to damage or garbage before them; "
            << "parser counted " << stat_bad_crc << " bad CRCs, " << stat_bad_len
            << " bad lengths, skipped " << stat_skipped << " of " << stream_bytes << " bytes"
            << std::endl;
  RecordProperty("false_accepts", static_cast<int>(false_accepts));
  RecordProperty("false_accepts_foreign_content", static_cast<int>(false_accepts - completed));
  RecordProperty("recovered", static_cast<int>(recovered));
  EXPECT_EQ(recovered, untouched);
  // CRC-16 lets ~1 in 65536 random candidates through; a frame cut after its first CRC byte is
  // completed by the next byte with chance 1/256 (its content is still genuine).
  EXPECT_LE(false_accepts, 10u);
  EXPECT_LE(false_accepts - completed, 2u);
}

}  // namespace
