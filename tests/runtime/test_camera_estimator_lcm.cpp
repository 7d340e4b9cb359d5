// The camera driver on a video file and the estimator node on synthetic telemetry, both over
// real LCM UDP multicast.
#include <gtest/gtest.h>
#include <lcm/lcm-cpp.hpp>
#include <unistd.h>

#include <autodrive/camera_info_t.hpp>
#include <autodrive/compressed_image_t.hpp>
#include <autodrive/imu_t.hpp>
#include <autodrive/odometry_t.hpp>
#include <autodrive/pose2d_t.hpp>
#include <autodrive/vehicle_state_t.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>

#include <atomic>
#include <chrono>
#include <cmath>
#include <functional>
#include <map>
#include <thread>

#include <autodrive/camera/camera_driver.hpp>
#include <autodrive/core/config.hpp>
#include <autodrive_lcm/subscribe.hpp>
#include <autodrive/estimator/estimator_node.hpp>
#include <autodrive/v2x.hpp>

namespace {
std::string base_yaml(int port) {
  return "lcm_url: \"udpm://239.255.76.67:" + std::to_string(port) +
         "?ttl=0\"\n"
         "clock: wall\n"
         "vehicle: {name: TESTCAR}\n";
}

bool pump_until(lcm::LCM &lcm, const std::function<bool()> &pred, double max_s = 30.0,
                const std::function<void()> &each = nullptr) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(max_s);
  while (std::chrono::steady_clock::now() < end) {
    if (each) each();
    lcm.handleTimeout(10);
    if (pred()) return true;
  }
  return pred();
}

// Publishes e signed by `signer_name`'s certificate (the testbed's, tools/setup), stamped with
// its own utime; the Eye's by default, as autodrive-eye does.
void publish_pose(lcm::LCM &lcm, autodrive::pose2d_t &e, const std::string &signer_name = "EYE") {
  static std::map<std::string, std::optional<autodrive::v2x::Signer>> signers;
  auto &signer = signers[signer_name];
  if (!signer) signer = autodrive::v2x::Signer::load("test", signer_name);
  ASSERT_TRUE(signer.has_value()) << "tools/setup makes the testbed's certificates";
  signer->sign("TESTCAR_POSE_EYE", e, e.utime);
  lcm.publish("TESTCAR_POSE_EYE", &e);
}

struct Sink {
  std::vector<autodrive::compressed_image_t> images;
  std::vector<autodrive::camera_info_t> infos;
  std::vector<autodrive::odometry_t> odom, map;
  void on_image(const autodrive::compressed_image_t *m) { images.push_back(*m); }
  void on_info(const autodrive::camera_info_t *m) { infos.push_back(*m); }
  void on_odom(const autodrive::odometry_t *m) { odom.push_back(*m); }
  void on_map(const autodrive::odometry_t *m) { map.push_back(*m); }
};
}  // namespace

