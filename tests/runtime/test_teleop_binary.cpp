// autodrive-teleop as a program: its gamepad path reads Linux joystick events (js_event) from
// a FIFO standing in for /dev/input/js0; dead-man held -> engaged commands, released ->
// disengaged, over real LCM UDP multicast.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <lcm/lcm-cpp.hpp>
#include <linux/joystick.h>
#include <sys/stat.h>
#include <unistd.h>

#include <autodrive/command_auth.hpp>
#include <autodrive/vehicle_command_t.hpp>

#include <chrono>
#include <fstream>
#include <functional>

#include "child_process.hpp"
#include <autodrive_lcm/subscribe.hpp>

namespace {
struct Commands {
  std::vector<autodrive::vehicle_command_t> got;
  void on(const autodrive::vehicle_command_t *m) { got.push_back(*m); }
};

void send_js(int fd, uint8_t type, uint8_t number, int16_t value) {
  js_event e{};
  e.type = type;
  e.number = number;
  e.value = value;
  ASSERT_EQ(::write(fd, &e, sizeof e), static_cast<ssize_t>(sizeof e));
}

bool pump_until(lcm::LCM &lcm, const std::function<bool()> &pred, double max_s = 30.0) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(max_s);
  while (std::chrono::steady_clock::now() < end) {
    lcm.handleTimeout(20);
    if (pred()) return true;
  }
  return pred();
}
}  // namespace

TEST(TeleopBinary, GamepadDeadmanEngagesAndReleaseStops) {
  const std::string fifo = "/tmp/adr-rt-js-" + std::to_string(getpid());
  ::unlink(fifo.c_str());
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  const int w = ::open(fifo.c_str(), O_RDWR | O_NONBLOCK);  // keeps a writer for the test's life
  ASSERT_GE(w, 0);
  const std::string url = "udpm://239.255.76.67:7777?ttl=0";
  lcm::LCM lcm(url);
  Commands cmds;
  autodrive_lcm::subscribe<autodrive::vehicle_command_t, Commands, &Commands::on>(
      lcm, "JS1_COMMAND", &cmds);
  // The car's key: teleop signs every command with it (a person's authority).
  const std::string key_file = fifo + ".key";
  {
    std::ofstream k(key_file);
    k << std::string(64, 'c') << "\n";
  }
  ::chmod(key_file.c_str(), 0600);
  autodrive::child_process::Child teleop(
      {AUTODRIVE_TELEOP_EXE, "--vehicle", "JS1", "--lcm-url", url, "--joystick", fifo,
       "--no-keyboard", "--max-throttle", "0.5", "--key-file", key_file},
      fifo + ".log");
  // Released: commands flow, disengaged.
  ASSERT_TRUE(pump_until(lcm, [&] { return cmds.got.size() >= 5; }));
  EXPECT_FALSE(cmds.got.back().engaged);
  const autodrive::auth::Key key = autodrive::auth::load_key(key_file);
  EXPECT_EQ(cmds.got.back().source, "teleop");
  EXPECT_EQ(cmds.got.back().authority, autodrive::auth::kAuthorityPerson);
  EXPECT_EQ(autodrive::auth::check_mac(key, "JS1", cmds.got.back()), autodrive::auth::MacCheck::ok);
  EXPECT_LT(cmds.got[cmds.got.size() - 2].counter, cmds.got.back().counter);
  // Stick up, steer right, hold the dead-man (button 4), headlights (button 0).
  send_js(w, JS_EVENT_AXIS, 1, -32767);
  send_js(w, JS_EVENT_AXIS, 3, 32767);
  send_js(w, JS_EVENT_BUTTON, 4, 1);
  send_js(w, JS_EVENT_BUTTON, 0, 1);
  ASSERT_TRUE(pump_until(lcm, [&] { return !cmds.got.empty() && cmds.got.back().engaged; }));
  const auto held = cmds.got.back();
  EXPECT_NEAR(held.throttle, 0.5, 1e-3);
  EXPECT_NEAR(held.steering, -1.0, 1e-3);
  EXPECT_EQ(held.headlights, 1);
  // Release the dead-man: stop.
  send_js(w, JS_EVENT_BUTTON, 4, 0);
  ASSERT_TRUE(pump_until(lcm, [&] { return !cmds.got.back().engaged; }));
  EXPECT_EQ(cmds.got.back().throttle, 0.0f);
  EXPECT_EQ(cmds.got.back().headlights, 1);  // lights stay as set
  // Quit while engaged (the dead-man held again): the last command it sends is disengaged.
  send_js(w, JS_EVENT_BUTTON, 4, 1);
  ASSERT_TRUE(pump_until(lcm, [&] { return cmds.got.back().engaged; }));
  teleop.stop();
  while (lcm.handleTimeout(300) > 0) {
  }  // every command it sent before it ended
  EXPECT_FALSE(cmds.got.back().engaged);
  ::close(w);
  ::unlink(fifo.c_str());
  ::unlink((fifo + ".log").c_str());
  ::unlink(key_file.c_str());
}

