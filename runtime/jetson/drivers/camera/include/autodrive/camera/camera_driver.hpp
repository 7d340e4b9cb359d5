// Camera driver: OpenCV capture from a V4L2 device (/dev/videoN), a GStreamer pipeline (any
// source containing '!', e.g. the Jetson CSI camera through nvarguscamerasrc) or a video file.
// Publishes <VEH>_<channel> (JPEG compressed_image_t) at rate_hz and <VEH>_<channel>_INFO
// (camera_info_t) at 1 Hz.
#pragma once

#include <atomic>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <autodrive/core/config.hpp>

namespace autodrive::camera {

enum class SourceKind { v4l2, gstreamer, file };
SourceKind classify_source(const std::string &source);

// JPEG-encodes a BGR frame (resized to width x height if needed).
std::vector<uint8_t> encode_jpeg(const void *bgr, int width_px, int height_px, int out_w, int out_h,
                                 int quality);

// Camera opens still blocked in OpenCV after their driver gave up waiting (a program exits
// with std::_Exit rather than run static destructors under them).
int stuck_openers();

class CameraDriver {
 public:
  CameraDriver(const autodrive::config::Config &config, std::size_t camera_index);
  ~CameraDriver();
  std::string init_error() const;
  void run(const std::atomic<bool> &stop);
  uint64_t frames_published() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace autodrive::camera