TEST(CameraLcm, VideoFilePublishedAsJpeg) {
  // A 20-frame 320x240 MJPG video, solid blue-green, as the capture source.
  const std::string video = "/tmp/adr-rt-cam-" + std::to_string(getpid()) + ".avi";
  {
    cv::VideoWriter w(video, cv::VideoWriter::fourcc('M', 'J', 'P', 'G'), 30, cv::Size(320, 240));
    ASSERT_TRUE(w.isOpened());
    for (int i = 0; i < 20; ++i) w.write(cv::Mat(240, 320, CV_8UC3, cv::Scalar(200, 120, 10)));
  }
  const autodrive::config::Config c =
      autodrive::config::parse(base_yaml(7774) + "cameras:\n  - {source: " + video +
                                   ", channel: CAM_FRONT, rate_hz: 30, width_px: 160,\n"
                                   "     height_px: 120, jpeg_quality: 90}\n",
                               "test config");
  lcm::LCM lcm(c.lcm_url);
  Sink sink;
  autodrive_lcm::subscribe<autodrive::compressed_image_t, Sink, &Sink::on_image>(
      lcm, "TESTCAR_CAM_FRONT", &sink);
  autodrive_lcm::subscribe<autodrive::camera_info_t, Sink, &Sink::on_info>(
      lcm, "TESTCAR_CAM_FRONT_INFO", &sink);
  autodrive::camera::CameraDriver driver(c, 0);
  ASSERT_EQ(driver.init_error(), "");
  std::atomic<bool> stop{false};
  std::thread th([&] { driver.run(stop); });
  // More frames than the file holds: the driver loops the file.
  const bool got = pump_until(lcm, [&] { return sink.images.size() >= 25 && !sink.infos.empty(); });
  stop = true;
  th.join();
  ::unlink(video.c_str());
  ASSERT_TRUE(got);
  const auto &img = sink.images.back();
  EXPECT_EQ(img.format, "jpeg");
  EXPECT_EQ(img.size_bytes, static_cast<int32_t>(img.data.size()));
  const cv::Mat decoded = cv::imdecode(img.data, cv::IMREAD_COLOR);
  ASSERT_EQ(decoded.cols, 160);
  ASSERT_EQ(decoded.rows, 120);
  const cv::Vec3b px = decoded.at<cv::Vec3b>(60, 80);
  EXPECT_NEAR(px[0], 200, 12);
  EXPECT_NEAR(px[1], 120, 12);
  EXPECT_NEAR(px[2], 10, 12);
  const auto &info = sink.infos.back();
  EXPECT_EQ(info.width_px, 160);
  EXPECT_EQ(info.distortion_model, "plumb_bob");
  EXPECT_NEAR(info.k[2], 80.0, 1e-9);
}

TEST(CameraLcm, MissingSourceIsRetriedNotFatal) {
  const autodrive::config::Config c = autodrive::config::parse(
      base_yaml(7775) +
          "cameras:\n  - {source: /nonexistent/video.avi, channel: CAM_FRONT, rate_hz: 30}\n",
      "test config");
  autodrive::camera::CameraDriver driver(c, 0);
  ASSERT_EQ(driver.init_error(), "");
  std::atomic<bool> stop{false};
  std::thread th([&] { driver.run(stop); });
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  stop = true;
  th.join();
  EXPECT_EQ(driver.frames_published(), 0u);
}

TEST(EstimatorLcm, TelemetryAndEyeToOdomAndMap) {
  const autodrive::config::Config c =
      autodrive::config::parse(base_yaml(7776) + "estimator: {rate_hz: 100}\n", "test config");
  lcm::LCM lcm(c.lcm_url);
  Sink sink;
  autodrive_lcm::subscribe<autodrive::odometry_t, Sink, &Sink::on_odom>(lcm, "TESTCAR_ODOM", &sink);
  autodrive_lcm::subscribe<autodrive::odometry_t, Sink, &Sink::on_map>(lcm, "TESTCAR_POSE_MAP",
                                                                       &sink);
  autodrive::estimator::EstimatorNode node(c);
  ASSERT_EQ(node.init_error(), "");
  std::atomic<bool> stop{false};
  std::thread th([&] { node.run(stop); });
  // A straight drive at 1 wheel revolution per second (0.204 m/s), 100 Hz telemetry stamped
  // 10 ms apart; Eye poses place the car at x = 2 m, y = 1 m, heading 90 deg.
  int k = 0;
  auto feed = [&] {
    autodrive::vehicle_state_t s{};
    s.utime = 1000000 + k * 10000LL;
    s.nano_time_us = k * 10000LL;
    s.encoder_counts[0] = s.encoder_counts[1] = k * 1920 / 100;
    lcm.publish("TESTCAR_STATE", &s);
    if (k % 10 == 0) {
      autodrive::pose2d_t e{};
      e.utime = s.utime;
      e.vehicle = "TESTCAR";
      e.x_m = 2.0;
      e.y_m = 1.0 + 0.204 * k * 0.01;
      e.yaw_rad = M_PI / 2;
      publish_pose(lcm, e);
    }
    ++k;
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  };
  const bool got = pump_until(
      lcm, [&] { return k >= 300 && sink.odom.size() > 200 && sink.map.size() > 50; }, 60, feed);
  stop = true;
  th.join();
  ASSERT_TRUE(got);
  const auto &o = sink.odom.back();
  EXPECT_EQ(o.frame_id, "odom");
  EXPECT_NEAR(o.vx_m_s, 2 * M_PI * 0.0325, 0.01);
  EXPECT_GT(o.x_m, 0.3);  // drove forward in its own frame
  EXPECT_NEAR(o.y_m, 0.0, 0.01);
  const auto &m = sink.map.back();
  EXPECT_EQ(m.frame_id, "map");
  EXPECT_NEAR(m.x_m, 2.0, 0.05);
  EXPECT_NEAR(m.yaw_rad, M_PI / 2, 0.05);
  EXPECT_GT(m.y_m, 1.3);
}

