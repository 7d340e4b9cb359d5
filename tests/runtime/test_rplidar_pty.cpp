// The RPLIDAR driver against a pty peer that speaks the A1 protocol (health, scan, nodes),
// over real LCM UDP multicast; also with corruption injected into the node stream.
#include <gtest/gtest.h>
#include <lcm/lcm-cpp.hpp>
#include <unistd.h>

#include <autodrive/lidar_scan_t.hpp>

#include <atomic>
#include <chrono>
#include <cmath>
#include <functional>
#include <random>
#include <sstream>
#include <thread>

#include <spdlog/sinks/ostream_sink.h>
#include <spdlog/spdlog.h>

#include <autodrive/core/config.hpp>
#include <autodrive_lcm/subscribe.hpp>
#include <autodrive/devtools/fake_nano.hpp>
#include <autodrive/rplidar/rplidar_decoder.hpp>
#include <autodrive/rplidar/rplidar_driver.hpp>

namespace {

double room_m(int deg_cw) {
  return 0.5 + 0.01 * deg_cw;
}

// A1 emulation: answers GET_HEALTH with `health_status`, streams nodes after SCAN.
struct FakeRplidar {
  explicit FakeRplidar(const std::string &link) : pty(link) {}
  autodrive::devtools::PtyPeer pty;
  uint8_t health_status = 0;
  bool scanning = false;
  int resets = 0, scans = 0, healths = 0;
  int angle = 0;
  double corrupt_fraction = 0.0;
  bool sticky_error = false;  // health error after every reset (a broken or lying device)
  bool forge_health = false;  // a health-error packet after every 40 nodes (a forger)
  std::mt19937 rng{99};

  void pump() {
    const auto in = pty.read(2);
    for (std::size_t i = 0; i + 1 < in.size(); ++i) {
      if (in[i] != autodrive::rplidar::kCmdSync) continue;
      const uint8_t cmd = in[i + 1];
      if (cmd == autodrive::rplidar::kCmdGetHealth) {
        ++healths;
        pty.write({0xA5, 0x5A, 0x03, 0x00, 0x00, 0x00, 0x06, health_status, 0x01, 0x00});
        if (health_status == 2 && !sticky_error) health_status = 0;  // healthy after a reset
      } else if (cmd == autodrive::rplidar::kCmdScan) {
        ++scans;
        scanning = true;
        pty.write({0xA5, 0x5A, 0x05, 0x00, 0x00, 0x40, 0x81});
      } else if (cmd == autodrive::rplidar::kCmdStop) {
        scanning = false;
      } else if (cmd == autodrive::rplidar::kCmdReset) {
        ++resets;
        scanning = false;
      }
      ++i;
    }
    if (!scanning) return;
    std::vector<uint8_t> out;
    std::uniform_real_distribution<double> u(0.0, 1.0);
    for (int k = 0; k < 40; ++k) {  // 40 nodes per pump
      autodrive::rplidar::Node n{angle == 0, 40, static_cast<double>(angle),
                                 room_m(angle) * 1000.0};
      uint8_t b[5];
      autodrive::rplidar::encode_node(n, b);
      if (u(rng) < corrupt_fraction) b[rng() % 5] ^= static_cast<uint8_t>(1u << (rng() % 8));
      out.insert(out.end(), b, b + 5);
      angle = (angle + 1) % 360;
    }
    if (forge_health) {
      const uint8_t forged[] = {0xA5, 0x5A, 0x03, 0x00, 0x00, 0x00, 0x06, 0x02, 0x34, 0x12};
      out.insert(out.end(), forged, forged + sizeof forged);
    }
    pty.write(out);
  }
};

struct LidarHarness {
  explicit LidarHarness(int port)
      : link("/tmp/adr-rt-lidar-" + std::to_string(getpid()) + "-" + std::to_string(port)),
        fake(link),
        config(autodrive::config::parse(
            "lcm_url: \"udpm://239.255.76.67:" + std::to_string(port) +
                "?ttl=0\"\n"
                "clock: wall\n"
                "vehicle: {name: TESTCAR}\n"
                "lidar: {device: " +
                link + ", baud: 115200, range_min_m: 0.15, range_max_m: 12.0}\n",
            "test config")),
        lcm(config.lcm_url) {
    autodrive_lcm::subscribe<autodrive::lidar_scan_t, LidarHarness, &LidarHarness::on_scan>(
        lcm, "TESTCAR_LIDAR", this);
  }
  ~LidarHarness() {
    stop = true;
    if (th.joinable()) th.join();
  }
  void start() {
    driver = std::make_unique<autodrive::rplidar::Driver>(config);
    ASSERT_EQ(driver->init_error(), "");
    th = std::thread([this] { driver->run(stop); });
  }
  bool wait_for(const std::function<bool()> &pred, double max_s = 30.0) {
    const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(max_s);
    while (std::chrono::steady_clock::now() < end) {
      fake.pump();
      lcm.handleTimeout(1);
      if (pred()) return true;
    }
    return pred();
  }
  void on_scan(const autodrive::lidar_scan_t *m) { scans.push_back(*m); }
  int matching_bins(const autodrive::lidar_scan_t &s) const {
    int ok = 0;
    for (int a = 0; a < 360; ++a)
      ok += std::fabs(s.ranges_m[static_cast<std::size_t>((360 - a) % 360)] - room_m(a)) < 1e-3;
    return ok;
  }

