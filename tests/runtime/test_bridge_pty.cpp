// The Nano bridge against a pty peer made of the shared proto codec (a fake Nano), over real
// LCM UDP multicast. No wall-time asserts: every wait is "until it happens" with a generous
// upper bound that only turns a hang into a failure.
#include <gtest/gtest.h>
#include <lcm/lcm-cpp.hpp>
#include <unistd.h>

#include <autodrive/command_auth.hpp>
#include <autodrive/control_status_t.hpp>
#include <autodrive/imu_t.hpp>
#include <autodrive/sim_clock_t.hpp>
#include <autodrive/vehicle_command_t.hpp>
#include <autodrive/vehicle_state_t.hpp>

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <sys/stat.h>

#include <atomic>
#include <chrono>
#include <fstream>
#include <functional>
#include <memory>
#include <thread>

#include <autodrive/nano_bridge/nano_bridge.hpp>
#include <autodrive/core/config.hpp>
#include <autodrive_lcm/subscribe.hpp>
#include <autodrive/devtools/fake_nano.hpp>

namespace {

// A test key file (mode 0600) for one harness; removed with it.
struct TestKey {
  explicit TestKey(const std::string &p, uint8_t fill = 0x5a) : path(p) {
    for (size_t i = 0; i < key.size(); ++i) key[i] = static_cast<uint8_t>(fill + i);
    std::ofstream f(path);
    for (uint8_t b : key) f << "0123456789abcdef"[b >> 4] << "0123456789abcdef"[b & 15];
    f << "\n";
    f.close();
    ::chmod(path.c_str(), 0600);
  }
  ~TestKey() { ::unlink(path.c_str()); }
  std::string path;
  autodrive::auth::Key key{};
};

std::string config_yaml(int port, const std::string &device, const std::string &key_file,
                        const std::string &clock) {
  const std::string sim_commands = clock == "sim" ? ", sim_clock_commands: true" : "";
  return "lcm_url: \"udpm://239.255.76.67:" + std::to_string(port) +
         "?ttl=0\"\n"
         "clock: " +
         clock +
         "\n"
         "vehicle: {name: TESTCAR}\n"
         "bridge: {device: " +
         device +
         ", baud: 500000, heartbeat_hz: 50,\n"
         "         command_timeout_ms: 200, hello_retry_ms: 50, refused_retry_ms: 50,\n"
         "         reconnect_ms: 50, link_timeout_ms: 2000, telemetry_period_ms: 10,\n"
         "         command_key_file: " +
         key_file + ", command_lease_ms: 300" + sim_commands +
         ",\n"
         "         imu: {gyro_var_rad2_s2: 0.0004}}\n";
}

class BridgeHarness {
 public:
  BridgeHarness(int port, uint32_t hash = protocol_schema_hash(), const std::string &clock = "wall")
      : link_("/tmp/adr-rt-test-" + std::to_string(getpid()) + "-" + std::to_string(port)),
        nano(link_, hash),
        key(link_ + ".key"),
        config(autodrive::config::parse(config_yaml(port, link_, key.path, clock), "test config")),
        lcm(config.lcm_url),
        signer(key.key, "TESTCAR", "test-autonomy", autodrive::auth::kAuthorityMachine) {
    autodrive_lcm::subscribe<autodrive::vehicle_state_t, BridgeHarness, &BridgeHarness::on_state>(
        lcm, "TESTCAR_STATE", this);
    autodrive_lcm::subscribe<autodrive::imu_t, BridgeHarness, &BridgeHarness::on_imu>(
        lcm, "TESTCAR_IMU", this);
    autodrive_lcm::subscribe<autodrive::control_status_t, BridgeHarness,
                             &BridgeHarness::on_control>(lcm, "TESTCAR_CONTROL", this);
  }
  ~BridgeHarness() {
    stop_ = true;
    if (thread_.joinable()) thread_.join();
  }
  void start() {
    bridge_ = std::make_unique<autodrive::bridge::NanoBridge>(config);
    ASSERT_EQ(bridge_->init_error(), "");
    thread_ = std::thread([this] { bridge_->run(stop_); });
  }
  autodrive::bridge::Status status() const { return bridge_->status(); }

