// The runtime binary (autodrive-runtime, unchanged) end to end against each Nano backend
// that this build has, with the SAME test body: the real firmware ELF in simavr
// (nano-simavr) and the MuJoCo simulator's emulated Nano (autodrive-sim). Command in, state
// out (applied throttle/steering, engaged mode, encoder counts), stale commands disengage,
// reconnect after the backend restarts. Backend extras: motor PWM in nano-simavr's log; the
// runtime's RPLIDAR driver against the simulator's emulated A1.
// All waits are liveness bounds only; nothing asserts on wall time.
#include <gtest/gtest.h>
#include <lcm/lcm-cpp.hpp>
#include <sys/stat.h>
#include <unistd.h>

#include <autodrive/lidar_scan_t.hpp>
#include <autodrive/command_auth.hpp>
#include <autodrive/vehicle_command_t.hpp>
#include <autodrive/vehicle_state_t.hpp>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <memory>
#include <optional>
#include <sstream>
#include <thread>

#include "child_process.hpp"
#include <autodrive_lcm/subscribe.hpp>

namespace {

struct Backend {
  std::string name;
  int port;
  bool has_lidar;
};

std::vector<Backend> backends() {
  std::vector<Backend> b;
#ifdef NANO_SIMAVR_EXE
  b.push_back({"simavr", 7780, false});
#endif
#ifdef AUTODRIVE_SIM_EXE
  b.push_back({"sim", 7781, true});
#endif
  return b;
}

bool exists(const std::string &p) {
  struct stat st {};
  return ::stat(p.c_str(), &st) == 0;
}

class BackendE2E : public ::testing::TestWithParam<Backend> {
 protected:
  void SetUp() override {
    const Backend &b = GetParam();
    dir_ = "/tmp/adr-rt-e2e-" + b.name + "-" + std::to_string(getpid());
    ::mkdir(dir_.c_str(), 0755);
    url_ = "udpm://239.255.76.67:" + std::to_string(b.port) + "?ttl=0";
    nano_link_ = b.name == "sim" ? dir_ + "/nigel1-nano" : dir_ + "/nano";
    lidar_link_ = dir_ + "/nigel1-lidar";
    pwm_log_ = dir_ + "/pwm.log";
    lcm_ = std::make_unique<lcm::LCM>(url_);
    ASSERT_TRUE(lcm_->good());
    autodrive_lcm::subscribe<autodrive::vehicle_state_t, BackendE2E, &BackendE2E::on_state>(
        *lcm_, "E2E1_STATE", this);
    autodrive_lcm::subscribe<autodrive::lidar_scan_t, BackendE2E, &BackendE2E::on_scan>(
        *lcm_, "E2E1_LIDAR", this);
    autodrive_lcm::subscribe<autodrive::lidar_scan_t, BackendE2E, &BackendE2E::on_sim_scan>(
        *lcm_, "NIGEL1_LIDAR", this);
    // The runtime's config: only the device paths and the LCM URL differ from the car's.
    std::ofstream cfg(dir_ + "/runtime.yaml");
    cfg << "lcm_url: \"" << url_ << "\"\nclock: wall\n"
        << "vehicle: {name: E2E1}\n"
        << "bridge: {device: " << nano_link_ << ", baud: 500000, heartbeat_hz: 50,\n"
        << "         command_timeout_ms: 200, reconnect_ms: 200,\n"
        << "         command_key_file: " << dir_ << "/E2E1.key}\n";
    // The car's key (mode 0600): the bridge applies only commands signed with it.
    {
      std::ofstream k(dir_ + "/E2E1.key");
      k << std::string(64, 'e') << "\n";
    }
    std::filesystem::permissions(
        dir_ + "/E2E1.key",
        std::filesystem::perms::owner_read | std::filesystem::perms::owner_write,
        std::filesystem::perm_options::replace);
    signer_.emplace(autodrive::auth::load_key(dir_ + "/E2E1.key"), "E2E1", "e2e-test",
                    autodrive::auth::kAuthorityMachine);
    if (b.has_lidar)
      cfg << "lidar: {device: " << lidar_link_
          << ", baud: 115200, range_min_m: 0.15, range_max_m: 12.0}\n";
  }
  void TearDown() override {
    runtime_.reset();
    backend_.reset();
    // Keep the logs of a failed test for a post-mortem; otherwise leave nothing behind.
    if (!HasFailure()) {
      std::error_code ec;
      std::filesystem::remove_all(dir_, ec);
    }
  }

