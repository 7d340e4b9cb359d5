// The emulated Nano: protocol conformance on the real pty with the shared parser (protocol.h),
// wire pacing, and the failsafe when the client goes quiet. Sim time only.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <poll.h>
#include <math.h>
#include <termios.h>
#include <unistd.h>

#include <vector>

#include "protocol.h"
#include "sim_test_util.h"

namespace {

// A client on the sim's pty symlink that collects the frames the emulated Nano sends.
struct Client {
  int fd = -1;
  protocol_parser_t parser;
  std::vector<protocol_frame_t> frames;
  uint8_t seq = 0;
  uint16_t cmd_seq = 0;

  explicit Client(const char *link) {
    fd = open(link, O_RDWR | O_NOCTTY | O_NONBLOCK);
    if (fd >= 0) {
      termios t;
      tcgetattr(fd, &t);
      cfmakeraw(&t);
      tcsetattr(fd, TCSANOW, &t);
    }
    protocol_parser_init(&parser);
  }
  ~Client() {
    if (fd >= 0) close(fd);
  }
  void read_all() {
    uint8_t buf[1024];
    ssize_t n;
    while ((n = read(fd, buf, sizeof buf)) > 0)
      protocol_parser_feed(
          &parser, buf, (size_t)n,
          [](const protocol_frame_t *f, void *ctx) {
            static_cast<Client *>(ctx)->frames.push_back(*f);
          },
          this);
  }
  void send(uint8_t id, const uint8_t *payload, uint8_t len) {
    uint8_t out[PROTOCOL_MAX_FRAME];
    const size_t n = protocol_frame_encode(id, seq++, payload, len, out, sizeof out);
    ASSERT_EQ(write(fd, out, n), (ssize_t)n);
  }
  void command(int16_t throttle, int16_t steering, bool engaged) {
    protocol_command_t c = {};
    c.seq = ++cmd_seq;
    c.throttle_milli = throttle;
    c.steering_milli = steering;
    c.flags = engaged ? PROTOCOL_CMD_ENGAGED : 0;
    uint8_t p[PROTOCOL_LEN_COMMAND];
    protocol_command_pack(&c, p);
    send(PROTOCOL_ID_COMMAND, p, sizeof p);
  }
  int count(uint8_t id) const {
    int n = 0;
    for (const auto &f : frames) n += f.id == id;
    return n;
  }
  bool last_state(protocol_state_t *st) const {
    for (auto it = frames.rbegin(); it != frames.rend(); ++it)
      if (it->id == PROTOCOL_ID_STATE) return protocol_state_unpack(it->payload, it->len, st) == 0;
    return false;
  }
};

// Steps the sim for ms milliseconds while the client reads; a command every 20 ms if asked.
void pump(simtest::Sim &s, Client &c, int ms, int16_t thr = 0, int16_t steer = 0,
          int commands = 0) {
  for (int k = 0; k < ms; k++) {
    if (commands && k % 20 == 0) {
      c.command(thr, steer, commands > 0);
      sim_nano_wait_input(s.s, 1, 1000);  // the kernel delivers pty bytes asynchronously
    }
    ASSERT_TRUE(s.run_to(sim_time_us(s.s) * 1e-6 + 0.001)) << s.err;
    c.read_all();
  }
  // frames the sim wrote may still be in the kernel: collect them (waits, asserts nothing)
  pollfd p = {c.fd, POLLIN, 0};
  while (::poll(&p, 1, 50) > 0) c.read_all();
}

TEST(Nano, ProtocolConformanceOnThePty) {
  simtest::Sim s(nullptr, 1, 1);
  ASSERT_NE(s.s, nullptr) << s.err;
  const std::string link = s.run_dir + "/nigel1-nano";
  ASSERT_EQ(std::string(sim_nano_link(s.s, 1)), link);
  Client c(link.c_str());
  ASSERT_GE(c.fd, 0) << link;

  // handshake: HELLO carries our protocol version and schema hash
  c.send(PROTOCOL_ID_HELLO_REQUEST, nullptr, 0);
  sim_nano_wait_input(s.s, 1, 1000);
  pump(s, c, 100);
  ASSERT_GE(c.count(PROTOCOL_ID_HELLO), 1);
  protocol_hello_t h = {};
  for (const auto &f : c.frames) {
    if (f.id == PROTOCOL_ID_HELLO) {
      ASSERT_EQ(protocol_hello_unpack(f.payload, f.len, &h), 0);
    }
  }
  EXPECT_EQ(h.proto_version, PROTOCOL_VERSION);
  EXPECT_EQ(h.schema_hash, protocol_schema_hash());

  // telemetry at 100 Hz of sim time, no bad frames
  c.frames.clear();
  pump(s, c, 500);
  EXPECT_GE(c.count(PROTOCOL_ID_STATE), 45);
  EXPECT_LE(c.count(PROTOCOL_ID_STATE), 51);
  EXPECT_EQ(c.parser.stats.bad_crc, 0u);
  protocol_state_t st = {};
  ASSERT_TRUE(c.last_state(&st));
  EXPECT_EQ(st.mode, PROTOCOL_MODE_DISARMED);
  EXPECT_NEAR(st.accel_raw[2], PROTOCOL_ACCEL_LSB_PER_G, 250);  // sim IMU through the firmware

  // arm (engaged=0 then 1) and drive: the STATE reflects the command and the car moves
  pump(s, c, 40, 0, 0, -1);
  pump(s, c, 1500, 500, 200, 1);
  ASSERT_TRUE(c.last_state(&st));
  EXPECT_EQ(st.mode, PROTOCOL_MODE_ENGAGED);
  EXPECT_EQ(st.throttle_milli, 500);
  EXPECT_EQ(st.steering_milli, 200);
  EXPECT_EQ(st.faults & PROTOCOL_FAULT_LINK_LOST, 0);
  EXPECT_GT(s.truth().vel_body_m_s[0], 0.08);
  EXPECT_GT(st.enc_counts[0], 100);
  EXPECT_GT(st.wheel_speed_mrad_s[0], 1000);

  // a corrupted frame is counted by the Nano's parser and reported
  const uint16_t bad_before = st.frames_bad_crc;
  uint8_t junk[PROTOCOL_MAX_FRAME];
  protocol_command_t cmd = {};
  uint8_t p[PROTOCOL_LEN_COMMAND];
  protocol_command_pack(&cmd, p);
  const size_t n = protocol_frame_encode(PROTOCOL_ID_COMMAND, 200, p, sizeof p, junk, sizeof junk);
  junk[n - 1] ^= 0xFF;
  ASSERT_EQ(write(c.fd, junk, n), (ssize_t)n);
  sim_nano_wait_input(s.s, 1, 1000);
  pump(s, c, 100, 500, 200, 1);
  ASSERT_TRUE(c.last_state(&st));
  EXPECT_EQ((uint16_t)(st.frames_bad_crc - bad_before), 1);

  // the client goes quiet: failsafe within the timeout (100 ms default) plus the wire
  c.frames.clear();
  pump(s, c, 300);
  ASSERT_TRUE(c.last_state(&st));
  EXPECT_EQ(st.mode, PROTOCOL_MODE_FAILSAFE);
  EXPECT_NE(st.faults & PROTOCOL_FAULT_LINK_LOST, 0);
  EXPECT_EQ(st.throttle_milli, 0);
}

TEST(Nano, BytesArriveAtTheWireRate) {
  simtest::Sim s(nullptr, 1, 1);
  ASSERT_NE(s.s, nullptr) << s.err;
  Client c(sim_nano_link(s.s, 1));
  ASSERT_GE(c.fd, 0);
  // 20 COMMAND frames (16 bytes each) written at once: at 500000 baud 50 bytes per ms reach
  // the firmware, so no step may deliver more than 4 frames and all take >= 6 steps
  for (int i = 0; i < 20; i++) c.command(0, 0, false);
  sim_nano_wait_input(s.s, 1, 1000);
  const nano_core_t *n = sim_nano(s.s, 1);
  const uint32_t base = n->parser.stats.frames_ok;
  int steps_with_frames = 0, max_per_step = 0;
  for (int k = 0; k < 5000 && n->parser.stats.frames_ok - base < 20; k++) {
    const uint32_t before = n->parser.stats.frames_ok;
    ASSERT_TRUE(s.run_to(sim_time_us(s.s) * 1e-6 + 0.001)) << s.err;
    const int got = (int)(n->parser.stats.frames_ok - before);
    if (got > 0 || steps_with_frames > 0) steps_with_frames++;
    if (got > max_per_step) max_per_step = got;
  }
  EXPECT_EQ(n->parser.stats.frames_ok - base, 20u);
  EXPECT_LE(max_per_step, 4);
  EXPECT_GE(steps_with_frames, 6);
}

TEST(Nano, FailsafeStopsTheCarWhenTheDriverGoesQuiet) {
  simtest::Sim s("constant:throttle=0.8,steering=0,stop_after=1.5");
  ASSERT_NE(s.s, nullptr) << s.err;
  ASSERT_TRUE(s.run_to(1.5)) << s.err;
  const nano_core_t *n = sim_nano(s.s, 1);
  EXPECT_EQ(n->failsafe.mode, PROTOCOL_MODE_ENGAGED);
  EXPECT_GT(s.truth().vel_body_m_s[0], 0.15);
  ASSERT_TRUE(s.run_to(1.7)) << s.err;
  EXPECT_EQ(n->failsafe.mode, PROTOCOL_MODE_FAILSAFE);
  EXPECT_NE(nano_core_faults(n) & PROTOCOL_FAULT_LINK_LOST, 0);
  uint8_t duty, rev, brake;
  uint16_t servo;
  sim_motor_outputs(s.s, 1, &duty, &rev, &brake, &servo);
  EXPECT_EQ(brake, 1);
  ASSERT_TRUE(s.run_to(3.0)) << s.err;
  EXPECT_LT(fabs(s.truth().vel_body_m_s[0]), 0.005);
}

}  // namespace

