// autodrive-eye as a user runs it: calibrate-intrinsics -> calibrate-map -> run on an image
// folder, and run on the LCM image channel over real UDP multicast (port 7790).
#include <gtest/gtest.h>
#include <lcm/lcm-cpp.hpp>
#include <autodrive/compressed_image_t.hpp>
#include <autodrive/eye_camera_status_t.hpp>
#include <autodrive_channels.h>
#include <autodrive/pose2d_t.hpp>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <sstream>
#include <thread>

#include "eye_render.hpp"
#include "eye_synth.hpp"
#include "eye_mapcal.hpp"
#include "eye_test_util.hpp"

namespace fs = std::filesystem;

namespace {

// Runs a shell command, returns its exit status and stdout (stderr folded in).
int run(const std::string &cmd, std::string *out) {
  FILE *p = popen((cmd + " 2>&1").c_str(), "r");
  if (!p) return -1;
  char buf[4096];
  out->clear();
  size_t n;
  while ((n = fread(buf, 1, sizeof buf, p)) > 0) out->append(buf, n);
  const int st = pclose(p);
  return WIFEXITED(st) ? WEXITSTATUS(st) : -1;
}

std::string fresh_dir(const std::string &name) {
  const fs::path d = fs::path(testing::TempDir()) / name;
  fs::remove_all(d);
  fs::create_directories(d);
  return d.string();
}

void write_reftags(const std::string &path, const std::vector<eye::RefTag> &refs) {
  std::ofstream f(path);
  f << "tags:\n";
  for (const auto &r : refs)
    f << " - {id: " << r.id << ", x_m: " << r.x_m << ", y_m: " << r.y_m << ", z_m: " << r.z_m
      << ", yaw_rad: " << r.yaw_rad << ", size_m: " << r.size_m << "}\n";
}

void write_config(const std::string &path, const eye::SynthScene &s, const std::string &url) {
  std::ofstream f(path);
  f << "intrinsics: camera.yaml\nmap: map.yaml\nlcm_url: \"" << url << "\"\n"
    << "tag_size_m: " << s.car.tag_size_m << "\ntag_offset_m: [0.035125, 0.0, 0.129165]\n"
    << "detector: {decimate: 1}\n"
    << "tracking: {roi: 0}\n"  // the folder's frames are unrelated scenes
    << "vehicles:\n - {name: NIGEL1, tag_id: 1}\n - {name: NIGEL2, tag_id: 2}\n";
}

// The scene's own calibration (camera.yaml, map.yaml: the synthesised camera exactly) and a run
// config on url (eye.yaml), in d.
void write_calibrated(const std::string &d, const eye::SynthScene &s, const std::string &url) {
  eye::intrinsics_save(d + "/camera.yaml", s.in);
  eye::MapCalib m;
  m.pose = s.pose;
  m.width_px = s.in.width_px;
  m.height_px = s.in.height_px;
  eye::mapcal_save(d + "/map.yaml", m);
  write_config(d + "/eye.yaml", s, url);
}

// Every "NIGEL1 x=... y=... yaw=..." on the output line of a frame.
bool find_pose(const std::string &line, const std::string &veh, double *x, double *y, double *yaw) {
  const auto at = line.find("  " + veh + " x=");
  if (at == std::string::npos) return false;
  return std::sscanf(line.c_str() + at + veh.size() + 2, " x=%lf y=%lf yaw=%lf", x, y, yaw) == 3;
}

}  // namespace

TEST(Cli, HelpForEveryCommand) {
  std::string out;
  EXPECT_EQ(run(std::string(EYE_BIN) + " --help", &out), 0);
  EXPECT_NE(out.find("calibrate-intrinsics"), std::string::npos);
  for (const char *sub : {"calibrate-intrinsics", "calibrate-map", "run"}) {
    EXPECT_EQ(run(std::string(EYE_BIN) + " " + sub + " --help", &out), 0) << sub;
    EXPECT_NE(out.find("Usage"), std::string::npos) << sub;
  }
}