  void start_backend() {
    const Backend &b = GetParam();
    std::vector<std::string> argv;
#ifdef NANO_SIMAVR_EXE
    if (b.name == "simavr")
      argv = {NANO_SIMAVR_EXE, "--pty", nano_link_, "--encoder-hz", "400", "--pwm-log", pwm_log_};
#endif
#ifdef AUTODRIVE_SIM_EXE
    if (b.name == "sim")
      argv = {AUTODRIVE_SIM_EXE, "--run-dir", dir_, "--lcm-url", url_, "--quiet"};
#endif
    backend_ = std::make_unique<autodrive::child_process::Child>(
        argv, dir_ + "/backend-" + std::to_string(++starts_) + ".log");
    ASSERT_TRUE(wait_for([&] { return exists(nano_link_); }, 60)) << "no pty at " << nano_link_;
  }
  void start_runtime() {
    const std::string only = GetParam().has_lidar ? "bridge,lidar" : "bridge";
    runtime_ = std::make_unique<autodrive::child_process::Child>(
        std::vector<std::string>{AUTODRIVE_RUNTIME_EXE, "--config", dir_ + "/runtime.yaml",
                                 "--only", only},
        dir_ + "/runtime.log");
  }

  bool wait_for(const std::function<bool()> &pred, double max_s = 60.0,
                const std::function<void()> &each = nullptr) {
    const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(max_s);
    while (std::chrono::steady_clock::now() < end) {
      if (each) each();
      lcm_->handleTimeout(20);
      if (pred()) return true;
    }
    return pred();
  }
  void command(float throttle, float steering, bool engaged) {
    autodrive::vehicle_command_t c{};
    c.seq = seq_++;
    c.throttle = throttle;
    c.steering = steering;
    c.engaged = engaged;
    signer_->sign(c);
    lcm_->publish("E2E1_COMMAND", &c);
  }
  std::string log(const std::string &name) const {
    std::ifstream in(dir_ + "/" + name);
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
  }

  void on_state(const autodrive::vehicle_state_t *m) {
    states_.push_back(*m);
  }
  void on_scan(const autodrive::lidar_scan_t *m) {
    scans_.push_back(*m);
  }
  void on_sim_scan(const autodrive::lidar_scan_t *m) {
    sim_scans_.push_back(*m);
  }

