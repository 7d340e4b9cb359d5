// Frame sources for `run`: camera device, GStreamer pipeline, video file, image folder, or an
// LCM image channel. Each frame is decoded to grey (an LCM channel's JPEGs are left to the
// tracker, which decodes them row by row beside its work) and stamped with its capture time.
#pragma once
#include <autodrive/log_limiter.hpp>
#include <opencv2/core.hpp>

#include <cstdint>
#include <memory>
#include <string>

#include "eye_rowdecode.hpp"

namespace eye {

struct Frame {
  cv::Mat gray;                      // CV_8UC1, or empty while jpeg is not decoded
  std::shared_ptr<RowDecoder> jpeg;  // an lcm: source's JPEG, decoded by the tracker
  int width_px() const;
  int height_px() const;
  int64_t utime = 0;        // capture time [us]
  bool wall_clock = false;  // utime is on the system clock (device, gst): latency is measurable
  std::string label;        // file name or frame counter, for messages
};

class Source {
 public:
  virtual ~Source() = default;
  // Next frame; false at the end of the stream (or after timeout for a live source).
  virtual bool next(Frame *f) = 0;
};

// spec: "device:<index>", "gst:<pipeline>", "video:<file>", "folder:<dir>", "lcm:<channel>".
// fps_hint: frame period used to stamp video and folder frames (their capture time is not
// recorded); lcm_url: for lcm sources; idle_timeout_s: a live source with no frame for this
// long ends the stream (0: wait forever). Throws eye::Error naming the source if it cannot open.
// width_px x height_px: the calibrated frame size; an lcm source skips (and logs at a limited
// rate) every frame whose header names another size, before decoding it.
std::unique_ptr<Source> source_open(const std::string &spec, double fps_hint,
                                    const std::string &lcm_url, double idle_timeout_s,
                                    int width_px = 0, int height_px = 0);

// Frames skipped because they cannot be believed, counted and logged at a limited rate per
// channel or source (on stderr): wrong size, bombs, garbage.
autodrive::LogLimiter &skipped_frames_log();

// Decodes a JPEG/PNG buffer to grey; throws eye::Error naming `what` if it is not an image.
cv::Mat decode_gray(const uint8_t *data, size_t n, const std::string &what);

int64_t now_utime();

// The LCM URL with a 4 MB socket receive buffer for udpm (large image messages).
std::string lcm_url_for_images(const std::string &url);

}  // namespace eye
