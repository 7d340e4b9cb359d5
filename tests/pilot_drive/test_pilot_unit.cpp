// autodrive-pilot's pure parts: the speed rule, the sidecar reader's errors, the frame size
// check of the preprocessing, and the ONNX opset reader on hand-made protobuf bytes.
#include <autodrive/strict_yaml.hpp>
#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>
#include <string>

#include <autodrive/pilot/frame_watchdog.hpp>
#include <autodrive/pilot/pilot_model.hpp>
#include <autodrive/pilot/speed_rule.hpp>

namespace {

// The frame timeout on a sim clock the test advances (event order, no wall time): silence is
// counted in sim time, and a frozen sim clock is silence whatever the sim age.
TEST(FrameWatchdog, TimesOutInSimTimeAndOnAFrozenSimClock) {
  using autodrive::clock::Clock;
  Clock clock(autodrive::config::ClockMode::sim);
  autodrive::pilot::FrameWatchdog w(clock, 500);
  int64_t mono = 10000000;       // the backstop's monotonic time [us], moved by hand
  EXPECT_FALSE(w.silent(mono));  // no frame yet: not driving, nothing to time out
  ASSERT_TRUE(clock.set_sim_us(3000000, mono));
  w.frame();
  ASSERT_TRUE(clock.set_sim_us(3500000, mono));
  EXPECT_FALSE(w.silent(mono));  // 500 ms of sim time: still within
  ASSERT_TRUE(clock.set_sim_us(3500001, mono));
  EXPECT_TRUE(w.silent(mono));
  EXPECT_EQ(w.silent_ms(), 500);
  w.frame();
  EXPECT_FALSE(w.silent(mono));
  mono += Clock::kFrozenAfterUs + 1;  // no SIM_CLOCK since: the simulator froze
  EXPECT_TRUE(w.silent(mono));
}

TEST(SpeedRule, SlowsForSteeringAndHoldsTheSetSpeed) {
  autodrive::pilot::SpeedRuleConfig c;
  c.set_speed_m_s = 0.2;
  c.min_speed_m_s = 0.1;
  autodrive::pilot::SpeedRule r(c);
  EXPECT_DOUBLE_EQ(r.target_m_s(0.0), 0.2);
  EXPECT_DOUBLE_EQ(r.target_m_s(-1.0), 0.1);
  EXPECT_DOUBLE_EQ(r.target_m_s(0.5), 0.15);
  // at the target speed the throttle is the feed-forward; slower -> more, faster -> less
  const double at = r.throttle(0.0, 0.2, 0.0);
  EXPECT_NEAR(at, c.feedforward_per_m_s * 0.2, 1e-12);
  EXPECT_GT(r.throttle(0.0, 0.1, 0.0), at);
  EXPECT_LT(r.throttle(0.0, 0.3, 0.0), at);
  EXPECT_LT(r.throttle(1.0, 0.2, 0.0), at);  // full lock: slower target
  // the integral closes a steady error; the output stays in [0, max]
  double last = 0;
  for (int i = 0; i < 100; ++i) last = r.throttle(0.0, 0.15, 0.05);
  EXPECT_GT(last, c.feedforward_per_m_s * 0.2 + c.kp_per_m_s * 0.05);
  EXPECT_LE(r.throttle(0.0, -5.0, 0.05), c.max_throttle);
  EXPECT_GE(r.throttle(0.0, 5.0, 0.05), 0.0);
}

std::string write(const std::string &name, const std::string &text) {
  const std::string path = ::testing::TempDir() + name;
  std::ofstream(path, std::ios::binary) << text;
  return path;
}

TEST(Sidecar, ErrorsNameTheFileAndTheKey) {
  int opset = 0;
  std::string sha;
  const std::string good =
      R"({"input": {"source_width": 640, "source_height": 480, "crop_top_px": 200,
      "crop_bottom_px": 40, "width": 200, "height": 66, "colour": "yuv", "scale": 0.00392156862745098,
      "mean": [0.5, 0.5, 0.5], "std": [0.25, 0.25, 0.25]}, "opset": 11,
      "onnx_sha256": "0000000000000000000000000000000000000000000000000000000000000000"})";
  const auto spec = autodrive::pilot::read_sidecar(write("good.json", good), opset, sha);
  EXPECT_EQ(spec.height_px, 66);
  EXPECT_EQ(opset, 11);
  auto refused = [&](const std::string &text, const std::string &words) {
    const std::string path = write("bad.json", text);
    try {
      autodrive::pilot::read_sidecar(path, opset, sha);
      ADD_FAILURE() << "accepted: " << text;
    } catch (const autodrive::InputError &e) {
      EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find(words), std::string::npos) << e.what();
    }
  };
  refused("{", "not valid JSON");
  refused(R"({"opset": 11})", "input: missing key");
  std::string s = good;
  refused(s.replace(s.find("\"yuv\""), 5, "\"hsv\""), "input.colour");
  s = good;
  refused(s.replace(s.find("\"crop_bottom_px\": 40"), 20, "\"crop_bottom_px\": 400"),
          "input.crop_bottom_px");
  s = good;
  refused(s.replace(s.find("[0.25, 0.25, 0.25]"), 18, "[0.25, 0, 0.25]"), "input.std");
  EXPECT_THROW(autodrive::pilot::read_sidecar(::testing::TempDir() + "none.json", opset, sha),
               autodrive::InputError);
}

TEST(Preprocess, RefusesAFrameOfAnotherSize) {
  autodrive::pilot::InputSpec spec;
  spec.source_width_px = 640;
  spec.source_height_px = 480;
  spec.width_px = 200;
  spec.height_px = 66;
  spec.std = {1, 1, 1};
  const cv::Mat ok(480, 640, CV_8UC3, cv::Scalar(10, 20, 30));
  const cv::Mat blob = autodrive::pilot::preprocess(ok, spec);
  ASSERT_EQ(blob.dims, 4);
  EXPECT_EQ(blob.size[1], 3);
  EXPECT_EQ(blob.size[2], 66);
  EXPECT_EQ(blob.size[3], 200);
  EXPECT_THROW(autodrive::pilot::preprocess(cv::Mat(240, 320, CV_8UC3), spec),
               autodrive::InputError);
}

TEST(OnnxOpset, ReadsTheDefaultDomainAndRefusesTruncatedBytes) {
  // ModelProto: ir_version (1) = 7; opset_import (8) {domain "" , version 12}; a graph (7) of 3
  // bytes
  const std::string model("\x08\x07\x42\x02\x10\x0c\x3a\x03\x0a\x01\x78", 11);
  EXPECT_EQ(autodrive::pilot::onnx_opset("m.onnx", model), 12);
  try {
    autodrive::pilot::onnx_opset("m.onnx", model.substr(0, 9));
    ADD_FAILURE() << "truncated bytes accepted";
  } catch (const autodrive::InputError &e) {
    EXPECT_NE(std::string(e.what()).find("m.onnx: truncated"), std::string::npos) << e.what();
  }
  EXPECT_THROW(autodrive::pilot::onnx_opset("m.onnx", std::string("\x08\x07", 2)),
               autodrive::InputError);
}

}  // namespace