// Probe findings: a forged POSE_EYE stream moved the map pose 1,000 m; an encoder jump gave
// an odometry speed of 1,063 m/s. Both are refused by the running estimator and counted.
TEST(EstimatorLcm, ForgedPosesEncoderJumpsAndGyroSpikesAreRefused) {
  const autodrive::config::Config c =
      autodrive::config::parse(base_yaml(7786) + "estimator: {rate_hz: 100}\n", "test config");
  lcm::LCM lcm(c.lcm_url);
  Sink sink;
  autodrive_lcm::subscribe<autodrive::odometry_t, Sink, &Sink::on_odom>(lcm, "TESTCAR_ODOM", &sink);
  autodrive_lcm::subscribe<autodrive::odometry_t, Sink, &Sink::on_map>(lcm, "TESTCAR_POSE_MAP",
                                                                       &sink);
  autodrive::estimator::EstimatorNode node(c);
  ASSERT_EQ(node.init_error(), "");
  std::atomic<bool> stop{false};
  std::thread th([&] { node.run(stop); });
  int k = 0;
  auto feed = [&] {
    autodrive::vehicle_state_t s{};
    s.utime = 1000000 + k * 10000LL;
    s.nano_time_us = k * 10000LL;
    s.encoder_counts[0] = s.encoder_counts[1] = k * 1920 / 100;
    if (k == 150) s.encoder_counts[0] += 1000000;  // a glitch: ~1,000 m/s for 10 ms
    lcm.publish("TESTCAR_STATE", &s);
    autodrive::pose2d_t e{};
    e.utime = s.utime;
    e.vehicle = "TESTCAR";
    e.yaw_rad = M_PI / 2;
    if (k % 10 == 0) {  // the real Eye at 10 Hz
      e.x_m = 2.0;
      e.y_m = 1.0 + 0.204 * k * 0.01;
      publish_pose(lcm, e);
    }
    if (k > 100) {  // a forger with the Eye's own key at 100 Hz, 1,000 m away: the gate
      e.x_m = 1002.0;
      e.y_m = 1.0;
      publish_pose(lcm, e);
      // and forgers without it, 0.3 m off: unsigned, and signed by a car's certificate
      e.x_m = 2.3;
      autodrive::pose2d_t unsigned_pose = e;
      unsigned_pose.auth.clear();
      unsigned_pose.auth_len = 0;
      lcm.publish("TESTCAR_POSE_EYE", &unsigned_pose);
      publish_pose(lcm, e, "NIGEL1");
    }
    if (k == 200) {
      autodrive::imu_t imu{};
      imu.utime = s.utime;
      imu.angular_velocity_rad_s[2] = 1e6;
      lcm.publish("TESTCAR_IMU", &imu);
    }
    ++k;
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  };
  const bool got = pump_until(
      lcm, [&] { return k >= 300 && sink.odom.size() > 200 && sink.map.size() > 50; }, 60, feed);
  stop = true;
  th.join();
  ASSERT_TRUE(got);
  double max_speed = 0, max_map_x = 0;
  for (const auto &o : sink.odom) max_speed = std::max(max_speed, std::abs(o.vx_m_s));
  for (const auto &m : sink.map) max_map_x = std::max(max_map_x, m.x_m);
  EXPECT_LT(max_speed, 0.5);
  EXPECT_LT(max_map_x, 2.05);
  EXPECT_NEAR(sink.map.back().x_m, 2.0, 0.05);
  const autodrive::estimator::InputStats st = node.input_stats();
  EXPECT_GE(st.wheel_dropped, 1u);
  EXPECT_LE(st.wheel_dropped, 2u);  // the jump and the step back
  EXPECT_GE(st.poses_gated, 150u);
  EXPECT_GE(st.poses_unauthenticated, 300u);
  EXPECT_NE(st.poses_refused_by_reason.find("unsigned="), std::string::npos)
      << st.poses_refused_by_reason;
  EXPECT_NE(st.poses_refused_by_reason.find("wrong role for this channel="), std::string::npos)
      << st.poses_refused_by_reason;
  EXPECT_EQ(st.gyro_dropped, 1u);
  EXPECT_EQ(st.reacquired, 0u);
}