  std::string link;
  FakeRplidar fake;
  autodrive::config::Config config;
  lcm::LCM lcm;
  std::vector<autodrive::lidar_scan_t> scans;
  std::unique_ptr<autodrive::rplidar::Driver> driver;
  std::atomic<bool> stop{false};
  std::thread th;
};

}  // namespace

TEST(RplidarPty, HealthScanAndPublish) {
  LidarHarness h(7770);
  h.fake.pty.open();
  h.start();
  ASSERT_TRUE(h.wait_for([&] { return h.scans.size() >= 3; }));
  EXPECT_GE(h.fake.healths, 1);
  EXPECT_GE(h.fake.scans, 1);
  for (const auto &s : h.scans) {
    EXPECT_EQ(s.num_ranges, 360);
    EXPECT_EQ(h.matching_bins(s), 360);
  }
}

TEST(RplidarPty, HealthErrorTriggersReset) {
  LidarHarness h(7771);
  h.fake.health_status = 2;
  h.fake.pty.open();
  h.start();
  ASSERT_TRUE(h.wait_for([&] { return h.scans.size() >= 1; }));
  EXPECT_GE(h.fake.resets, 1);
  EXPECT_GE(h.fake.healths, 2);
}

TEST(RplidarPty, CorruptedStreamStillPublishes) {
  LidarHarness h(7772);
  h.fake.corrupt_fraction = 0.02;
  h.fake.pty.open();
  h.start();
  ASSERT_TRUE(h.wait_for([&] { return h.scans.size() >= 5; }));
  int good = 0, total = 0;
  for (const auto &s : h.scans) {
    good += h.matching_bins(s);
    total += 360;
  }
  EXPECT_GT(good, total * 9 / 10);
  EXPECT_GT(h.driver->status().bad_nodes, 0u);
}

TEST(RplidarPty, ReopensAfterUnplug) {
  LidarHarness h(7773);
  h.fake.pty.open();
  h.start();
  ASSERT_TRUE(h.wait_for([&] { return h.scans.size() >= 1; }));
  h.fake.pty.close();
  ASSERT_TRUE(h.wait_for([&] { return h.driver->status().disconnects >= 1; }));
  h.fake.scanning = false;
  h.fake.pty.open();
  const std::size_t before = h.scans.size();
  ASSERT_TRUE(h.wait_for([&] { return h.scans.size() >= before + 2; }));
  EXPECT_GE(h.driver->status().opens, 2u);
}

// Probe findings: forged health packets gave one log line each and endless resets.
TEST(RplidarPty, HealthErrorFloodLimitsResets) {
  LidarHarness h(7783);
  h.fake.health_status = 2;
  h.fake.sticky_error = true;
  h.fake.pty.open();
  h.start();
  ASSERT_TRUE(h.wait_for([&] { return h.driver->status().resets_refused >= 1; }, 40.0));
  EXPECT_EQ(h.driver->status().resets, 3u);
  EXPECT_EQ(h.fake.resets, 3);
}

TEST(RplidarPty, ForgedHealthPacketsWhileScanningAreIgnoredAndLoggedAtALimitedRate) {
  // Capture the log: the driver logs through spdlog's default logger.
  std::ostringstream log;
  auto sink = std::make_shared<spdlog::sinks::ostream_sink_mt>(log);
  sink->set_pattern("%v");
  const auto previous = spdlog::default_logger();
  spdlog::set_default_logger(std::make_shared<spdlog::logger>("captured", sink));
  const auto t0 = std::chrono::steady_clock::now();
  uint64_t forged = 0;
  {
    LidarHarness h(7784);
    h.fake.forge_health = true;
    h.fake.pty.open();
    h.start();
    ASSERT_TRUE(h.wait_for([&] { return h.driver->status().unsolicited_health >= 50; }));
    EXPECT_EQ(h.fake.resets, 0);
    EXPECT_EQ(h.driver->status().resets, 0u);
    forged = h.driver->status().unsolicited_health;
  }
  const double elapsed_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  spdlog::set_default_logger(previous);
  std::istringstream in(log.str());
  int health_lines = 0;
  for (std::string line; std::getline(in, line);)
    health_lines += line.find("health") != std::string::npos;
  // 5 lines per 10 s and device, then one summary per 10 s: however long the run took on a
  // loaded machine (the limiter's periods are wall time), never one line per forged packet
  const int allowed = 6 * (1 + static_cast<int>(elapsed_s / 10.0));
  EXPECT_LE(health_lines, allowed) << elapsed_s << " s";
  EXPECT_LT(static_cast<uint64_t>(health_lines), forged);
  EXPECT_GE(health_lines, 1);
}
