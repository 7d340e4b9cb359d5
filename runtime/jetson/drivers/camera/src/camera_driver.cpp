#include <autodrive/camera/camera_driver.hpp>

#include <autodrive/camera_info_t.hpp>
#include <autodrive/compressed_image_t.hpp>
#include <lcm/lcm-cpp.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>
#include <spdlog/spdlog.h>

#include <condition_variable>
#include <mutex>
#include <thread>

#include <autodrive/core/clock.hpp>

namespace autodrive::camera {

SourceKind classify_source(const std::string &s) {
  if (s.find('!') != std::string::npos) return SourceKind::gstreamer;
  if (s.rfind("/dev/video", 0) == 0) return SourceKind::v4l2;
  return SourceKind::file;
}

std::vector<uint8_t> encode_jpeg(const void *bgr, int w, int h, int out_w, int out_h, int quality) {
  cv::Mat img(h, w, CV_8UC3, const_cast<void *>(bgr));
  cv::Mat sized = img;
  if (w != out_w || h != out_h)
    cv::resize(img, sized, cv::Size(out_w, out_h), 0, 0, cv::INTER_AREA);
  std::vector<uint8_t> out;
  cv::imencode(".jpg", sized, out, {cv::IMWRITE_JPEG_QUALITY, quality});
  return out;
}

// Named, not anonymous: CameraDriver::Impl holds an Opener, and the aarch64 unity build
// (-Wsubobject-linkage) refuses an anonymous type inside a class of an included file.
namespace opener_detail {
// Openers still blocked inside cv::VideoCapture::open (their threads are detached).
std::atomic<int> g_stuck_openers{0};

// One cv::VideoCapture::open on a thread of its own: OpenCV's GStreamer backend waits for the
// pipeline to start without any timeout, so a pipeline that never starts would hold the
// driver (and its stop) for good. The state is shared, so a stuck opener may outlive the
// driver and end whenever open returns.
struct Opener {
  std::mutex mu;
  std::condition_variable cv;
  bool done = false, ok = false;
  cv::VideoCapture cap;
};
}  // namespace opener_detail
using opener_detail::g_stuck_openers;
using opener_detail::Opener;

int stuck_openers() {
  return g_stuck_openers.load();
}

struct CameraDriver::Impl {
  autodrive::config::Config config;
  autodrive::config::Camera cam;
  std::string tag;
  lcm::LCM lcm;
  autodrive::clock::Clock clock;
  std::atomic<uint64_t> published{0};
  std::string error;
  std::shared_ptr<Opener> opener;  // the open in progress (or stuck), if any

  Impl(const autodrive::config::Config &c, std::size_t i)
      : config(c), lcm(c.lcm_url), clock(c.clock) {
    if (i >= c.cameras.size()) {
      error = c.file + ": cameras[" + std::to_string(i) + "]: missing";
      return;
    }
    cam = c.cameras[i];
    tag = "[camera " + c.vehicle.name + cam.channel + "] ";
    if (lcm.good()) clock.attach(lcm);
  }

  static bool open_source(const autodrive::config::Camera &cam, cv::VideoCapture &cap) {
    switch (classify_source(cam.source)) {
      case SourceKind::gstreamer: return cap.open(cam.source, cv::CAP_GSTREAMER);
      case SourceKind::v4l2:
        if (!cap.open(cam.source, cv::CAP_V4L2)) return false;
        cap.set(cv::CAP_PROP_FRAME_WIDTH, cam.width_px);
        cap.set(cv::CAP_PROP_FRAME_HEIGHT, cam.height_px);
        cap.set(cv::CAP_PROP_FPS, cam.rate_hz);
        return true;
      case SourceKind::file: return cap.open(cam.source, cv::CAP_ANY);
    }
    return false;
  }

  // Opens the source within cam.open_timeout_ms (returning early on stop). False when it failed
  // or timed out (logged once per outage by the caller via `why`); a timed-out open keeps
  // running detached, and the next call waits for it rather than starting another.
  bool open(cv::VideoCapture &cap, const std::atomic<bool> &stop, std::string *why) {
    if (!opener) {
      opener = std::make_shared<Opener>();
      ++g_stuck_openers;
      std::thread([o = opener, c = cam] {
        const bool ok = open_source(c, o->cap);
        std::lock_guard<std::mutex> g(o->mu);
        o->ok = ok;
        o->done = true;
        --g_stuck_openers;
        o->cv.notify_all();
      }).detach();
    }
    const auto deadline =
        std::chrono::steady_clock::now() + std::chrono::milliseconds(cam.open_timeout_ms);
    std::unique_lock<std::mutex> lk(opener->mu);
    while (!opener->done && !stop && std::chrono::steady_clock::now() < deadline)
      opener->cv.wait_for(lk, std::chrono::milliseconds(20));
    if (!opener->done) {
      *why = "opening it did not finish within " + std::to_string(cam.open_timeout_ms) +
             " ms (camera.open_timeout_ms): is every element of the pipeline installed (e.g. "
             "nvarguscamerasrc on a Jetson) and the camera plugged in?";
      return false;  // still running: the next attempt waits for this one
    }
    const bool ok = opener->ok;
    if (ok) cap = std::move(opener->cap);
    lk.unlock();
    opener.reset();
    *why = "it does not open (no such device or file, or a pipeline that fails to start)";
    return ok;
  }