TEST(Cli, BadInputGivesClearErrorNotCrash) {
  std::string out;
  EXPECT_EQ(run(std::string(EYE_BIN) + " run -c /nonexistent/eye.yaml", &out), 1);
  EXPECT_NE(out.find("/nonexistent/eye.yaml: cannot be opened"), std::string::npos) << out;
  const std::string d = fresh_dir("eye_cli_bad");
  std::ofstream(d + "/broken.png") << "not a png";
  EXPECT_EQ(
      run(std::string(EYE_BIN) + " calibrate-intrinsics --images " + d + " -o " + d + "/c.yaml",
          &out),
      1);
  EXPECT_NE(out.find("broken.png: cannot read the image"), std::string::npos) << out;
}

// The whole user flow at 640x480: checkerboard folder -> camera.yaml; map image with reference
// tags -> map.yaml; run on a folder of frames, one of which has NIGEL1's tag missing.
TEST(Cli, CalibrateThenRunOnFolder) {
  const std::string d = fresh_dir("eye_cli_flow");
  eye::SynthScene s = eye::synth_scene(640, 480, 0.10);
  s.noise_sigma = 1.5;
  // 1. intrinsics
  fs::create_directories(d + "/board");
  for (int i = 0; i < 12; ++i) {
    const double u = ((i % 4) + 0.5) / 4.0 - 0.5, v = ((i / 4) % 3 + 0.5) / 3.0 - 0.5;
    cv::Mat rvec = (cv::Mat_<double>(3, 1) << 0.6 * std::sin(1.7 * i), 0.6 * std::cos(2.3 * i),
                    0.2 * std::sin(0.9 * i)),
            r;
    cv::Rodrigues(rvec, r);
    eye::CameraPose p;
    p.r_cam_map = cv::Matx33d(r);
    p.t_cam_map = cv::Vec3d(u * 0.55, v * 0.4, 0.65 + 0.1 * (i % 3)) -
                  p.r_cam_map * cv::Vec3d(0.125, 0.0875, 0);
    char name[64];
    std::snprintf(name, sizeof name, "/board/view%02d.png", i);
    ASSERT_TRUE(cv::imwrite(d + name, eye::render_checkerboard(s.in, p, 10, 7, 0.025, 2)));
  }
  std::string out;
  ASSERT_EQ(run(std::string(EYE_BIN) + " calibrate-intrinsics --images " + d + "/board -o " + d +
                    "/camera.yaml",
                &out),
            0)
      << out;
  // 2. map
  const auto refs = eye::synth_reference_tags(s);
  write_reftags(d + "/tags.yaml", refs);
  fs::create_directories(d + "/mapimg");
  ASSERT_TRUE(cv::imwrite(d + "/mapimg/map.png", eye::synth_frame(s, {}, refs, 1)));
  ASSERT_EQ(run(std::string(EYE_BIN) + " calibrate-map --intrinsics " + d + "/camera.yaml --tags " +
                    d + "/tags.yaml --images " + d + "/mapimg -o " + d + "/map.yaml",
                &out),
            0)
      << out;
  EXPECT_NE(out.find("residual rms"), std::string::npos);
  // 3. run
  write_config(d + "/eye.yaml", s, "udpm://239.255.76.67:7791?ttl=0");
  fs::create_directories(d + "/frames");
  const std::vector<eye::SynthCar> truth = {
      {1, 0.7, 0.6, 0.4}, {1, 2.2, 1.5, -2.0}, {1, 1.5, 1.0, 3.0}};
  for (size_t k = 0; k < 3; ++k) {
    std::vector<eye::SynthCar> cars = {{2, 1.5, 0.4, 1.0}};
    if (k != 1) cars.push_back(truth[k]);  // frame 1: NIGEL1 not in view
    ASSERT_TRUE(cv::imwrite(d + "/frames/f" + std::to_string(k) + ".png",
                            eye::synth_frame(s, cars, {}, 10 + k)));
  }
  ASSERT_EQ(run(std::string(EYE_BIN) + " run -c " + d + "/eye.yaml --source folder:" + d +
                    "/frames --fps 10 --debug-image " + d + "/debug.png",
                &out),
            0)
      << out;
  std::istringstream lines(out);
  std::string line;
  int k = 0;
  while (std::getline(lines, line)) {
    if (line.find("/frames/f") == std::string::npos) continue;
    double x, y, yaw;
    EXPECT_EQ(find_pose(line, "NIGEL2", &x, &y, &yaw), true) << line;
    if (k == 1) {
      EXPECT_FALSE(find_pose(line, "NIGEL1", &x, &y, &yaw)) << "stale pose: " << line;
    } else {
      ASSERT_TRUE(find_pose(line, "NIGEL1", &x, &y, &yaw)) << line;
      EXPECT_LT(1000 * std::hypot(x - truth[static_cast<size_t>(k)].x_m,
                                  y - truth[static_cast<size_t>(k)].y_m),
                5.0)
          << line;
    }
    ++k;
  }
  EXPECT_EQ(k, 3) << out;
  EXPECT_FALSE(cv::imread(d + "/debug.png").empty());
}