// A car knows its map pose only from the Eye (or a pose given with its uncertainty): before
// the first Eye pose no POSE_MAP at all (never the filter's origin), then one from that fix on.
TEST(EstimatorLcm, NoMapPoseBeforeTheFirstEyeFix) {
  const autodrive::config::Config c =
      autodrive::config::parse(base_yaml(7788) + "estimator: {rate_hz: 100}\n", "test config");
  lcm::LCM lcm(c.lcm_url);
  Sink sink;
  autodrive_lcm::subscribe<autodrive::odometry_t, Sink, &Sink::on_odom>(lcm, "TESTCAR_ODOM", &sink);
  autodrive_lcm::subscribe<autodrive::odometry_t, Sink, &Sink::on_map>(lcm, "TESTCAR_POSE_MAP",
                                                                       &sink);
  autodrive::estimator::EstimatorNode node(c);
  ASSERT_EQ(node.init_error(), "");
  std::atomic<bool> stop{false};
  std::thread th([&] { node.run(stop); });
  const int64_t first_fix_us = 1000000 + 150 * 10000LL;  // after 1.5 s of telemetry
  int k = 0;
  auto feed = [&] {
    autodrive::vehicle_state_t s{};
    s.utime = 1000000 + k * 10000LL;
    s.nano_time_us = k * 10000LL;
    lcm.publish("TESTCAR_STATE", &s);
    if (s.utime >= first_fix_us && k % 10 == 0) {
      autodrive::pose2d_t e{};
      e.utime = s.utime;
      e.vehicle = "TESTCAR";
      e.x_m = 2.0;
      e.y_m = -1.0;
      e.yaw_rad = 1.0;
      publish_pose(lcm, e);
    }
    ++k;
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  };
  const bool got = pump_until(
      lcm, [&] { return k >= 250 && sink.odom.size() > 200 && sink.map.size() > 20; }, 60, feed);
  stop = true;
  th.join();
  ASSERT_TRUE(got);
  for (const auto &m : sink.map) EXPECT_GE(m.utime, first_fix_us) << "a map pose before a fix";
  EXPECT_NEAR(sink.map.front().x_m, 2.0, 0.01);  // the first is the fix, not the origin
  EXPECT_NEAR(sink.map.front().y_m, -1.0, 0.01);
  EXPECT_NEAR(sink.map.front().yaw_rad, 1.0, 0.01);
}

// A start pose given with its uncertainty: the map filter starts there, as sure as it says.
TEST(EstimatorConfig, InitialPoseWithItsUncertainty) {
  const auto c = autodrive::config::parse(
      base_yaml(7788) +
          "estimator: {rate_hz: 100, initial_pose_map: [1, 2, 0.5], initial_pos_std_m: 0.02, "
          "initial_yaw_std_rad: 0.035}\n",
      "test config");
  ASSERT_TRUE(c.estimator.has_initial_pose_map);
  EXPECT_DOUBLE_EQ(c.estimator.initial_pos_std_m, 0.02);
  EXPECT_DOUBLE_EQ(c.estimator.initial_yaw_std_rad, 0.035);
  const auto d = autodrive::config::parse(base_yaml(7788) + "estimator: {rate_hz: 100}\n", "t");
  EXPECT_DOUBLE_EQ(d.estimator.initial_pos_std_m, d.estimator.eye_pos_std_m);  // the default
  EXPECT_THROW(autodrive::config::parse(
                   base_yaml(7788) + "estimator: {rate_hz: 100, initial_pos_std_m: -1}\n", "t"),
               autodrive::config::Error);
}