  void publish_info() {
    autodrive::camera_info_t info{};
    info.utime = clock.now_us();
    info.frame_id = cam.frame_id;
    info.width_px = cam.width_px;
    info.height_px = cam.height_px;
    for (int i = 0; i < 9; ++i) info.k[i] = cam.k[static_cast<std::size_t>(i)];
    info.distortion_model = "plumb_bob";
    info.num_d = static_cast<int32_t>(cam.d.size());
    info.d = cam.d;
    lcm.publish(config.vehicle.name + cam.info_channel, &info);
  }

  void run(const std::atomic<bool> &stop) {
    const bool is_file = classify_source(cam.source) == SourceKind::file;
    const int64_t period_us = static_cast<int64_t>(1e6 / cam.rate_hz);
    cv::VideoCapture cap;
    bool failure_logged = false;
    int64_t next_frame_us = autodrive::clock::monotonic_us(), next_info_us = next_frame_us;
    while (!stop) {
      if (!cap.isOpened()) {
        if (!failure_logged) spdlog::info("{}opening '{}'", tag, cam.source);
        std::string why;
        if (!open(cap, stop, &why)) {
          if (stop) break;
          if (!failure_logged)
            spdlog::error("{}cannot open '{}': {}; retrying every 1 s", tag, cam.source, why);
          failure_logged = true;
          for (int i = 0; i < 50 && !stop; ++i)
            std::this_thread::sleep_for(std::chrono::milliseconds(20));
          continue;
        }
        failure_logged = false;
        spdlog::info("{}capturing from '{}'", tag, cam.source);
      }
      cv::Mat frame;
      bool ok = cap.read(frame) && !frame.empty();
      if (!ok && is_file && cam.loop_file) {
        cap.set(cv::CAP_PROP_POS_FRAMES, 0);  // rewind a file and go on
        ok = cap.read(frame) && !frame.empty();
      }
      if (!ok) {
        spdlog::warn("{}'{}' stopped delivering frames; reopening", tag, cam.source);
        cap.release();
        continue;
      }
      const int64_t now = autodrive::clock::monotonic_us();
      if (!is_file && now < next_frame_us) continue;  // live source faster than our rate
      if (is_file && now < next_frame_us)
        std::this_thread::sleep_for(std::chrono::microseconds(next_frame_us - now));
      next_frame_us += period_us;
      if (next_frame_us < autodrive::clock::monotonic_us())
        next_frame_us = autodrive::clock::monotonic_us() + period_us;
      if (frame.type() != CV_8UC3) cv::cvtColor(frame, frame, cv::COLOR_GRAY2BGR);
      cv::Mat cont = frame.isContinuous() ? frame : frame.clone();
      autodrive::compressed_image_t img{};
      img.utime = clock.now_us();
      img.frame_id = cam.frame_id;
      img.format = "jpeg";
      img.width_px = cam.width_px;
      img.height_px = cam.height_px;
      img.data = encode_jpeg(cont.data, cont.cols, cont.rows, cam.width_px, cam.height_px,
                             cam.jpeg_quality);
      img.size_bytes = static_cast<int32_t>(img.data.size());
      lcm.publish(config.vehicle.name + cam.channel, &img);
      ++published;
      if (autodrive::clock::monotonic_us() >= next_info_us) {
        publish_info();
        next_info_us = autodrive::clock::monotonic_us() + 1000000;
      }
    }
  }
};

CameraDriver::CameraDriver(const autodrive::config::Config &config, std::size_t i)
    : impl_(std::make_unique<Impl>(config, i)) {}
CameraDriver::~CameraDriver() = default;

std::string CameraDriver::init_error() const {
  if (!impl_->error.empty()) return impl_->error;
  if (!impl_->lcm.good()) return "LCM URL '" + impl_->config.lcm_url + "' unusable";
  return "";
}

void CameraDriver::run(const std::atomic<bool> &stop) {
  impl_->run(stop);
}
uint64_t CameraDriver::frames_published() const {
  return impl_->published.load();
}

}  // namespace autodrive::camera