  // Runs the fake Nano (telemetry every ~10 ms once it said hello) and the LCM side until
  // pred() holds; false after max_s seconds.
  bool wait_for(const std::function<bool()> &pred, double max_s = 20.0) {
    const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(max_s);
    while (std::chrono::steady_clock::now() < end) {
      if (nano.pty.is_open())
        nano.pump(5);
      else
        std::this_thread::sleep_for(std::chrono::milliseconds(5));
      if (send_states && nano.hellos_sent > 0 && nano.pty.is_open()) {
        protocol_state_t s{};
        s.nano_time_us = static_cast<uint32_t>(10000u * ++state_count_);
        s.enc_counts[0] = enc_left;
        s.enc_counts[1] = 2 * enc_left;
        s.throttle_milli = 250;
        s.gyro_raw[2] = 655;
        s.quat_q14[0] = PROTOCOL_QUAT_ONE;
        s.battery_mv = 11700;
        s.mode = PROTOCOL_MODE_ENGAGED;
        nano.send_state(s);
      }
      lcm.handleTimeout(1);
      if (pred()) return true;
    }
    return pred();
  }

  // An unsigned command.
  autodrive::vehicle_command_t command(float throttle, float steering, bool engaged,
                                       int8_t headlights = 1, int8_t indicators = 2) {
    autodrive::vehicle_command_t c{};
    c.seq = cmd_seq_++;
    c.throttle = throttle;
    c.steering = steering;
    c.headlights = headlights;
    c.indicators = indicators;
    c.engaged = engaged;
    return c;
  }
  // A command signed by the harness's source (the autonomy's role) with the car's key.
  void publish_command(float throttle, float steering, bool engaged, int8_t headlights = 1,
                       int8_t indicators = 2) {
    autodrive::vehicle_command_t c = command(throttle, steering, engaged, headlights, indicators);
    signer.sign(c);
    lcm.publish("TESTCAR_COMMAND", &c);
  }
  void publish_sim_clock(int64_t t_us) {
    autodrive::sim_clock_t m{};
    m.utime = t_us;
    m.real_time_factor = 1.0;
    lcm.publish("SIM_CLOCK", &m);
  }

  std::string link_;
  autodrive::devtools::FakeNano nano;
  TestKey key;
  autodrive::config::Config config;
  lcm::LCM lcm;
  autodrive::auth::Signer signer;
  std::vector<autodrive::control_status_t> controls;
  bool send_states = true;
  int32_t enc_left = 100;
  std::vector<autodrive::vehicle_state_t> states;
  std::vector<autodrive::imu_t> imus;

 private:
  void on_state(const autodrive::vehicle_state_t *m) { states.push_back(*m); }
  void on_imu(const autodrive::imu_t *m) { imus.push_back(*m); }
  void on_control(const autodrive::control_status_t *m) { controls.push_back(*m); }
  std::unique_ptr<autodrive::bridge::NanoBridge> bridge_;
  std::atomic<bool> stop_{false};
  std::thread thread_;
  int state_count_ = 0;
  int32_t cmd_seq_ = 0;
};

int count_engaged(const std::vector<protocol_command_t> &cmds, std::size_t from = 0) {
  int n = 0;
  for (std::size_t i = from; i < cmds.size(); ++i)
    n += (cmds[i].flags & PROTOCOL_CMD_ENGAGED) ? 1 : 0;
  return n;
}

}  // namespace

TEST(BridgePty, HandshakeThenStateAndImuPublished) {
  BridgeHarness h(7760);
  h.nano.open();
  h.start();
  ASSERT_TRUE(h.wait_for([&] { return h.states.size() >= 5 && h.imus.size() >= 5; }));
  EXPECT_EQ(h.status().state, autodrive::bridge::LinkState::linked);
  EXPECT_GE(h.nano.hello_requests, 1);
  // CONFIG sent after the handshake with the configured telemetry period.
  EXPECT_GE(h.nano.configs, 1);
  EXPECT_EQ(h.nano.last_config.telemetry_period_ms, 10);
  const auto &s = h.states.back();
  EXPECT_EQ(s.encoder_counts[0], 100);
  EXPECT_EQ(s.encoder_counts[1], 200);
  EXPECT_NEAR(s.throttle_applied, 0.25, 1e-6);
  EXPECT_NEAR(s.battery_voltage_v, 11.7, 1e-5);
  EXPECT_GT(s.host_frames_ok, 0);
  const auto &m = h.imus.back();
  EXPECT_NEAR(m.angular_velocity_rad_s[2], 10.0 * M_PI / 180.0, 1e-9);
  EXPECT_DOUBLE_EQ(m.angular_velocity_covariance[8], 0.0004);
}

