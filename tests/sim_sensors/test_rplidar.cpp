// The emulated RPLIDAR A1 on a real pty: a client speaks the serial protocol through the
// symlink. Time is the sim clock passed to sim_rplidar_poll, never the wall clock.
#include <gtest/gtest.h>
#include <fcntl.h>
#include <termios.h>
#include <unistd.h>

#include <cmath>
#include <string>
#include <vector>

#include "room.hpp"

extern "C" {
#include "sim_lidar.h"
#include "sim_rplidar.h"
}

namespace {

struct Client {
  int fd = -1;
  explicit Client(const std::string &path) {
    fd = open(path.c_str(), O_RDWR | O_NOCTTY | O_NONBLOCK);
    EXPECT_GE(fd, 0) << path;
    termios t;
    if (fd >= 0 && tcgetattr(fd, &t) == 0) {
      cfmakeraw(&t);
      cfsetispeed(&t, B115200);
      cfsetospeed(&t, B115200);
      tcsetattr(fd, TCSANOW, &t);
    }
  }
  ~Client() {
    if (fd >= 0) close(fd);
  }
  void send(std::vector<uint8_t> b) { ASSERT_EQ(write(fd, b.data(), b.size()), (ssize_t)b.size()); }
  void drain(std::vector<uint8_t> &into) {
    uint8_t buf[4096];
    for (;;) {
      ssize_t n = read(fd, buf, sizeof buf);
      if (n <= 0) break;
      into.insert(into.end(), buf, buf + n);
    }
  }
};

struct Device {
  std::string dir, link;
  sim_rplidar_t *r = nullptr;
  int64_t now_us = 0;
  Device() {
    char tmpl[] = "/tmp/sim_rplidar_test_XXXXXX";
    dir = mkdtemp(tmpl);
    link = dir + "/nigel1-lidar";
    char err[256] = "";
    r = sim_rplidar_create(link.c_str(), SIM_RPLIDAR_BAUD, err, sizeof err);
    EXPECT_NE(r, nullptr) << err;
  }
  ~Device() {
    sim_rplidar_destroy(r);
    EXPECT_NE(access(link.c_str(), F_OK), 0) << "symlink left behind";
    rmdir(dir.c_str());
  }
  // advances the sim clock in 1 ms steps, polling the device and collecting client bytes
  void run_ms(int ms, Client &c, std::vector<uint8_t> &rx) {
    for (int i = 0; i < ms; i++) {
      now_us += 1000;
      char err[256];
      ASSERT_EQ(sim_rplidar_poll(r, now_us, err, sizeof err), 0) << err;
      c.drain(rx);
    }
  }
};

const std::vector<uint8_t> kScanDescriptor = {0xA5, 0x5A, 0x05, 0x00, 0x00, 0x40, 0x81};

// A device asked to SCAN by its client; ranges[i] = 1 + 0.01 i m, so a node's distance says
// which ray it carries.
struct ScanSession {
  Device dev;
  Client c{dev.link};
  std::vector<uint8_t> rx;
  std::vector<float> ranges = std::vector<float>(360);
  ScanSession() {
    for (int i = 0; i < 360; i++) ranges[i] = 1.0f + i * 0.01f;
    c.send({0xA5, 0x20});
    dev.run_ms(1, c, rx);
  }
};

}  // namespace

TEST(SimRplidar, SymlinkPointsAtPty) {
  Device dev;
  ASSERT_NE(dev.r, nullptr);
  char target[256] = {0};
  ASSERT_GT(readlink(dev.link.c_str(), target, sizeof target - 1), 0);
  EXPECT_EQ(std::string(target), sim_rplidar_slave_path(dev.r));
  EXPECT_EQ(std::string(target).rfind("/dev/pts/", 0), 0u);
}

TEST(SimRplidar, HealthAndInfo) {
  Device dev;
  ASSERT_NE(dev.r, nullptr);
  Client c(dev.link);
  std::vector<uint8_t> rx;
  c.send({0xA5, 0x52});
  dev.run_ms(5, c, rx);
  ASSERT_EQ(rx.size(), 10u);
  EXPECT_EQ(rx, (std::vector<uint8_t>{0xA5, 0x5A, 0x03, 0x00, 0x00, 0x00, 0x06, 0, 0, 0}));
  rx.clear();
  c.send({0xA5, 0x50});
  dev.run_ms(5, c, rx);
  ASSERT_EQ(rx.size(), 27u);
  EXPECT_EQ(std::vector<uint8_t>(rx.begin(), rx.begin() + 7),
            (std::vector<uint8_t>{0xA5, 0x5A, 0x14, 0x00, 0x00, 0x00, 0x04}));
  EXPECT_EQ(rx[7], 0x18);  // model A1M8
  // garbage and a payload command with a bad checksum are ignored, counted, and harmless
  rx.clear();
  c.send({0x00, 0x13, 0xA5, 0xF0, 0x02, 0x94, 0x02, 0x00});
  c.send({0xA5, 0x52});
  dev.run_ms(5, c, rx);
  EXPECT_EQ(rx.size(), 10u);
  sim_rplidar_stats_t st;
  sim_rplidar_get_stats(dev.r, &st);
  EXPECT_EQ(st.bad_requests, 1u);
}

