#include "eye_source.hpp"

#include <autodrive_lcm/subscribe.hpp>
#include <lcm/lcm-cpp.hpp>
#include <spdlog/sinks/stdout_sinks.h>
#include <autodrive/compressed_image_t.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <chrono>
#include <deque>
#include <filesystem>

#include "eye_error.hpp"
#include "eye_frame_check.hpp"
#ifdef AUTODRIVE_EYE_GST_APPSINK
#include "eye_gst.hpp"
#endif

namespace eye {

int Frame::width_px() const {
  return jpeg ? jpeg->width_px() : gray.cols;
}
int Frame::height_px() const {
  return jpeg ? jpeg->height_px() : gray.rows;
}

int64_t now_utime() {
  return std::chrono::duration_cast<std::chrono::microseconds>(
             std::chrono::system_clock::now().time_since_epoch())
      .count();
}

cv::Mat decode_gray(const uint8_t *data, size_t n, const std::string &what) {
  if (n == 0) throw Error(what + ": empty image data");
  cv::Mat buf(1, static_cast<int>(n), CV_8UC1, const_cast<uint8_t *>(data));
  cv::Mat g = cv::imdecode(buf, cv::IMREAD_GRAYSCALE);
  if (g.empty()) throw Error(what + ": cannot decode the image data (not JPEG/PNG?)");
  return g;
}

namespace {

// How a capture source's frames are stamped.
enum class Stamp {
  kFileIndex,   // video files: frame index / fps (no capture time recorded)
  kV4l2Buffer,  // the V4L2 buffer time stamp (CLOCK_MONOTONIC) mapped to the system clock
  kGstPts,      // the GStreamer running time at read + the wall clock at PLAYING (used only
                // without the native appsink of eye_gst.cpp)
};

int64_t monotonic_utime() {
  return std::chrono::duration_cast<std::chrono::microseconds>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

class CaptureSource : public Source {
 public:
  CaptureSource(const std::string &spec, cv::VideoCapture cap, Stamp stamp, double fps)
      : spec_(spec), cap_(std::move(cap)), stamp_(stamp), fps_(fps), base_utime_(now_utime()) {}
  bool next(Frame *f) override {
    cv::Mat m;
    if (!cap_.read(m) || m.empty()) return false;
    // OpenCV 4.6's CAP_PROP_POS_MSEC: V4L2 gives the driver's buffer time stamp
    // (CLOCK_MONOTONIC, taken at capture); GStreamer the pipeline's position (running time)
    // when the frame is read, not the buffer's own PTS (a few ms later than it).
    const double t_ms = stamp_ == Stamp::kFileIndex ? 0.0 : cap_.get(cv::CAP_PROP_POS_MSEC);
    switch (stamp_) {
      case Stamp::kFileIndex:
        f->utime = static_cast<int64_t>(1e6 * static_cast<double>(n_) / fps_);
        break;
      case Stamp::kV4l2Buffer:
        f->utime =
            t_ms > 0 ? std::llround(1e3 * t_ms) + (now_utime() - monotonic_utime()) : now_utime();
        break;
      case Stamp::kGstPts:
        // The pipeline's running time starts at PLAYING, which open() waited for.
        f->utime = t_ms >= 0 ? base_utime_ + std::llround(1e3 * t_ms) : now_utime();
        break;
    }
    f->wall_clock = stamp_ != Stamp::kFileIndex;
    f->label = spec_ + "#" + std::to_string(n_++);
    if (m.channels() == 3)
      cv::cvtColor(m, f->gray, cv::COLOR_BGR2GRAY);
    else if (m.channels() == 1)
      f->gray = m;
    else
      throw Error(spec_ + ": unsupported frame with " + std::to_string(m.channels()) + " channels");
    return true;
  }

 private:
  std::string spec_;
  cv::VideoCapture cap_;
  Stamp stamp_;
  double fps_;
  int64_t base_utime_;  // wall clock when the source was open (GStreamer: PLAYING) [us]
  int64_t n_ = 0;
};

class FolderSource : public Source {
 public:
  FolderSource(const std::string &dir, double fps) : fps_(fps) {
    std::error_code ec;
    if (!std::filesystem::is_directory(dir, ec)) throw Error(dir + ": not a folder");
    for (const auto &e : std::filesystem::directory_iterator(dir)) {
      std::string ext = e.path().extension().string();
      std::transform(ext.begin(), ext.end(), ext.begin(), ::tolower);
      if (ext == ".png" || ext == ".jpg" || ext == ".jpeg" || ext == ".bmp" || ext == ".pgm")
        files_.push_back(e.path().string());
    }
    std::sort(files_.begin(), files_.end());
    if (files_.empty()) throw Error(dir + ": no .png/.jpg/.bmp/.pgm images in the folder");
  }
  bool next(Frame *f) override {
    if (i_ >= files_.size()) return false;
    f->label = files_[i_];
    f->gray = cv::imread(files_[i_], cv::IMREAD_GRAYSCALE);
    if (f->gray.empty()) throw Error(files_[i_] + ": cannot read the image");
    f->utime = static_cast<int64_t>(1e6 * static_cast<double>(i_) / fps_);
    ++i_;
    return true;
  }

 private:
  std::vector<std::string> files_;
  size_t i_ = 0;
  double fps_;
};

class LcmSource : public Source {
 public:
  LcmSource(const std::string &url, const std::string &channel, double idle_s, int width_px,
            int height_px)
      : lcm_(url), channel_(channel), idle_s_(idle_s), width_px_(width_px), height_px_(height_px) {
    if (!lcm_.good()) throw Error("lcm: cannot open " + url);
    // A plain function + context (autodrive_lcm::subscribe: decodes, counts malformed
    // messages): LCM 1.3.1's member-function subscription on a polymorphic class trips UBSan.
    sub_ = autodrive_lcm::subscribe<autodrive::compressed_image_t, LcmSource, &LcmSource::on_image>(
        lcm_, channel, this);
    sub_->setQueueCapacity(4);  // drop old frames rather than fall behind the camera
  }
  bool next(Frame *f) override {
    auto start = std::chrono::steady_clock::now();
    for (;;) {
      while (q_.empty()) {
        const int r = lcm_.handleTimeout(100);
        if (r < 0 && errno == EINTR) return false;  // a signal (SIGINT, SIGTERM): the run ends
        if (r < 0) throw Error("lcm: handle failed on channel " + channel_);
        const double waited =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        skipped_frames_log().flush();
        if (q_.empty() && idle_s_ > 0 && waited > idle_s_) return false;
      }
      Pending p = std::move(q_.front());
      q_.pop_front();
      // Decoded only now: a frame dropped from a full queue costs no decode. A JPEG's header
      // is read here and its rows by the tracker.
      try {
        f->jpeg.reset();
        f->gray.release();
        if (p.format == "jpeg")
          f->jpeg = std::make_shared<RowDecoder>(std::move(p.data), p.label);
        else
          f->gray = decode_gray(p.data.data(), p.data.size(), p.label);
      } catch (const Error &e) {
        skipped_frames_log().event(p.channel, std::string(e.what()) + " (frame skipped)");
        continue;
      }
      f->utime = p.utime;
      f->label = std::move(p.label);
      f->wall_clock = false;
      return true;
    }
  }

 private:
  void on_image(const lcm::ReceiveBuffer *, const std::string &chan,
                const autodrive::compressed_image_t *m) {
    Pending f;
    f.utime = m->utime;
    f.label = chan + "@" + std::to_string(m->utime);
    f.channel = chan;
    // Believe the header only if it names the calibrated size: nothing else is decoded.
    const std::string why = width_px_ > 0 ? check_frame(m->data.data(), m->data.size(), m->format,
                                                        width_px_, height_px_)
                                          : "";
    if (!why.empty()) {
      skipped_frames_log().event(chan, "frame @" + std::to_string(m->utime) + " skipped: " + why);
      return;
    }
    f.data = m->data;
    f.format = m->format;
    if (q_.size() >= 2) q_.pop_front();  // keep the newest
    q_.push_back(std::move(f));
  }
  lcm::LCM lcm_;
  std::string channel_;
  double idle_s_;
  int width_px_, height_px_;
  lcm::Subscription *sub_ = nullptr;
  struct Pending {  // a frame whose header names the calibrated size, not decoded yet
    int64_t utime = 0;
    std::string label, channel, format;
    std::vector<uint8_t> data;
  };
  std::deque<Pending> q_;
};

}  // namespace

// A 720p-960p JPEG is ~100-200 KB, several UDP fragments: with the kernel's default receive
// buffer (~200 KB) LCM 1.3.1 loses most such frames on udpm (measured: 0 of 6 arrived; with a
// 4 MB buffer 6 of 6). Ask for 4 MB (net.core.rmem_max here) unless the URL says otherwise.
std::string lcm_url_for_images(const std::string &url) {
  if (url.rfind("udpm://", 0) != 0 || url.find("recv_buf_size=") != std::string::npos) return url;
  return url + (url.find('?') == std::string::npos ? "?" : "&") + "recv_buf_size=4194304";
}

autodrive::LogLimiter &skipped_frames_log() {
  static autodrive::LogLimiter log("skipped frames", autodrive::LogLimits(),
                                   spdlog::stderr_logger_mt("autodrive-eye"));
  return log;
}

std::unique_ptr<Source> source_open(const std::string &spec, double fps_hint,
                                    const std::string &lcm_url, double idle_timeout_s, int width_px,
                                    int height_px) {
  const auto colon = spec.find(':');
  if (colon == std::string::npos)
    throw Error("source '" + spec +
                "': expected <kind>:<what>, kind one of device, gst, video, folder, lcm");
  const std::string kind = spec.substr(0, colon), what = spec.substr(colon + 1);
  if (!(fps_hint > 0)) throw Error("source '" + spec + "': fps must be positive");
  if (kind == "folder") return std::make_unique<FolderSource>(what, fps_hint);
  if (kind == "lcm")
    return std::make_unique<LcmSource>(lcm_url_for_images(lcm_url), what, idle_timeout_s, width_px,
                                       height_px);
  cv::VideoCapture cap;
  if (kind == "device") {
    int idx = -1;
    try {
      idx = std::stoi(what);
    } catch (const std::exception &) {
      throw Error("source '" + spec + "': device index must be a number");
    }
    cap.open(idx, cv::CAP_V4L2);
  } else if (kind == "gst") {
#ifdef AUTODRIVE_EYE_GST_APPSINK
    return gst_source_open(spec, what, idle_timeout_s);  // stamps: the buffers' PTS
#else
    cap.open(what, cv::CAP_GSTREAMER);
#endif
  } else if (kind == "video") {
    if (!std::filesystem::exists(what)) throw Error("source '" + spec + "': no such file");
    cap.open(what, cv::CAP_FFMPEG);
  } else {
    throw Error("source '" + spec + "': unknown kind '" + kind +
                "' (device, gst, video, folder, lcm)");
  }
  if (!cap.isOpened()) throw Error("source '" + spec + "': cannot open");
  const Stamp stamp = kind == "device" ? Stamp::kV4l2Buffer
                      : kind == "gst"  ? Stamp::kGstPts
                                       : Stamp::kFileIndex;
  return std::make_unique<CaptureSource>(spec, std::move(cap), stamp, fps_hint);
}

}  // namespace eye