TEST(BridgePty, SchemaMismatchRefused) {
  BridgeHarness h(7761, protocol_schema_hash() ^ 0x5A5A5A5Au);
  h.nano.open();
  h.start();
  ASSERT_TRUE(h.wait_for([&] { return h.status().refusals >= 1; }));
  // Keep the peer talking (HELLOs and STATE frames) for several more retries.
  const int hellos = h.nano.hello_requests;
  ASSERT_TRUE(h.wait_for([&] { return h.nano.hello_requests >= hellos + 3; }));
  const autodrive::bridge::Status st = h.status();
  EXPECT_EQ(st.state, autodrive::bridge::LinkState::refused);
  EXPECT_TRUE(h.nano.commands.empty()) << "commands sent to a mismatched Nano";
  EXPECT_TRUE(h.states.empty()) << "telemetry published from a mismatched Nano";
  // The message names both schema hashes and versions.
  char ours[16], theirs[16];
  std::snprintf(ours, sizeof ours, "0x%08x", protocol_schema_hash());
  std::snprintf(theirs, sizeof theirs, "0x%08x", protocol_schema_hash() ^ 0x5A5A5A5Au);
  EXPECT_NE(st.last_refusal.find(ours), std::string::npos) << st.last_refusal;
  EXPECT_NE(st.last_refusal.find(theirs), std::string::npos) << st.last_refusal;
  EXPECT_NE(st.last_refusal.find("firmware 1.2.3"), std::string::npos) << st.last_refusal;
  EXPECT_NE(st.last_refusal.find("protocol v1"), std::string::npos) << st.last_refusal;
}

TEST(BridgePty, CommandsForwarded) {
  BridgeHarness h(7762);
  h.nano.open();
  h.start();
  ASSERT_TRUE(h.wait_for([&] { return h.status().state == autodrive::bridge::LinkState::linked; }));
  // Heartbeat before any LCM command: frames flow, never engaged.
  ASSERT_TRUE(h.wait_for([&] { return h.nano.commands.size() >= 3; }));
  EXPECT_EQ(count_engaged(h.nano.commands), 0);
  auto found = [&] {
    for (const auto &c : h.nano.commands)
      if (c.throttle_milli == 500 && c.steering_milli == -250 && c.headlights == 1 &&
          c.indicators == 2 && (c.flags & PROTOCOL_CMD_ENGAGED))
        return true;
    return false;
  };
  ASSERT_TRUE(h.wait_for([&] {
    h.publish_command(0.5f, -0.25f, true);
    return found();
  }));
}

TEST(BridgePty, StaleCommandsDisengage) {
  BridgeHarness h(7763);
  h.nano.open();
  h.start();
  ASSERT_TRUE(h.wait_for([&] { return h.status().state == autodrive::bridge::LinkState::linked; }));
  ASSERT_TRUE(h.wait_for([&] {
    h.publish_command(0.4f, 0.1f, true);
    return count_engaged(h.nano.commands) >= 3;
  }));
  // Stop publishing: the heartbeat must go on, disengaged, throttle 0, lights kept.
  const std::size_t mark = h.nano.commands.size();
  auto disengaged_after_mark = [&] {
    for (std::size_t i = mark; i < h.nano.commands.size(); ++i) {
      const auto &c = h.nano.commands[i];
      if (!(c.flags & PROTOCOL_CMD_ENGAGED) && c.throttle_milli == 0) return true;
    }
    return false;
  };
  ASSERT_TRUE(h.wait_for(disengaged_after_mark));
  // Once disengaged it stays so while no command arrives.
  std::size_t first = mark;
  while (first < h.nano.commands.size() && (h.nano.commands[first].flags & PROTOCOL_CMD_ENGAGED))
    ++first;
  const std::size_t target = h.nano.commands.size() + 5;
  ASSERT_TRUE(h.wait_for([&] { return h.nano.commands.size() >= target; }));
  EXPECT_EQ(count_engaged(h.nano.commands, first), 0);
  EXPECT_EQ(h.nano.commands.back().headlights, 1);
  EXPECT_EQ(h.nano.commands.back().indicators, 2);
  // A fresh command re-engages.
  ASSERT_TRUE(h.wait_for([&] {
    h.publish_command(0.3f, 0.0f, true);
    return count_engaged(h.nano.commands, first) >= 1;
  }));
}