TEST(SimRplidar, ScanNodesDecodeToTheLidarScanAndStop) {
  room::Room room;
  ASSERT_NE(room.m, nullptr);
  sim_lidar_config_t cfg;
  sim_lidar_config_default(&cfg);
  char err[256];
  sim_lidar_t *l = sim_lidar_create(room.m, "car", &cfg, err, sizeof err);
  ASSERT_NE(l, nullptr) << err;
  sim_lidar_scan_now(room.m, room.d, l, 0);
  const sim_lidar_scan_t *s = sim_lidar_last_scan(l);

  Device dev;
  ASSERT_NE(dev.r, nullptr);
  Client c(dev.link);
  std::vector<uint8_t> rx;
  sim_rplidar_push_scan(dev.r, s->ranges_m, s->intensities, s->num_rays);  // not scanning yet
  dev.run_ms(5, c, rx);
  EXPECT_TRUE(rx.empty());
  c.send({0xA5, 0x20});
  dev.run_ms(2, c, rx);
  EXPECT_TRUE(sim_rplidar_scanning(dev.r));
  sim_rplidar_push_scan(dev.r, s->ranges_m, s->intensities, s->num_rays);
  sim_rplidar_push_scan(dev.r, s->ranges_m, s->intensities, s->num_rays);
  // 2 revolutions = 3600 bytes + 7: at 115200 baud (11520 B/s) that is ~313 ms of wire time
  dev.run_ms(200, c, rx);
  const size_t after_200ms = rx.size();
  // paced like a UART: never more than the wire carries in 202 ms plus the idle credit (20 ms)
  EXPECT_LE(after_200ms, (size_t)(0.222 * 11520));
  EXPECT_GT(after_200ms, (size_t)(0.190 * 11520));
  dev.run_ms(200, c, rx);
  ASSERT_EQ(rx.size(), 7u + 2 * 360 * 5);
  EXPECT_EQ(std::vector<uint8_t>(rx.begin(), rx.begin() + 7), kScanDescriptor);
  for (int rev = 0; rev < 2; rev++) {
    for (int k = 0; k < 360; k++) {
      const uint8_t *n = rx.data() + 7 + (rev * 360 + k) * 5;
      const int start = n[0] & 1, inv = (n[0] >> 1) & 1, q = n[0] >> 2;
      ASSERT_EQ(start, !inv) << "node " << k;
      EXPECT_EQ(start, k == 0 ? 1 : 0) << "node " << k;
      ASSERT_EQ(n[1] & 1, 1) << "check bit, node " << k;
      const double angle_deg = ((n[1] >> 1) | (n[2] << 7)) / 64.0;
      const double dist_mm = (n[3] | (n[4] << 8)) / 4.0;
      // the head turns clockwise like a real A1: node k is at device angle k deg, which is the
      // scan's ray at CCW angle (360 - k) % 360 deg
      EXPECT_NEAR(angle_deg, k, 1.0 / 64) << "node " << k;
      EXPECT_NEAR(dist_mm, s->ranges_m[(360 - k) % 360] * 1000.0, 0.125 + 1e-3) << "node " << k;
      EXPECT_EQ(q, 47) << "node " << k;
    }
  }
  c.send({0xA5, 0x25});  // STOP
  sim_rplidar_push_scan(dev.r, s->ranges_m, s->intensities, s->num_rays);
  rx.clear();
  dev.run_ms(100, c, rx);
  EXPECT_FALSE(sim_rplidar_scanning(dev.r));
  EXPECT_TRUE(rx.empty()) << rx.size() << " bytes after STOP";
  sim_rplidar_stats_t st;
  sim_rplidar_get_stats(dev.r, &st);
  EXPECT_EQ(st.nodes_tx, 720u);
  sim_lidar_destroy(l);
}

