// RPLIDAR A1 decoder on synthetic byte streams: good, chunked, corrupted (resync), health.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include <autodrive/rplidar/rplidar_decoder.hpp>

namespace {
using Bytes = std::vector<uint8_t>;

const Bytes kScanDescriptor = {0xA5, 0x5A, 0x05, 0x00, 0x00, 0x40, 0x81};

// Range the synthetic room returns at a device angle [mm]: a smooth function of the angle.
double room_mm(int deg_cw) {
  return 1000.0 + 5.0 * deg_cw;
}

// `turns` full turns of 360 nodes at whole degrees (cw), starting at 0 deg with the S flag.
std::vector<Bytes> node_bytes(int turns) {
  std::vector<Bytes> out;
  for (int t = 0; t < turns; ++t)
    for (int a = 0; a < 360; ++a) {
      autodrive::rplidar::Node n;
      n.start = a == 0;
      n.quality = 47;
      n.angle_deg = a;
      n.distance_mm = (a % 45 == 7) ? 0.0 : room_mm(a);  // a few "no return" rays
      Bytes b(5);
      autodrive::rplidar::encode_node(n, b.data());
      out.push_back(b);
    }
  return out;
}

struct Collector {
  autodrive::rplidar::Decoder dec;
  autodrive::rplidar::ScanAssembler asm_{autodrive::rplidar::ScanParams{}};
  std::vector<autodrive::lidar_scan_t> scans;
  int64_t t_us = 0;
  Collector() {
    dec.on_node = [this](const autodrive::rplidar::Node &n) {
      autodrive::lidar_scan_t s;
      t_us += 400;
      if (asm_.add(n, t_us, &s)) scans.push_back(s);
    };
  }
  void feed(const Bytes &b) { dec.feed(b.data(), b.size()); }
};

// Checks one scan against the synthetic room; returns the number of bins that match.
int matching_bins(const autodrive::lidar_scan_t &s) {
  int ok = 0;
  for (int a = 0; a < 360; ++a) {
    const int bin = (360 - a) % 360;  // device clockwise -> REP-103 counter-clockwise
    const float r = s.ranges_m[static_cast<std::size_t>(bin)];
    if (a % 45 == 7)
      ok += std::isinf(r) ? 1 : 0;
    else
      ok += std::fabs(r - room_mm(a) / 1000.0) < 1e-3 ? 1 : 0;
  }
  return ok;
}
}  // namespace

TEST(RplidarDecoder, NodeRoundTrip) {
  autodrive::rplidar::Node n{true, 15, 123.453125, 2345.25}, m;
  uint8_t b[5];
  autodrive::rplidar::encode_node(n, b);
  EXPECT_EQ(b[0] & 0x03, 0x01);  // S=1, !S=0
  EXPECT_EQ(b[1] & 0x01, 0x01);  // C=1
  ASSERT_TRUE(autodrive::rplidar::Decoder::decode_node(b, &m));
  EXPECT_TRUE(m.start);
  EXPECT_EQ(m.quality, 15);
  EXPECT_DOUBLE_EQ(m.angle_deg, 123.453125);
  EXPECT_DOUBLE_EQ(m.distance_mm, 2345.25);
}

TEST(RplidarDecoder, RejectsBadCheckBits) {
  uint8_t b[5];
  autodrive::rplidar::encode_node(autodrive::rplidar::Node{false, 10, 10.0, 500.0}, b);
  autodrive::rplidar::Node m;
  uint8_t bad[5];
  std::copy(b, b + 5, bad);
  bad[0] |= 0x03;  // S and !S both set
  EXPECT_FALSE(autodrive::rplidar::Decoder::decode_node(bad, &m));
  std::copy(b, b + 5, bad);
  bad[1] &= 0xFE;  // C cleared
  EXPECT_FALSE(autodrive::rplidar::Decoder::decode_node(bad, &m));
  std::copy(b, b + 5, bad);
  bad[2] = 0xFF;  // angle >= 360 deg
  EXPECT_FALSE(autodrive::rplidar::Decoder::decode_node(bad, &m));
}