TEST(BridgePty, InvalidCommandsRejectedNotForwarded) {
  BridgeHarness h(7764);
  h.nano.open();
  h.start();
  ASSERT_TRUE(h.wait_for([&] { return h.status().state == autodrive::bridge::LinkState::linked; }));
  ASSERT_TRUE(h.wait_for([&] {
    h.publish_command(3.0f, 0.0f, true);  // throttle out of range
    return h.status().commands_rejected >= 3;
  }));
  EXPECT_EQ(count_engaged(h.nano.commands), 0);
}

TEST(BridgePty, ReconnectsAfterDeviceDisappears) {
  BridgeHarness h(7765);
  h.nano.open();
  h.start();
  ASSERT_TRUE(h.wait_for([&] { return h.states.size() >= 3; }));
  // Unplug: the device and its symlink vanish.
  h.nano.close();
  ASSERT_TRUE(h.wait_for([&] { return h.status().disconnects >= 1; }));
  EXPECT_EQ(h.status().state, autodrive::bridge::LinkState::no_device);
  // Replug (a new pty, as after a sim restart) with new telemetry values.
  h.enc_left = 5000;
  h.nano.hellos_sent = 0;
  h.nano.open();
  ASSERT_TRUE(
      h.wait_for([&] { return !h.states.empty() && h.states.back().encoder_counts[0] == 5000; }));
  const autodrive::bridge::Status st = h.status();
  EXPECT_EQ(st.state, autodrive::bridge::LinkState::linked);
  EXPECT_GE(st.opens, 2u);
  EXPECT_GE(st.handshakes, 2u);
  // Commands flow to the new device.
  h.nano.commands.clear();
  ASSERT_TRUE(h.wait_for([&] {
    h.publish_command(0.2f, 0.0f, true);
    return count_engaged(h.nano.commands) >= 1;
  }));
}

TEST(BridgePty, MissingDeviceRetriedUntilItAppears) {
  BridgeHarness h(7766);
  h.start();  // no device yet
  ASSERT_TRUE(
      h.wait_for([&] { return h.status().state == autodrive::bridge::LinkState::no_device; }, 5));
  h.nano.open();
  ASSERT_TRUE(h.wait_for([&] { return h.states.size() >= 2; }));
  EXPECT_EQ(h.status().opens, 1u);
}

// Probe finding: garbage on the Nano link gave no log line at all. It is counted (and logged
// at a limited rate, naming the device); telemetry between the garbage still flows, and a
// STATE whose fields are out of range is dropped, not published.
TEST(BridgePty, GarbageFromTheNanoIsCountedAndStateStillFlows) {
  BridgeHarness h(7785);
  h.nano.open();
  h.start();
  ASSERT_TRUE(h.wait_for([&] { return h.states.size() >= 3; }));
  std::vector<uint8_t> garbage(300);
  for (std::size_t i = 0; i < garbage.size(); ++i) garbage[i] = static_cast<uint8_t>(i * 37 + 11);
  for (int k = 0; k < 20; ++k) {
    h.nano.pty.write(garbage);
    const std::size_t before = h.states.size();
    ASSERT_TRUE(h.wait_for([&] { return h.states.size() > before; }));
  }
  const autodrive::bridge::Status st = h.status();
  EXPECT_GE(st.rx_skipped_bytes + st.rx_bad_crc + st.rx_bad_length, 20u);
  EXPECT_EQ(st.state, autodrive::bridge::LinkState::linked);
  // A STATE claiming 30x full steering is implausible: dropped and counted.
  h.send_states = false;
  protocol_state_t bad{};
  bad.steering_milli = 30000;
  bad.quat_q14[0] = PROTOCOL_QUAT_ONE;
  const uint64_t bad_before = h.status().rx_bad_payload;
  h.nano.send_state(bad);
  ASSERT_TRUE(h.wait_for([&] { return h.status().rx_bad_payload > bad_before; }));
  h.wait_for([] { return false; }, 0.2);
  for (const auto &s : h.states) EXPECT_LE(std::abs(s.steering_applied), 1.0f);
}