// At 7 Hz the 115200-baud wire cannot carry 360 nodes per revolution: the device sends fewer,
// evenly spread (like the real A1's fixed sample rate), never dropping a block of angles.
TEST(SimRplidar, SevenHertzScansAreThinnedEvenlyNotCut) {
  ScanSession ss;
  ASSERT_NE(ss.dev.r, nullptr);
  std::vector<uint8_t> &rx = ss.rx;
  for (int rev = 0; rev < 21; rev++) {  // 3 s at 7 Hz, one scan pushed per revolution
    sim_rplidar_push_scan(ss.dev.r, ss.ranges.data(), nullptr, 360);
    ss.dev.run_ms(rev % 7 == 6 ? 142 : 143, ss.c, rx);  // 1/7 s in whole ms
  }
  ASSERT_GT(rx.size(), 7u);
  EXPECT_EQ(std::vector<uint8_t>(rx.begin(), rx.begin() + 7), kScanDescriptor);
  const size_t nodes = (rx.size() - 7) / 5;
  std::vector<int> rev_sizes;
  int max_gap_rays = 0, prev_ray = -1;
  for (size_t k = 0; k < nodes; k++) {
    const uint8_t *n = rx.data() + 7 + 5 * k;
    const double dist_m = (n[3] | (n[4] << 8)) / 4000.0;
    const int ray = (int)std::lround((dist_m - 1.0) / 0.01);  // which ray this node carries
    const double angle_deg = ((n[1] >> 1) | (n[2] << 7)) / 64.0;
    ASSERT_NEAR(angle_deg, std::fmod(360.0 - ray, 360.0), 1.0 / 64) << "node " << k;
    if (n[0] & 1) {
      rev_sizes.push_back(0);
      prev_ray = -1;
    }
    if (!rev_sizes.empty()) rev_sizes.back()++;
    const int step = (360 - ray) % 360;  // clockwise sweep step of this ray
    if (prev_ray >= 0) max_gap_rays = std::max(max_gap_rays, step - prev_ray);
    prev_ray = step;
  }
  ASSERT_GE(rev_sizes.size(), 15u);
  // after the first (full) revolution: 97 % of 2304 nodes/s over 1/7 s, i.e. ~319..322 nodes
  for (size_t i = 1; i + 1 < rev_sizes.size(); i++) {
    EXPECT_GE(rev_sizes[i], 315) << "revolution " << i;
    EXPECT_LE(rev_sizes[i], 325) << "revolution " << i;
  }
  EXPECT_LE(max_gap_rays, 2);  // evenly thinned: never more than one ray skipped in a row
  sim_rplidar_stats_t st;
  sim_rplidar_get_stats(ss.dev.r, &st);
  EXPECT_EQ(st.nodes_dropped, 0u);
}

TEST(SimRplidar, SlowWireDropsOldNodesAndClientHangupStops) {
  Device dev;
  ASSERT_NE(dev.r, nullptr);
  std::vector<float> ranges(360, 1.0f);
  {
    Client c(dev.link);
    std::vector<uint8_t> rx;
    c.send({0xA5, 0x20});
    dev.run_ms(1, c, rx);
    for (int i = 0; i < 5; i++) sim_rplidar_push_scan(dev.r, ranges.data(), nullptr, 360);
    sim_rplidar_stats_t st;
    sim_rplidar_get_stats(dev.r, &st);
    EXPECT_GE(st.nodes_dropped, 3u * 360 - 10);
  }
  // the client closed the pty: the device stops scanning, as if unplugged
  char err[256];
  dev.now_us += 1000;
  ASSERT_EQ(sim_rplidar_poll(dev.r, dev.now_us, err, sizeof err), 0) << err;
  EXPECT_FALSE(sim_rplidar_scanning(dev.r));
}

