// autodrive-runtime as a program, with a camera whose GStreamer pipeline never starts (its one
// element sleeps 100 s before its first buffer, as a missing or unplugged Jetson camera holds
// cv::VideoCapture::open): the open times out with a message naming the pipeline, and SIGINT or
// SIGTERM still stops the process. Judged by event order (the message, then the exit after the
// signal) with generous bounds that only turn a hang into a failure.
#include <gtest/gtest.h>
#include <signal.h>
#include <unistd.h>

#include <chrono>
#include <fstream>
#include <functional>
#include <sstream>
#include <thread>

#include "child_process.hpp"

namespace {

const char *kPipeline =
    "videotestsrc is-live=true ! identity sleep-time=100000000 ! videoconvert ! appsink";

std::string read_file(const std::string &path) {
  std::ifstream f(path);
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

bool wait_until(const std::function<bool()> &pred, double max_s) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(max_s);
  while (std::chrono::steady_clock::now() < end) {
    if (pred()) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  return pred();
}

void stops_on(int signal_number) {
  const std::string base =
      "/tmp/adr-rt-stop-" + std::to_string(getpid()) + "-" + std::to_string(signal_number);
  const std::string config = base + ".yaml", log = base + ".log";
  {
    std::ofstream f(config);
    f << "lcm_url: \"memq://\"\nclock: wall\nvehicle: {name: STOPCAR}\n"
      << "cameras:\n  - {source: \"" << kPipeline << "\", channel: CAM_FRONT, rate_hz: 30,"
      << " open_timeout_ms: 300}\n";
  }
  autodrive::child_process::Child runtime(
      {AUTODRIVE_RUNTIME_EXE, "--config", config, "--only", "camera"}, log);
  // The open is reported, naming the pipeline and the timeout.
  ASSERT_TRUE(wait_until(
      [&] { return read_file(log).find("did not finish within 300 ms") != std::string::npos; },
      120.0))
      << read_file(log);
  const std::string text = read_file(log);
  EXPECT_NE(text.find(kPipeline), std::string::npos) << text;
  // The signal stops it, though the open is still blocked inside OpenCV.
  ASSERT_TRUE(runtime.running()) << text;
  ASSERT_EQ(::kill(runtime.pid(), signal_number), 0);
  EXPECT_TRUE(wait_until([&] { return !runtime.running(); }, 60.0))
      << "still running after the signal:\n"
      << read_file(log);
  ::unlink(config.c_str());
  ::unlink(log.c_str());
}

}  // namespace

TEST(RuntimeStop, SigintStopsItWhileACameraNeverOpens) {
  stops_on(SIGINT);
}

TEST(RuntimeStop, SigtermStopsItWhileACameraNeverOpens) {
  stops_on(SIGTERM);
}