// ---- Command authentication (issue: only an authorised source can drive a car) ---------------

namespace {
bool any_frame_with_throttle(const std::vector<protocol_command_t> &cmds, int16_t milli,
                             std::size_t from = 0) {
  for (std::size_t i = from; i < cmds.size(); ++i)
    if (cmds[i].throttle_milli == milli && (cmds[i].flags & PROTOCOL_CMD_ENGAGED)) return true;
  return false;
}
}  // namespace

TEST(BridgeAuth, UnsignedAndWrongKeyCommandsIgnored) {
  BridgeHarness h(7767);
  h.nano.open();
  h.start();
  ASSERT_TRUE(h.wait_for([&] { return h.status().state == autodrive::bridge::LinkState::linked; }));
  // A hostile publisher: full throttle at full lock, unsigned ...
  ASSERT_TRUE(h.wait_for([&] {
    auto c = h.command(0.9f, -1.0f, true);
    c.source = "autonomy";  // claims a name, signs nothing
    c.authority = autodrive::auth::kAuthorityPerson;
    h.lcm.publish("TESTCAR_COMMAND", &c);
    return h.status().control.dropped_unsigned >= 5;
  }));
  // ... and signed with a key that is not the car's.
  autodrive::auth::Key wrong = h.key.key;
  wrong[0] ^= 1;
  autodrive::auth::Signer intruder(wrong, "TESTCAR", "intruder", autodrive::auth::kAuthorityPerson);
  ASSERT_TRUE(h.wait_for([&] {
    auto c = h.command(0.8f, 1.0f, true);
    intruder.sign(c);
    h.lcm.publish("TESTCAR_COMMAND", &c);
    return h.status().control.dropped_bad_mac >= 5;
  }));
  EXPECT_EQ(count_engaged(h.nano.commands), 0);
  EXPECT_EQ(h.status().control.applied, 0);
  EXPECT_EQ(h.status().holder, "");
  // Counted and named on <VEH>_CONTROL.
  ASSERT_TRUE(h.wait_for([&] {
    return !h.controls.empty() && h.controls.back().dropped_bad_mac >= 5 &&
           h.controls.back().last_dropped_source == "intruder";
  }));
  // The same command signed with the car's key drives: the gate is not simply closed.
  ASSERT_TRUE(h.wait_for([&] {
    h.publish_command(0.7f, 0.0f, true);
    return any_frame_with_throttle(h.nano.commands, 700);
  }));
  EXPECT_EQ(h.status().holder, "test-autonomy");
}

TEST(BridgeAuth, ReplayedCommandsIgnored) {
  BridgeHarness h(7768);
  h.nano.open();
  h.start();
  ASSERT_TRUE(h.wait_for([&] { return h.status().state == autodrive::bridge::LinkState::linked; }));
  // A recorded command of the real source ...
  auto recorded = h.command(0.35f, 0.2f, true);
  h.signer.sign(recorded);
  h.lcm.publish("TESTCAR_COMMAND", &recorded);
  ASSERT_TRUE(h.wait_for([&] { return any_frame_with_throttle(h.nano.commands, 350); }));
  // ... went stale (disengaged frames) ...
  ASSERT_TRUE(h.wait_for([&] {
    return !h.nano.commands.empty() && !(h.nano.commands.back().flags & PROTOCOL_CMD_ENGAGED);
  }));
  const std::size_t mark = h.nano.commands.size();
  // ... and is replayed, byte for byte, many times.
  ASSERT_TRUE(h.wait_for([&] {
    h.lcm.publish("TESTCAR_COMMAND", &recorded);
    return h.status().control.dropped_replay >= 20;
  }));
  // A validly signed command from a new source, but stamped outside the replay window (5 s old).
  auto old = h.command(0.45f, 0.0f, true);
  autodrive::auth::Signer other(h.key.key, "TESTCAR", "recorded-elsewhere",
                                autodrive::auth::kAuthorityMachine);
  other.sign(old);
  old.counter -= 5000000;
  const auto mac =
      autodrive::auth::mac_of(h.key.key, autodrive::auth::canonical_bytes(old, "TESTCAR"));
  std::copy(mac.begin(), mac.end(), old.mac);
  ASSERT_TRUE(h.wait_for([&] {
    h.lcm.publish("TESTCAR_COMMAND", &old);
    return h.status().control.dropped_replay >= 30;
  }));
  EXPECT_EQ(count_engaged(h.nano.commands, mark), 0);
  EXPECT_EQ(h.status().control.applied, 1);
}