TEST(RplidarDecoder, GoodStreamGivesFullScans) {
  Collector c;
  c.feed(kScanDescriptor);
  for (const auto &b : node_bytes(4)) c.feed(b);
  ASSERT_TRUE(c.dec.scanning());
  // Four turns: a scan is complete at each of the three later start flags.
  ASSERT_EQ(c.scans.size(), 3u);
  for (const auto &s : c.scans) {
    EXPECT_EQ(s.num_ranges, 360);
    EXPECT_EQ(matching_bins(s), 360);
    EXPECT_NEAR(s.angle_increment_rad, M_PI / 180.0, 1e-7);
    EXPECT_NEAR(s.scan_time_s, 360 * 400e-6, 1e-6);
  }
  EXPECT_EQ(c.dec.stats().bad_nodes, 0u);
  EXPECT_EQ(c.dec.stats().skipped_bytes, 0u);
}

TEST(RplidarDecoder, ChunkingDoesNotMatter) {
  Bytes all = kScanDescriptor;
  for (const auto &b : node_bytes(3)) all.insert(all.end(), b.begin(), b.end());
  Collector whole, bytewise;
  whole.feed(all);
  for (uint8_t x : all) bytewise.feed(Bytes{x});
  ASSERT_EQ(whole.scans.size(), 2u);
  ASSERT_EQ(bytewise.scans.size(), 2u);
  EXPECT_EQ(whole.scans[1].ranges_m, bytewise.scans[1].ranges_m);
}

TEST(RplidarDecoder, LeadingGarbageBeforeDescriptorSkipped) {
  Collector c;
  c.feed(Bytes{0x00, 0xA5, 0x13, 0x5A, 0xFF});
  c.feed(kScanDescriptor);
  for (const auto &b : node_bytes(2)) c.feed(b);
  EXPECT_EQ(c.scans.size(), 1u);
  EXPECT_EQ(c.dec.stats().skipped_bytes, 5u);
}

TEST(RplidarDecoder, ResyncsAfterInsertedBytes) {
  // Zero bytes fail the S/!S check, so the decoder must drop exactly those and lose no node.
  Collector c;
  c.feed(kScanDescriptor);
  int inserted = 0;
  int i = 0;
  for (const auto &b : node_bytes(3)) {
    c.feed(b);
    if (++i % 50 == 0) {
      c.feed(Bytes{0x00, 0x00, 0x00});
      inserted += 3;
    }
  }
  ASSERT_EQ(c.scans.size(), 2u);
  for (const auto &s : c.scans) EXPECT_EQ(matching_bins(s), 360);
  EXPECT_EQ(c.dec.stats().nodes, 3u * 360u - 1u);  // the last waits for its successor
  EXPECT_EQ(c.dec.stats().skipped_bytes, static_cast<uint64_t>(inserted));
}

TEST(RplidarDecoder, SurvivesRandomCorruption) {
  // Random byte flips and drops: the decoder must keep producing scans, mostly correct.
  std::mt19937 rng(1234);
  std::uniform_int_distribution<int> pct(0, 999), byte(0, 255);
  Bytes stream = kScanDescriptor;
  int corrupted = 0;
  for (const auto &b : node_bytes(20)) {
    Bytes n = b;
    const int r = pct(rng);
    if (r < 10) {
      n[static_cast<std::size_t>(pct(rng) % 5)] = static_cast<uint8_t>(byte(rng));  // 1% flips
      ++corrupted;
    } else if (r < 15) {
      n.erase(n.begin() + pct(rng) % 5);  // 0.5% lost bytes
      ++corrupted;
    }
    stream.insert(stream.end(), n.begin(), n.end());
  }
  Collector c;
  c.feed(stream);
  ASSERT_GT(corrupted, 50);
  ASSERT_GE(c.scans.size(), 15u);  // a few turns may lose their start node
  int good = 0, total = 0;
  for (const auto &s : c.scans) {
    good += matching_bins(s);
    total += 360;
  }
  EXPECT_GT(good, total * 95 / 100);
  EXPECT_GT(c.dec.stats().bad_nodes, 0u);
}

TEST(RplidarDecoder, HealthAnswerParsed) {
  autodrive::rplidar::Decoder d;
  std::vector<autodrive::rplidar::Health> got;
  d.on_health = [&](const autodrive::rplidar::Health &h) { got.push_back(h); };
  const Bytes health = {0xA5, 0x5A, 0x03, 0x00, 0x00, 0x00, 0x06, 0x02, 0x34, 0x12};
  d.feed(health.data(), health.size());
  ASSERT_EQ(got.size(), 1u);
  EXPECT_EQ(got[0].status, 2);
  EXPECT_EQ(got[0].error_code, 0x1234);
  EXPECT_FALSE(d.scanning());
}