  std::string dir_, url_, nano_link_, lidar_link_, pwm_log_;
  std::unique_ptr<lcm::LCM> lcm_;
  std::unique_ptr<autodrive::child_process::Child> backend_, runtime_;
  std::vector<autodrive::vehicle_state_t> states_;
  std::vector<autodrive::lidar_scan_t> scans_, sim_scans_;
  int32_t seq_ = 0;
  std::optional<autodrive::auth::Signer> signer_;
  int starts_ = 0;
};

TEST_P(BackendE2E, CommandInStateOutStaleDisengagesReconnects) {
  start_backend();
  start_runtime();
  // Handshake with the real firmware / the sim's Nano: telemetry arrives, the car boots silent.
  ASSERT_TRUE(wait_for([&] { return states_.size() >= 20; })) << log("runtime.log");
  EXPECT_NE(states_.back().mode, 1);
  EXPECT_EQ(states_.back().throttle_applied, 0.0f);
  const int32_t enc0 = states_.back().encoder_counts[0];

  // Command in -> applied state out (after the firmware's slew/rate limits), wheels turn.
  auto driving = [&] {
    const auto &s = states_.back();
    return s.mode == 1 && s.throttle_applied > 0.45f && s.steering_applied > 0.45f &&
           s.encoder_counts[0] > enc0 + 50;
  };
  ASSERT_TRUE(wait_for(driving, 60, [&] { command(0.5f, 0.5f, true); }))
      << "last state: mode " << int(states_.back().mode) << " throttle "
      << states_.back().throttle_applied << " steering " << states_.back().steering_applied
      << " enc " << states_.back().encoder_counts[0] << " (from " << enc0 << ")";

  // Stop publishing: the bridge's heartbeat goes on disengaged; the car stops.
  auto stopped = [&] {
    const auto &s = states_.back();
    return s.mode != 1 && s.throttle_applied == 0.0f;
  };
  ASSERT_TRUE(wait_for(stopped, 60));

  if (GetParam().name == "simavr") {
    // The motor PWM register moved with the command and came back to 0.
    std::istringstream in(log("pwm.log"));
    std::string line;
    bool drove = false, stopped_after = false;
    while (std::getline(in, line)) {
      std::istringstream f(line);
      double t_sim, t_mono, servo, duty;
      if (!(f >> t_sim >> t_mono >> servo >> duty)) continue;
      if (duty > 0)
        drove = true;
      else if (drove)
        stopped_after = true;
    }
    EXPECT_TRUE(drove) << log("pwm.log");
    EXPECT_TRUE(stopped_after);
  }

  // Restart the backend (sim restart / Nano reset + replug): the same runtime reconnects.
  backend_.reset();
  const std::size_t before = states_.size();
  lcm_->handleTimeout(100);
  start_backend();
  ASSERT_TRUE(wait_for([&] { return states_.size() >= before + 20; }, 90)) << log("runtime.log");
  EXPECT_TRUE(runtime_->running());
  const std::string rt = log("runtime.log");
  EXPECT_NE(rt.find("lost the Nano"), std::string::npos) << rt;
}

// Backends with an emulated RPLIDAR A1 (the simulator).
class LidarE2E : public BackendE2E {};

std::vector<Backend> lidar_backends() {
  std::vector<Backend> out;
  for (const auto &b : backends())
    if (b.has_lidar) out.push_back(b);
  return out;
}

TEST_P(LidarE2E, RplidarDriverAgainstEmulatedA1) {
  start_backend();
  // The simulator publishes NIGEL1_LIDAR itself only while no client scans its emulated A1:
  // take its scan first, then start the runtime's driver on the pty.
  ASSERT_TRUE(wait_for([&] { return !sim_scans_.empty(); }))
      << "no NIGEL1_LIDAR from the simulator";
  start_runtime();
  ASSERT_TRUE(wait_for([&] { return scans_.size() >= 5; }))
      << "driver scans " << scans_.size() << "\n"
      << log("runtime.log");
  // The car stands still: every ray the driver reports must equal the simulator's own
  // published scan (to the protocol's quarter-millimetre quantisation). The emulated A1, like
  // the real one, sends a fixed number of samples per second, so at 7 Hz a turn has fewer
  // than 360 nodes and some bins stay empty (+inf): most bins must be filled.
  const auto &ours = scans_.back();
  const auto &truth = sim_scans_.back();
  ASSERT_EQ(ours.num_ranges, 360);
  ASSERT_EQ(truth.num_ranges, 360);
  int truth_finite = 0, ours_finite = 0, match = 0;
  for (int i = 0; i < 360; ++i) {
    const float a = ours.ranges_m[static_cast<std::size_t>(i)];
    const float b = truth.ranges_m[static_cast<std::size_t>(i)];
    truth_finite += std::isfinite(b) ? 1 : 0;
    if (!std::isfinite(a)) continue;
    ++ours_finite;
    if (std::isfinite(b) && std::fabs(a - b) < 0.002f) ++match;
  }
  EXPECT_GT(truth_finite, 100);
  EXPECT_GE(ours_finite, truth_finite * 8 / 10);
  std::ostringstream diff;
  for (int i = 0; i < 360; i += 15)
    diff << i << ": " << ours.ranges_m[static_cast<std::size_t>(i)] << " vs "
         << truth.ranges_m[static_cast<std::size_t>(i)] << "\n";
  EXPECT_GE(match, ours_finite * 99 / 100) << "driver scan differs from the simulator's:\n"
                                           << diff.str();
}

std::string backend_name(const ::testing::TestParamInfo<Backend> &i) {
  return i.param.name;
}

INSTANTIATE_TEST_SUITE_P(Backends, BackendE2E, ::testing::ValuesIn(backends()), backend_name);
GTEST_ALLOW_UNINSTANTIATED_PARAMETERIZED_TEST(BackendE2E);
INSTANTIATE_TEST_SUITE_P(Backends, LidarE2E, ::testing::ValuesIn(lidar_backends()), backend_name);
GTEST_ALLOW_UNINSTANTIATED_PARAMETERIZED_TEST(LidarE2E);

}  // namespace