TEST(BridgeAuth, LeaseTeleopTakesFromAutonomyAutonomyNeverFromTeleop) {
  BridgeHarness h(7769);
  h.nano.open();
  h.start();
  ASSERT_TRUE(h.wait_for([&] { return h.status().state == autodrive::bridge::LinkState::linked; }));
  autodrive::auth::Signer teleop(h.key.key, "TESTCAR", "test-teleop",
                                 autodrive::auth::kAuthorityPerson);
  auto teleop_cmd = [&](float throttle, bool engaged) {
    auto c = h.command(throttle, 0.0f, engaged);
    teleop.sign(c);
    h.lcm.publish("TESTCAR_COMMAND", &c);
  };
  // The autonomy drives.
  ASSERT_TRUE(h.wait_for([&] {
    h.publish_command(0.3f, 0.0f, true);
    return any_frame_with_throttle(h.nano.commands, 300);
  }));
  ASSERT_TRUE(h.wait_for(
      [&] { return !h.controls.empty() && h.controls.back().holder == "test-autonomy"; }));
  // The dead-man is pressed: the person takes control while the autonomy keeps sending.
  std::size_t mark = h.nano.commands.size();
  ASSERT_TRUE(h.wait_for([&] {
    h.publish_command(0.3f, 0.0f, true);
    teleop_cmd(0.6f, true);
    return any_frame_with_throttle(h.nano.commands, 600, mark);
  }));
  ASSERT_TRUE(h.wait_for([&] {
    return !h.controls.empty() && h.controls.back().holder == "test-teleop" &&
           h.controls.back().holder_authority == autodrive::auth::kAuthorityPerson;
  }));
  // Dead-man released (teleop sends disengaged): the autonomy, still sending engaged commands,
  // never gets the car back while the person holds control.
  ASSERT_TRUE(h.wait_for([&] {
    h.publish_command(0.3f, 0.0f, true);
    teleop_cmd(0.0f, false);
    return !h.nano.commands.empty() && !(h.nano.commands.back().flags & PROTOCOL_CMD_ENGAGED);
  }));
  mark = h.nano.commands.size();
  const int64_t not_holder0 = h.status().control.dropped_not_holder;
  ASSERT_TRUE(h.wait_for([&] {
    h.publish_command(0.3f, 0.0f, true);
    teleop_cmd(0.0f, false);
    return h.nano.commands.size() >= mark + 25;
  }));
  EXPECT_EQ(count_engaged(h.nano.commands, mark), 0);
  EXPECT_GT(h.status().control.dropped_not_holder, not_holder0);
  EXPECT_EQ(h.status().holder, "test-teleop");
  // Teleop quits: its lease lapses (published), then the autonomy may drive again.
  ASSERT_TRUE(h.wait_for([&] {
    h.publish_command(0.3f, 0.0f, true);
    return h.status().holder == "test-autonomy";
  }));
  bool lapsed_published = false;
  for (const auto &c : h.controls) lapsed_published = lapsed_published || c.holder.empty();
  EXPECT_TRUE(lapsed_published) << "the lapse of the person's lease was not published";
  EXPECT_GE(h.status().control.holder_changes, 4);  // autonomy, teleop, none, autonomy
}

TEST(BridgeAuth, FloodIsCappedAtTheBucketRate) {
  BridgeHarness h(7778);
  h.nano.open();
  h.start();
  ASSERT_TRUE(h.wait_for([&] { return h.status().state == autodrive::bridge::LinkState::linked; }));
  ASSERT_TRUE(h.wait_for([&] {
    h.publish_command(0.2f, 0.0f, true);
    return count_engaged(h.nano.commands) >= 1;
  }));
  // 4000 valid commands as fast as they go (each used to become a serial frame).
  const std::size_t mark = h.nano.commands.size();
  const auto t0 = std::chrono::steady_clock::now();
  for (int i = 0; i < 4000; ++i) {
    h.publish_command(0.2f, 0.0f, true);
    if (i % 50 == 0) h.nano.pump(0);
  }
  h.wait_for([] { return false; }, 0.2);
  const double elapsed_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const std::size_t frames = h.nano.commands.size() - mark;
  // At most the bucket's arithmetic over the time it took (burst + rate x time), with 3 frames
  // for the edges (written before the mark, read after it): a slow machine makes fewer
  // frames, never more.
  const auto &b = h.config.bridge;
  EXPECT_LE(static_cast<double>(frames), b.command_burst_frames + b.command_rate_hz * elapsed_s + 3)
      << frames << " COMMAND frames in " << elapsed_s << " s";
  EXPECT_GE(h.status().control.applied, 100);
  EXPECT_GT(h.status().commands_held, 0u) << "the flood never found the bucket empty";
}