namespace {

// Everything the emulated Nano sends during 1.5 s of scripted driving, read from its pty.
std::string nano_stream(uint64_t seed) {
  simtest::Sim s("constant:throttle=0.6,steering=0.3", 1, 1, -1, "parking_school", 0, seed);
  if (!s.s) return "error: " + s.err;
  const int fd = open(sim_nano_link(s.s, 1), O_RDWR | O_NOCTTY | O_NONBLOCK);
  if (fd < 0) return "error: open";
  termios t;
  tcgetattr(fd, &t);
  cfmakeraw(&t);
  tcsetattr(fd, TCSANOW, &t);
  std::string out;
  uint8_t buf[1024];
  for (int k = 1; k <= 1500; k++) {
    if (!s.run_to(0.001 * k)) return "error: " + s.err;
    ssize_t n;
    while ((n = read(fd, buf, sizeof buf)) > 0) out.append((const char *)buf, (size_t)n);
  }
  pollfd p = {fd, POLLIN, 0};
  while (::poll(&p, 1, 50) > 0) {  // what the kernel still holds (waits, asserts nothing)
    const ssize_t n = read(fd, buf, sizeof buf);
    if (n <= 0) break;
    out.append((const char *)buf, (size_t)n);
  }
  close(fd);
  return out;
}

// Same seed: the firmware's whole byte stream (STATE with IMU noise, AHRS, encoders) repeats
// exactly; another seed changes the IMU biases and noise, so the stream differs.
TEST(Nano, TelemetryIsDeterministicForASeed) {
  const std::string a = nano_stream(11), b = nano_stream(11), c = nano_stream(12);
  ASSERT_GT(a.size(), 140u * 67u) << a.substr(0, 200);  // ~150 STATE frames of 67 bytes
  EXPECT_TRUE(a == b) << "same seed, different telemetry";
  EXPECT_FALSE(a == c) << "the seed does not reach the IMU noise";
}

}  // namespace
