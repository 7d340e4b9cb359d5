// A JPEG decoded to grey row by row (libjpeg's scanline API), so that one thread can decode
// while others already work on the rows above: the Eye searches a tracked car's window as soon
// as the rows under it are decoded, instead of after the whole frame (the decode of a 720p
// frame is ~4 ms here, as long as the windows of 10 cars).
#pragma once
#include <opencv2/core.hpp>

#include <condition_variable>
#include <cstdint>
#include <limits>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

namespace eye {

struct JpegRows;  // libjpeg's state (C, no destructors): eye_rowdecode.cpp

class RowDecoder {
 public:
  // Keeps a copy of the data and reads the header; throws eye::Error naming `what` if it is not
  // a JPEG. The grey image is allocated here and filled by decode().
  RowDecoder(const uint8_t *data, size_t n, std::string what);
  // The same, taking the data over (a frame from the bus: no second copy).
  RowDecoder(std::vector<uint8_t> data, std::string what);
  ~RowDecoder();
  RowDecoder(const RowDecoder &) = delete;
  RowDecoder &operator=(const RowDecoder &) = delete;
  int width_px() const { return gray_.cols; }
  int height_px() const { return gray_.rows; }
  const std::string &what() const { return what_; }
  // The frame (CV_8UC1); rows below rows_done() are not written yet.
  const cv::Mat &image() const { return gray_; }
  // Decodes every row, once; throws eye::Error naming the frame on corrupt data (waiters are
  // released first). Warnings (a truncated end) decode as libjpeg fills them, as cv::imdecode.
  void decode();
  // Blocks until rows [0, rows) are decoded; false if the decode failed.
  bool wait_rows(int rows) const;

 private:
  void progress(int rows, bool failed);
  static void on_rows(void *self, int rows);
  std::string what_;
  std::vector<uint8_t> data_;
  cv::Mat gray_;
  std::unique_ptr<JpegRows> jpeg_;
  mutable std::mutex m_;
  mutable std::condition_variable cv_;
  int rows_done_ = 0;
  mutable int waiting_for_ = std::numeric_limits<int>::max();  // rows a waiter needs (one waiter)
  bool failed_ = false, decoded_ = false;
};

}  // namespace eye