// --keys-stdin: the key bytes a program writes into teleop's standard input (autodrive-sim's
// window in manual mode) drive as a terminal's do, signed as a person; the end of the input
// quits, with a last disengaged command.
TEST(TeleopBinary, KeysFromAPipeDriveAndTheirEndQuits) {
  const std::string fifo = "/tmp/adr-rt-keys-" + std::to_string(getpid());
  ::unlink(fifo.c_str());
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  // close-on-exec: teleop must not inherit a writer of its own input
  const int w = ::open(fifo.c_str(), O_RDWR | O_NONBLOCK | O_CLOEXEC);
  ASSERT_GE(w, 0);
  const std::string url = "udpm://239.255.76.67:7777?ttl=0";
  lcm::LCM lcm(url);
  Commands cmds;
  autodrive_lcm::subscribe<autodrive::vehicle_command_t, Commands, &Commands::on>(
      lcm, "KEYS1_COMMAND", &cmds);
  const std::string key_file = fifo + ".key";
  {
    std::ofstream k(key_file);
    k << std::string(64, 'd') << "\n";
  }
  ::chmod(key_file.c_str(), 0600);
  autodrive::child_process::Child teleop(
      {"/bin/sh", "-c",
       std::string("exec ") + AUTODRIVE_TELEOP_EXE + " --keys-stdin --vehicle KEYS1 --lcm-url '" +
           url + "' --key-file " + key_file + " --key-repeat-delay-ms 200 --key-hold-ms 300 < " +
           fifo},
      fifo + ".log");
  ASSERT_TRUE(pump_until(lcm, [&] { return cmds.got.size() >= 5; }));
  EXPECT_FALSE(cmds.got.back().engaged);
  // w held (repeated every 50 ms): engaged forward at the keyboard's drive level
  const auto t_end = std::chrono::steady_clock::now() + std::chrono::seconds(30);
  while (std::chrono::steady_clock::now() < t_end && !(cmds.got.back().engaged)) {
    ASSERT_EQ(::write(w, "w", 1), 1);
    lcm.handleTimeout(50);
  }
  ASSERT_TRUE(cmds.got.back().engaged);
  EXPECT_GT(cmds.got.back().throttle, 0.0f);
  EXPECT_EQ(cmds.got.back().source, "teleop");
  EXPECT_EQ(cmds.got.back().authority, autodrive::auth::kAuthorityPerson);
  EXPECT_EQ(
      autodrive::auth::check_mac(autodrive::auth::load_key(key_file), "KEYS1", cmds.got.back()),
      autodrive::auth::MacCheck::ok);
  // the writer closes: teleop ends on its own, its last command disengaged
  ::close(w);
  const auto quit_by = std::chrono::steady_clock::now() + std::chrono::seconds(30);
  while (teleop.running() && std::chrono::steady_clock::now() < quit_by) lcm.handleTimeout(50);
  EXPECT_FALSE(teleop.running()) << "teleop did not quit at the end of its input";
  while (lcm.handleTimeout(300) > 0) {
  }
  EXPECT_FALSE(cmds.got.back().engaged);
  ::unlink(fifo.c_str());
  ::unlink((fifo + ".log").c_str());
  ::unlink(key_file.c_str());
}