TEST(BridgeAuth, StaleCommandNeverResentBeyondTheTimeout) {
  BridgeHarness h(7783);
  h.nano.open();
  h.start();
  ASSERT_TRUE(h.wait_for([&] { return h.status().state == autodrive::bridge::LinkState::linked; }));
  ASSERT_TRUE(h.wait_for([&] { return h.nano.commands.size() >= 3; }));
  // One burst of a few commands, then silence: the bridge sends the 3 at once, then repeats the
  // last only while it is younger than command_timeout_ms (200 ms at 50 Hz: 10 heartbeats),
  // then disengages and stays so, and the Nano's own failsafe timer runs out as designed.
  const std::size_t mark = h.nano.commands.size();
  for (int i = 0; i < 3; ++i) h.publish_command(1.0f, 0.0f, true);
  ASSERT_TRUE(h.wait_for([&] { return count_engaged(h.nano.commands, mark) >= 1; }));
  ASSERT_TRUE(h.wait_for([&] { return h.nano.commands.size() >= mark + 40; }));
  EXPECT_LE(count_engaged(h.nano.commands, mark), 3 + 200 / 20 + 1);
  EXPECT_FALSE(h.nano.commands.back().flags & PROTOCOL_CMD_ENGAGED);
}

TEST(BridgeAuth, UnicastUdpToTheLcmPortDoesNotDrive) {
  BridgeHarness h(7787);
  h.nano.open();
  h.start();
  ASSERT_TRUE(h.wait_for([&] { return h.status().state == autodrive::bridge::LinkState::linked; }));
  // Not a publisher at all: a plain UDP socket writes LCM's "LC02" packet of an engaged
  // full-throttle command to 127.0.0.1:<port>, which LCM's receive socket accepts.
  auto c = h.command(1.0f, 1.0f, true);
  c.source = "unicast";
  c.authority = autodrive::auth::kAuthorityPerson;
  std::vector<uint8_t> payload(static_cast<size_t>(c.getEncodedSize()));
  c.encode(payload.data(), 0, static_cast<int>(payload.size()));
  uint32_t seqno = 0;
  ASSERT_TRUE(h.wait_for([&] {
    // A new socket (source port) each time: the kernel may hand a unicast datagram to any
    // socket bound to the port, the bridge's or this harness's.
    const int fd = ::socket(AF_INET, SOCK_DGRAM, 0);
    sockaddr_in to{};
    to.sin_family = AF_INET;
    to.sin_port = htons(7787);
    to.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    std::vector<uint8_t> pkt = {0x4c, 0x43, 0x30, 0x32};
    ++seqno;
    for (int i = 3; i >= 0; --i) pkt.push_back(static_cast<uint8_t>(seqno >> (8 * i)));
    const std::string ch = "TESTCAR_COMMAND";
    pkt.insert(pkt.end(), ch.begin(), ch.end());
    pkt.push_back(0);
    pkt.insert(pkt.end(), payload.begin(), payload.end());
    ::sendto(fd, pkt.data(), pkt.size(), 0, reinterpret_cast<const sockaddr *>(&to), sizeof to);
    ::close(fd);
    return h.status().control.dropped_unsigned >= 3;
  }));
  EXPECT_EQ(count_engaged(h.nano.commands), 0);
  EXPECT_EQ(h.status().control.applied, 0);
  EXPECT_EQ(h.status().control.last_dropped_source, "unicast");
}