// Garbage from the client (random bytes, random scans pushed meanwhile) never breaks the
// device: afterwards, padding, STOP and GET_HEALTH get the exact health answer. Under ASan
// this also checks the parser and the node queue for memory errors.
TEST(SimRplidar, RandomBytesNeverBreakTheParser) {
  Device dev;
  ASSERT_NE(dev.r, nullptr);
  Client c(dev.link);
  std::vector<uint8_t> rx;
  std::vector<float> ranges(360);
  uint64_t x = 0x12345678abcdefull;
  auto next = [&x]() {
    x ^= x << 13;
    x ^= x >> 7;
    x ^= x << 17;
    return x;
  };
  for (int round = 0; round < 400; round++) {
    std::vector<uint8_t> junk(next() % 64);
    for (auto &b : junk) {
      uint64_t v = next();
      b = (v & 7) == 0 ? 0xA5 : (uint8_t)(v >> 8);  // plenty of sync bytes
    }
    if (!junk.empty()) c.send(junk);
    if (next() % 8 == 0) {
      for (auto &r : ranges) r = (float)(next() % 20000) / 1000.0f;
      sim_rplidar_push_scan(dev.r, ranges.data(), nullptr, 360);
    }
    dev.run_ms(1 + (int)(next() % 5), c, rx);
  }
  // resynchronise: enough padding to end any half-received payload request, then STOP
  c.send(std::vector<uint8_t>(300, 0x00));
  c.send({0xA5, 0x25});
  dev.run_ms(500, c, rx);  // drains whatever was still queued
  rx.clear();
  c.send({0xA5, 0x52});
  dev.run_ms(5, c, rx);
  EXPECT_EQ(rx, (std::vector<uint8_t>{0xA5, 0x5A, 0x03, 0x00, 0x00, 0x00, 0x06, 0, 0, 0}));
  EXPECT_FALSE(sim_rplidar_scanning(dev.r));
}

TEST(SimRplidar, EncodeNodeLayout) {
  uint8_t n[5];
  sim_rplidar_encode_node(n, 1, 47, 90.0, 1234.5);
  EXPECT_EQ(n[0], (47 << 2) | 1);
  const int a = (n[1] >> 1) | (n[2] << 7);
  EXPECT_EQ(a, 90 * 64);
  EXPECT_EQ(n[1] & 1, 1);
  EXPECT_EQ(n[3] | (n[4] << 8), 4938);
  sim_rplidar_encode_node(n, 0, 0, 360.0, INFINITY);
  EXPECT_EQ(n[0], 2);
  EXPECT_EQ((n[1] >> 1) | (n[2] << 7), 0);
  EXPECT_EQ(n[3] | (n[4] << 8), 0);
}

TEST(SimRplidar, RefusesToReplaceARegularFile) {
  char tmpl[] = "/tmp/sim_rplidar_test_XXXXXX";
  std::string dir = mkdtemp(tmpl);
  std::string path = dir + "/not-a-link";
  FILE *f = fopen(path.c_str(), "w");
  ASSERT_NE(f, nullptr);
  fclose(f);
  char err[256] = "";
  EXPECT_EQ(sim_rplidar_create(path.c_str(), SIM_RPLIDAR_BAUD, err, sizeof err), nullptr);
  EXPECT_NE(std::string(err).find(path), std::string::npos) << err;
  unlink(path.c_str());
  rmdir(dir.c_str());
}

// Streamed like the real A1 (rays pushed as the head passes them): a revolution's first node
// reaches the client a few ms after it is measured, not one revolution (143 ms) later, and
// the thinning is the same as for whole-revolution pushes.
TEST(SimRplidar, StreamedRaysArriveWhileTheHeadSpins) {
  ScanSession ss;
  ASSERT_NE(ss.dev.r, nullptr);
  std::vector<uint8_t> &rx = ss.rx;
  std::vector<int64_t> start_pushed_ms, start_seen_ms;
  size_t parsed = 7;  // after the descriptor
  int next_ray = 0;
  for (int ms = 0; ms < 3000; ms++) {  // 3 s at 7 Hz: ray i is due at i / 360 / 7 s
    const int due = std::min(360, static_cast<int>((ms % 143 + 1) * 360 / 143));
    if (ms % 143 == 0) {
      next_ray = 0;
      start_pushed_ms.push_back(ms);
    }
    sim_rplidar_push_rays(ss.dev.r, ss.ranges.data(), nullptr, next_ray, due, 360);
    next_ray = std::max(next_ray, due);
    ss.dev.run_ms(1, ss.c, rx);
    for (; parsed + 5 <= rx.size(); parsed += 5)
      if (rx[parsed] & 1) start_seen_ms.push_back(ms);
  }
  ASSERT_GE(start_seen_ms.size(), 15u);
  // The queue never holds more than about one ray's worth of lag beyond the wire's own
  // pace: every revolution start is on the wire within 20 ms of being measured [ms].
  for (size_t k = 1; k < start_seen_ms.size(); k++) {
    const auto pushed = *std::prev(
        std::upper_bound(start_pushed_ms.begin(), start_pushed_ms.end(), start_seen_ms[k]));
    EXPECT_LE(start_seen_ms[k] - pushed, 20) << "revolution " << k;
  }
}