// run on the LCM image channel: each pose carries the frame's capture time; a frame without
// the tag gives no pose. Real UDP multicast on loopback, port 7790.
TEST(Cli, RunOnLcmStampsCaptureTime) {
  const std::string url = "udpm://239.255.76.67:7790?ttl=0";
  const std::string d = fresh_dir("eye_cli_lcm");
  eye::SynthScene s = eye::synth_scene(640, 480, 0.10);
  write_calibrated(d, s, url);

  lcm::LCM lcm(url);
  ASSERT_TRUE(lcm.good());
  std::mutex mu;
  std::vector<autodrive::pose2d_t> got;
  struct Handler {
    std::mutex *mu;
    std::vector<autodrive::pose2d_t> *got;
    // subscribeFunction, not a member-function subscription: LCM 1.3.1's member pointer
    // call trips UBSan ("member access within misaligned address 0x1").
    static void on(const lcm::ReceiveBuffer *, const std::string &, const autodrive::pose2d_t *m,
                   Handler *h) {
      std::lock_guard<std::mutex> l(*h->mu);
      h->got->push_back(*m);
    }
  } h{&mu, &got};
  lcm.subscribeFunction("NIGEL1_POSE_EYE", &Handler::on, &h);
  // The camera's health, about once a second of capture time (the first frame's at once).
  std::vector<autodrive::eye_camera_status_t> status;
  struct StatusHandler {
    std::mutex *mu;
    std::vector<autodrive::eye_camera_status_t> *got;
    static void on(const lcm::ReceiveBuffer *, const std::string &,
                   const autodrive::eye_camera_status_t *m, StatusHandler *sh) {
      std::lock_guard<std::mutex> l(*sh->mu);
      sh->got->push_back(*m);
    }
  } sh{&mu, &status};
  lcm.subscribeFunction(AUTODRIVE_CH_EYE_CAMERA_STATUS, &StatusHandler::on, &sh);

  std::string eye_out;
  std::atomic<int> eye_status{-2};
  std::thread child([&] {
    eye_status = run(std::string(EYE_BIN) + " run -c " + d + "/eye.yaml --source lcm:EYE_IMAGE " +
                         "--idle-timeout-s 4",
                     &eye_out);
  });

  auto publish = [&](int64_t utime, const std::vector<eye::SynthCar> &cars) {
    std::vector<uchar> jpg;
    cv::imencode(".jpg", eye::synth_frame(s, cars, {}, static_cast<uint64_t>(utime)), jpg,
                 {cv::IMWRITE_JPEG_QUALITY, 95});
    autodrive::compressed_image_t m;
    m.utime = utime;
    m.frame_id = "eye";
    m.format = "jpeg";
    m.width_px = 640;
    m.height_px = 480;
    m.size_bytes = static_cast<int32_t>(jpg.size());
    m.data.assign(jpg.begin(), jpg.end());
    lcm.publish("EYE_IMAGE", &m);
  };
  auto has = [&](int64_t utime) {
    std::lock_guard<std::mutex> l(mu);
    for (const auto &p : got)
      if (p.utime == utime) return true;
    return false;
  };
  // Wait for the pose of `utime`, republishing in case the Eye was not subscribed yet.
  auto await = [&](int64_t utime, const std::vector<eye::SynthCar> &cars, bool republish) {
    const auto t0 = std::chrono::steady_clock::now();
    while (!has(utime) && std::chrono::steady_clock::now() - t0 < std::chrono::seconds(60)) {
      if (republish) publish(utime, cars);
      for (int i = 0; i < 10; ++i) lcm.handleTimeout(50);
    }
    return has(utime);
  };
  const eye::SynthCar car{1, 1.2, 0.9, 0.5};
  const int64_t t0 = 1'700'000'000'000'000;
  EXPECT_TRUE(await(t0, {car}, true));  // the Eye is up
  publish(t0 + 33'333, {});             // tag not in view
  publish(t0 + 66'666, {{1, 1.3, 0.9, 0.5}});
  EXPECT_TRUE(await(t0 + 66'666, {}, false));
  child.join();
  ASSERT_EQ(eye_status.load(), 0) << eye_out;
  // the frame without the tag was processed, and gave no pose
  EXPECT_NE(eye_out.find("EYE_IMAGE@" + std::to_string(t0 + 33'333)), std::string::npos) << eye_out;
  EXPECT_FALSE(has(t0 + 33'333));
  std::lock_guard<std::mutex> l(mu);
  ASSERT_FALSE(got.empty());
  for (const auto &p : got) {
    EXPECT_EQ(p.vehicle, "NIGEL1");
    EXPECT_EQ(p.frame_id, "map");
    EXPECT_EQ(static_cast<int>(p.source), static_cast<int>(autodrive::pose2d_t::SOURCE_EYE));
    EXPECT_GT(p.covariance[0], 0);
    if (p.utime == t0 + 66'666) {
      EXPECT_NEAR(p.x_m, 1.3, 0.005);
      EXPECT_NEAR(p.y_m, 0.9, 0.005);
      EXPECT_NEAR(p.yaw_rad, 0.5, 0.01);
    }
  }
  ASSERT_FALSE(status.empty()) << "no " << AUTODRIVE_CH_EYE_CAMERA_STATUS;
  EXPECT_EQ(status[0].camera, "eye");
  EXPECT_EQ(status[0].width_px, s.in.width_px);
  EXPECT_EQ(status[0].height_px, s.in.height_px);
  EXPECT_GE(status[0].frames, 1);
  EXPECT_EQ(status[0].ref_tags_seen, -1);  // no reference_tags in this config
  EXPECT_FALSE(status[0].moved);
  EXPECT_EQ(status[0].cov_scale, 1.0f);
}

// run on a video file (MJPG in AVI via FFMPEG): frames stamped index / --fps, poses found.
TEST(Cli, RunOnVideoFile) {
  const std::string d = fresh_dir("eye_cli_video");
  const eye::SynthScene s = eye::synth_scene(640, 480, 0.10);
  write_calibrated(d, s, "udpm://239.255.76.67:7792?ttl=0");
  cv::VideoWriter vw(d + "/drive.avi", cv::CAP_FFMPEG, cv::VideoWriter::fourcc('M', 'J', 'P', 'G'),
                     10, cv::Size(640, 480), false);
  ASSERT_TRUE(vw.isOpened());
  for (int k = 0; k < 3; ++k) vw.write(eye::synth_frame(s, {{1, 1.0 + 0.05 * k, 1.0, 0.2}}, {}, k));
  vw.release();
  std::string out;
  ASSERT_EQ(run(std::string(EYE_BIN) + " run -c " + d + "/eye.yaml --source video:" + d +
                    "/drive.avi --fps 10",
                &out),
            0)
      << out;
  std::istringstream lines(out);
  std::string line;
  int k = 0;
  while (std::getline(lines, line)) {
    if (line.find("drive.avi#") == std::string::npos) continue;
    EXPECT_NE(line.find("utime=" + std::to_string(k * 100000)), std::string::npos) << line;
    double x, y, yaw;
    ASSERT_TRUE(find_pose(line, "NIGEL1", &x, &y, &yaw)) << line;
    EXPECT_NEAR(x, 1.0 + 0.05 * k, 0.005) << line;
    EXPECT_NEAR(y, 1.0, 0.005) << line;
    ++k;
  }
  EXPECT_EQ(k, 3) << out;
  EXPECT_EQ(
      run(std::string(EYE_BIN) + " run -c " + d + "/eye.yaml --source video:" + d + "/none.avi",
          &out),
      1);
  EXPECT_NE(out.find("none.avi"), std::string::npos) << out;
}

// Probe findings: one wrong-size frame made the Eye exit 1; a 335-byte JPEG claiming
// 20000x20000 px took 459 MB, then the Eye exited. Now every bad frame is skipped before it is
// decoded (logged at a limited rate), and the Eye still localises the good frame after them.
// Real UDP multicast on loopback, port 7792.
TEST(Cli, RunOnLcmSurvivesWrongSizesBombsAndGarbage) {
  const std::string url = "udpm://239.255.76.67:7792?ttl=0";
  const std::string d = fresh_dir("eye_cli_bad_frames");
  eye::SynthScene s = eye::synth_scene(640, 480, 0.10);
  write_calibrated(d, s, url);
  lcm::LCM lcm(url);
  ASSERT_TRUE(lcm.good());
  std::mutex mu;
  std::vector<int64_t> got;
  struct Handler {
    std::mutex *mu;
    std::vector<int64_t> *got;
    static void on(const lcm::ReceiveBuffer *, const std::string &, const autodrive::pose2d_t *m,
                   Handler *h) {
      std::lock_guard<std::mutex> l(*h->mu);
      h->got->push_back(m->utime);
    }
  } h{&mu, &got};
  lcm.subscribeFunction("NIGEL1_POSE_EYE", &Handler::on, &h);
  std::string eye_out;
  std::atomic<int> eye_status{-2};
  std::thread child([&] {
    eye_status = run(std::string(EYE_BIN) + " run -c " + d + "/eye.yaml --source lcm:EYE_IMAGE " +
                         "--idle-timeout-s 4 -q",
                     &eye_out);
  });
  auto send = [&](int64_t utime, const std::string &format, const std::vector<uchar> &data) {
    autodrive::compressed_image_t m;
    m.utime = utime;
    m.frame_id = "eye";
    m.format = format;
    m.width_px = 640;
    m.height_px = 480;
    m.size_bytes = static_cast<int32_t>(data.size());
    m.data.assign(data.begin(), data.end());
    lcm.publish("EYE_IMAGE", &m);
  };
  const eye::SynthCar car{1, 1.2, 0.9, 0.5};
  auto good = [&](int64_t utime) {
    std::vector<uchar> jpg;
    cv::imencode(".jpg", eye::synth_frame(s, {car}, {}, static_cast<uint64_t>(utime)), jpg,
                 {cv::IMWRITE_JPEG_QUALITY, 95});
    send(utime, "jpeg", jpg);
  };
  auto has = [&](int64_t utime) {
    std::lock_guard<std::mutex> l(mu);
    return std::find(got.begin(), got.end(), utime) != got.end();
  };
  auto await = [&](int64_t utime, bool republish) {
    const auto t0 = std::chrono::steady_clock::now();
    while (!has(utime) && std::chrono::steady_clock::now() - t0 < std::chrono::seconds(60)) {
      if (republish) good(utime);
      for (int i = 0; i < 10; ++i) lcm.handleTimeout(50);
    }
    return has(utime);
  };
  const int64_t t0 = 1'700'000'000'000'000;
  ASSERT_TRUE(await(t0, true));  // the Eye is up
  std::vector<uchar> small;
  cv::imencode(".jpg", cv::Mat(240, 320, CV_8UC1, cv::Scalar(50)), small);
  std::vector<uchar> big_png;
  cv::imencode(".png", cv::Mat(960, 1280, CV_8UC1, cv::Scalar(50)), big_png);
  const std::vector<uchar> bomb = eye_test::jpeg_claiming(20000, 20000);
  std::vector<uchar> garbage(335);
  for (size_t i = 0; i < garbage.size(); ++i) garbage[i] = static_cast<uchar>(i * 91 + 7);
  int64_t t = t0;
  const auto flood_start = std::chrono::steady_clock::now();
  for (int k = 0; k < 20; ++k) {
    send(++t, "jpeg", small);
    send(++t, "png", big_png);
    send(++t, "jpeg", bomb);
    send(++t, "jpeg", garbage);
    send(++t, "png", garbage);
    send(++t, "bmp", garbage);
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  // Still alive and still localising.
  EXPECT_TRUE(await(t + 1000, true));
  child.join();
  EXPECT_EQ(eye_status.load(), 0) << eye_out;
  const double elapsed_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - flood_start).count();
  // Skipped frames were logged at a limited rate: at most 5 lines (+ a summary) per 10 s of the
  // limiter's (wall) periods, however long a loaded machine took; never one per bad frame (120).
  const size_t allowed = 6 * (1 + static_cast<size_t>(elapsed_s / 10.0));
  size_t lines = 0;
  for (size_t at = eye_out.find("EYE_IMAGE: "); at != std::string::npos;
       at = eye_out.find("EYE_IMAGE: ", at + 1))
    ++lines;
  EXPECT_GE(lines, 1u) << eye_out;
  EXPECT_LE(lines, allowed) << elapsed_s << " s: " << eye_out;
  EXPECT_LT(lines, 120u) << eye_out;
}

// run on a real GStreamer pipeline (multifilesrc of recorded JPEG frames at 30 fps -> jpegdec ->
// appsink sync=true): frames stamped with their buffer PTS on the system clock (33.3 ms apart,
// inside the run's wall-clock span), poses found, capture-to-pose latency printed.
namespace {

// The utimes of the frame lines of a `run` on a gst: source (NIGEL1 at x = 1.0 + 0.05 k in frame
// k is checked on each; the run prints its capture-to-pose latency).
std::vector<long long> gst_run_utimes(const std::string &dir, const std::string &pipeline) {
  std::string out;
  EXPECT_EQ(
      run(std::string(EYE_BIN) + " run -c " + dir + "/eye.yaml --source 'gst:" + pipeline + "'",
          &out),
      0)
      << out;
  std::istringstream lines(out);
  std::string line;
  std::vector<long long> utimes;
  while (std::getline(lines, line)) {
    const auto at = line.find(" utime=");
    if (line.rfind("gst:", 0) != 0 || at == std::string::npos) continue;
    utimes.push_back(std::stoll(line.substr(at + 7)));
    double x, y, yaw;
    EXPECT_TRUE(find_pose(line, "NIGEL1", &x, &y, &yaw)) << line;
    EXPECT_NEAR(x, 1.0 + 0.05 * static_cast<double>(utimes.size() - 1), 0.005) << line;
  }
  EXPECT_NE(out.find("capture to pose on LCM: p50"), std::string::npos) << out;
  return utimes;
}

}  // namespace

TEST(Cli, RunOnGstreamerPipelineStampsSystemClock) {
  const std::string d = fresh_dir("eye_cli_gst");
  const eye::SynthScene s = eye::synth_scene(640, 480, 0.10);
  write_calibrated(d, s, "udpm://239.255.76.67:7793?ttl=0");
  const int n = 6;
  for (int k = 0; k < n; ++k) {
    char name[32];
    std::snprintf(name, sizeof name, "/f%03d.jpg", k);
    ASSERT_TRUE(cv::imwrite(d + name, eye::synth_frame(s, {{1, 1.0 + 0.05 * k, 1.0, 0.2}}, {}, k)));
  }
  // Recorded frames at a fixed rate (multifilesrc gives buffer k the PTS k / rate).
  const auto pipeline = [&](const std::string &rate, bool sync) {
    return "multifilesrc location=" + d + "/f%03d.jpg index=0 stop-index=" + std::to_string(n - 1) +
           " caps=image/jpeg,framerate=" + rate +
           " ! jpegdec ! videoconvert ! video/x-raw,format=BGR ! appsink sync=" +
           (sync ? "true" : "false");
  };
  const auto wall_us = [] {
    return std::chrono::duration_cast<std::chrono::microseconds>(
               std::chrono::system_clock::now().time_since_epoch())
        .count();
  };
  // Played at its rate (sync=true): stamps on the system clock, inside the run.
  const int64_t t0 = wall_us();
  const auto played = gst_run_utimes(d, pipeline("30/1", true));
  const int64_t t1 = wall_us();
  ASSERT_EQ(played.size(), static_cast<size_t>(n));
  EXPECT_GE(played.front(), t0);
  EXPECT_LE(played.back(), t1);
#ifdef AUTODRIVE_EYE_GST_APPSINK
  // The Eye's own appsink: each stamp is the buffer's PTS on the system clock, so consecutive
  // stamps are 1/30 s apart to the microsecond (rounding), whenever the Eye pulled them.
  for (size_t k = 1; k < played.size(); ++k)
    EXPECT_NEAR(played[k] - played[k - 1], 1e6 / 30, 2) << "frame " << k;
  // Pulled as fast as they decode (sync=false) from a 0.5 Hz recording: the stamps still
  // follow the PTS, 2 s apart to the microsecond; grab times (a few ms apart, however loaded
  // the machine) would not.
  const auto pulled = gst_run_utimes(d, pipeline("1/2", false));
  ASSERT_EQ(pulled.size(), static_cast<size_t>(n));
  for (size_t k = 1; k < pulled.size(); ++k)
    EXPECT_NEAR(pulled[k] - pulled[k - 1], 2000000, 2) << "frame " << k;
#else
  // OpenCV's capture (no gstreamer-app dev files in this build) reports the pipeline position
  // when the frame is read, not the PTS: what holds is an increasing stamp on the system clock.
  for (size_t k = 1; k < played.size(); ++k) EXPECT_GT(played[k], played[k - 1]);
#endif
}

// realtime_priority: the running Eye's threads are SCHED_FIFO at that priority; where the
// system does not grant it (no CAP_SYS_NICE, no rtprio limit) the Eye says so, naming its
// config, and runs at ordinary priority; an out-of-range value is refused with the key. The
// lcm source waits 1.5 s for frames (port 7796), so the policy is read while it runs.
TEST(Cli, RealtimePriorityIsTakenOrNamed) {
  const std::string d = fresh_dir("eye_cli_realtime");
  const eye::SynthScene s = eye::synth_scene(640, 480, 0.10);
  write_calibrated(d, s, "udpm://239.255.76.67:7796?ttl=0");
  // Every thread of the process (LCM's, the trackers') shows its policy in chrt's output.
  const auto policies = [&](const std::string &prefix, const std::string &args) {
    const std::string cmd = prefix + " " + EYE_BIN + " run -c " + d +
                            "/eye.yaml --source lcm:EYE_IMAGE --idle-timeout-s 1.5 " + args +
                            " 2>&1 & pid=$!; sleep 0.7; for t in /proc/$pid/task/*; do chrt -p "
                            "${t##*/}; done; wait $pid; echo exit=$?";
    std::string out;
    run(cmd, &out);
    return out;
  };
  std::string out;
  if (run("chrt -f 1 true", &out) == 0) {  // this test may take real-time priority itself
    out = policies("", "--realtime-priority 7");
    EXPECT_NE(out.find("SCHED_FIFO"), std::string::npos) << out;
    EXPECT_NE(out.find("priority: 7"), std::string::npos) << out;
    EXPECT_EQ(out.find("SCHED_OTHER"), std::string::npos) << "a thread left ordinary: " << out;
    EXPECT_EQ(out.find("not granted"), std::string::npos) << out;
    EXPECT_NE(out.find("exit=0"), std::string::npos) << out;
  }
  // Without the capability (dropped from the bounding set, so not even root has it).
  out = policies("setpriv --bounding-set -sys_nice --inh-caps -sys_nice", "--realtime-priority 7");
  EXPECT_NE(out.find("realtime_priority 7 not granted"), std::string::npos) << out;
  EXPECT_NE(out.find(d + "/eye.yaml"), std::string::npos) << out;
  EXPECT_EQ(out.find("SCHED_FIFO"), std::string::npos) << out;
  EXPECT_NE(out.find("exit=0"), std::string::npos) << out;
  // 0: ordinary, and nothing said.
  out = policies("", "--realtime-priority 0");
  EXPECT_EQ(out.find("SCHED_FIFO"), std::string::npos) << out;
  EXPECT_EQ(out.find("not granted"), std::string::npos) << out;
  {
    std::ofstream f(d + "/eye.yaml", std::ios::app);
    f << "realtime_priority: 120\n";
  }
  EXPECT_EQ(run(std::string(EYE_BIN) + " run -c " + d + "/eye.yaml --max-frames 1", &out), 1);
  EXPECT_NE(out.find("realtime_priority"), std::string::npos) << out;
  EXPECT_NE(out.find(d + "/eye.yaml"), std::string::npos) << out;
}