TEST(RplidarDecoder, RequestBytes) {
  EXPECT_EQ(autodrive::rplidar::request(autodrive::rplidar::kCmdScan), (Bytes{0xA5, 0x20}));
  EXPECT_EQ(autodrive::rplidar::request(autodrive::rplidar::kCmdGetHealth), (Bytes{0xA5, 0x52}));
}

TEST(RplidarAssembler, MountYawAndRangeLimits) {
  autodrive::rplidar::ScanParams p;
  p.mount_yaw_rad = M_PI / 2;  // sensor 0 deg points left
  p.range_max_m = 2.0;
  autodrive::rplidar::ScanAssembler a(p);
  autodrive::lidar_scan_t s;
  auto range_at = [](int deg_cw) {
    if (deg_cw == 0) return 1000.0;
    if (deg_cw == 90) return 1500.0;   // cw 90 -> ccw 0 (forward)
    if (deg_cw == 180) return 2500.0;  // beyond range_max -> inf
    if (deg_cw == 270) return 0.0;     // distance 0 -> no return
    return 1800.0;
  };
  for (int d = 0; d < 360; ++d)
    EXPECT_FALSE(a.add({d == 0, 10, double(d), range_at(d)}, d * 1000, &s));
  ASSERT_TRUE(a.add({true, 10, 0.0, 1000.0}, 360000, &s));
  EXPECT_FLOAT_EQ(s.ranges_m[90], 1.0f);
  EXPECT_FLOAT_EQ(s.ranges_m[0], 1.5f);
  EXPECT_TRUE(std::isinf(s.ranges_m[270]));
  EXPECT_TRUE(std::isinf(s.ranges_m[180]));
  EXPECT_FLOAT_EQ(s.ranges_m[1], 1.8f);
  EXPECT_EQ(s.utime, 0);
  EXPECT_NEAR(s.scan_time_s, 0.36, 1e-6);
}

TEST(RplidarAssembler, FakeStartFlagMidTurnIgnored) {
  autodrive::rplidar::ScanAssembler a(autodrive::rplidar::ScanParams{});
  autodrive::lidar_scan_t s;
  int emitted = 0;
  for (int t = 0; t < 3; ++t)
    for (int d = 0; d < 360; ++d) {
      const bool fake = d == 120 || d == 15;  // S on a node far from 0, or too early in a turn
      emitted += a.add({d == 0 || fake, 10, double(d), 1000.0}, (t * 360 + d) * 1000, &s);
    }
  EXPECT_EQ(emitted, 2);
  EXPECT_NEAR(s.scan_time_s, 0.36, 1e-6);
}

// Three turns of an A1 whose angle steps by step_deg per node (+1: clockwise, as the device
// turns); node k carries 1000 + k mm.
struct Turns {
  autodrive::rplidar::Decoder d;
  autodrive::rplidar::ScanAssembler a{autodrive::rplidar::ScanParams{}};
  std::vector<autodrive::lidar_scan_t> scans;
  int64_t t = 0;
  explicit Turns(int step_deg) {
    d.on_node = [this](const autodrive::rplidar::Node &n) {
      autodrive::lidar_scan_t s;
      if (a.add(n, t += 1000, &s)) scans.push_back(s);
    };
    const uint8_t desc[7] = {0xA5, 0x5A, 0x05, 0x00, 0x00, 0x40, 0x81};
    d.feed(desc, 7);
    for (int turn = 0; turn < 3; ++turn)
      for (int k = 0; k < 360; ++k) {
        uint8_t b[5];
        autodrive::rplidar::encode_node(
            {k == 0, 10, double((360 + step_deg * k) % 360), 1000.0 + k}, b);
        d.feed(b, 5);
      }
  }
};

TEST(RplidarAssembler, ClockwiseTurnsBecomeCounterClockwiseScans) {
  // The device's angle grows clockwise; the scan (REP-103) counts counter-clockwise: the node
  // at device angle k deg lands in bin (360 - k) % 360.
  Turns turns(+1);
  ASSERT_EQ(turns.scans.size(), 2u);
  for (int k = 0; k < 360; ++k)
    EXPECT_NEAR(turns.scans[0].ranges_m[static_cast<std::size_t>((360 - k) % 360)],
                1.0 + k / 1000.0, 1e-6)
        << "device angle " << k;
}