TEST(BridgePty, AFreshCommandGoesOutInThePassThatReceivedIt) {
  BridgeHarness h(7788);
  h.nano.open();
  h.start();
  ASSERT_TRUE(h.wait_for([&] { return h.status().state == autodrive::bridge::LinkState::linked; }));
  // Commands one at a time, each two heartbeats after the previous one's frame (so the bucket
  // has refilled: 2 tokens per heartbeat period at 100 Hz vs 50 Hz): every one is written in the
  // LCM callback that received it (commands_at_once), none waits for a heartbeat or a token.
  const uint64_t at_once = h.status().commands_at_once;
  for (int k = 0; k < 10; ++k) {
    const int16_t milli = static_cast<int16_t>(100 + 10 * k);
    const std::size_t mark = h.nano.commands.size();
    h.publish_command(milli / 1000.0f, 0.0f, true);
    std::size_t at = 0;
    ASSERT_TRUE(h.wait_for([&] {
      for (std::size_t i = mark; i < h.nano.commands.size(); ++i)
        if (h.nano.commands[i].throttle_milli == milli) return (at = i) > 0;
      return false;
    })) << "command "
        << k << " never reached the Nano";
    ASSERT_TRUE(h.wait_for([&] { return h.nano.commands.size() >= at + 3; }));
  }
  EXPECT_EQ(h.status().commands_at_once, at_once + 10);
  EXPECT_EQ(h.status().commands_held, 0u);
}

TEST(BridgePty, OnTheSimClockASilentSourceDisengagesAtItsTimeout) {
  // clock: sim: freshness and heartbeat follow SIM_CLOCK, which this test moves by hand.
  BridgeHarness h(7789, protocol_schema_hash(), "sim");
  h.nano.open();
  h.start();
  int64_t sim_us = 1000000;
  ASSERT_TRUE(h.wait_for([&] {
    h.publish_sim_clock(sim_us);
    return h.status().state == autodrive::bridge::LinkState::linked;
  }));
  // One command (more, still on their way, would be frames of their own later on).
  h.publish_command(0.4f, 0.0f, true);
  ASSERT_TRUE(h.wait_for([&] { return count_engaged(h.nano.commands) >= 1; }));
  // The source falls silent at sim time 1.0 s (command_timeout_ms 200). The next frame after a
  // SIM_CLOCK step is the heartbeat of that sim time.
  auto frame_after_step = [&](int64_t t_us) {
    const std::size_t mark = h.nano.commands.size();
    h.publish_sim_clock(t_us);
    EXPECT_TRUE(h.wait_for([&] { return h.nano.commands.size() > mark; }));
    return h.nano.commands.back();
  };
  const protocol_command_t young = frame_after_step(sim_us + 150000);
  EXPECT_TRUE(young.flags & PROTOCOL_CMD_ENGAGED) << "150 ms of sim time: still fresh";
  const protocol_command_t stale = frame_after_step(sim_us + 250000);
  EXPECT_FALSE(stale.flags & PROTOCOL_CMD_ENGAGED) << "250 ms of sim time: past the timeout";
  EXPECT_EQ(stale.throttle_milli, 0);
}

TEST(BridgePty, OnTheSimClockAStalledSimIsNotALostLink) {
  // clock: sim: a host too busy to step the sim is no lost link (link_timeout_ms 2000 of sim
  // time); a sim whose clock runs on while its Nano is silent is one.
  BridgeHarness h(7779, protocol_schema_hash(), "sim");
  h.nano.open();
  h.start();
  int64_t sim_us = 1000000;
  ASSERT_TRUE(h.wait_for([&] {
    h.publish_sim_clock(sim_us);
    return h.status().state == autodrive::bridge::LinkState::linked && h.states.size() >= 3;
  }));
  const int hellos = h.nano.hello_requests;
  h.send_states = false;  // the Nano falls silent, and so does the sim clock, for 3 s of wall time
  EXPECT_FALSE(h.wait_for([&] { return h.nano.hello_requests > hellos; }, 3.0))
      << "a stalled sim clock set off a handshake";
  EXPECT_EQ(h.status().state, autodrive::bridge::LinkState::linked);
  sim_us += 2500000;  // now 2.5 s of sim time pass with no frame from the Nano
  EXPECT_TRUE(h.wait_for([&] {
    h.publish_sim_clock(sim_us);
    return h.nano.hello_requests > hellos;
  })) << "a silent Nano on a running sim clock was never handshaken again";
}
