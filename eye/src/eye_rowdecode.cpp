#include "eye_rowdecode.hpp"

#include <jpeglib.h>

#include <algorithm>
#include <csetjmp>
#include <cstdio>
#include <limits>

#include "eye_error.hpp"

namespace eye {

struct JpegRows {
  jpeg_decompress_struct cinfo;
  jpeg_error_mgr mgr;
  std::jmp_buf jump;
  char message[JMSG_LENGTH_MAX];
  bool created;
};

namespace {

// libjpeg's default error handler exits the process: jump back out instead.
void on_error(j_common_ptr cinfo) {
  auto *j = reinterpret_cast<JpegRows *>(cinfo->client_data);
  (*cinfo->err->format_message)(cinfo, j->message);
  std::longjmp(j->jump, 1);
}

void quiet(j_common_ptr, int) {}

// The libjpeg calls, each between a setjmp and the longjmps it may take: no C++ object with a
// destructor lives in these frames. Return false with j->message filled on an error.
bool open_header(JpegRows *j, const uint8_t *data, size_t n) {
  j->cinfo.err = jpeg_std_error(&j->mgr);
  j->mgr.error_exit = on_error;
  j->mgr.emit_message = quiet;
  j->cinfo.client_data = j;
  if (setjmp(j->jump)) return false;
  jpeg_create_decompress(&j->cinfo);
  j->created = true;
  jpeg_mem_src(&j->cinfo, data, static_cast<unsigned long>(n));
  jpeg_read_header(&j->cinfo, TRUE);
  j->cinfo.out_color_space = JCS_GRAYSCALE;  // the chroma is never decoded
  return true;
}

// Rows into base (row stride `step` bytes), calling done(ctx, rows so far) after each batch.
bool read_rows(JpegRows *j, uint8_t *base, size_t step, void (*done)(void *, int), void *ctx) {
  if (setjmp(j->jump)) return false;
  jpeg_start_decompress(&j->cinfo);
  while (j->cinfo.output_scanline < j->cinfo.output_height) {
    JSAMPROW rows[16];
    for (JDIMENSION k = 0; k < 16; ++k)
      rows[k] = base + step * std::min<JDIMENSION>(j->cinfo.output_scanline + k,
                                                   j->cinfo.output_height - 1);
    const JDIMENSION left = j->cinfo.output_height - j->cinfo.output_scanline;
    jpeg_read_scanlines(&j->cinfo, rows, left < 16 ? left : 16);
    done(ctx, static_cast<int>(j->cinfo.output_scanline));
  }
  jpeg_finish_decompress(&j->cinfo);
  return true;
}

}  // namespace

RowDecoder::RowDecoder(const uint8_t *data, size_t n, std::string what)
    : RowDecoder(std::vector<uint8_t>(data, data + n), std::move(what)) {}

RowDecoder::RowDecoder(std::vector<uint8_t> data, std::string what)
    : what_(std::move(what)), data_(std::move(data)), jpeg_(std::make_unique<JpegRows>()) {
  jpeg_->created = false;
  if (data_.empty()) throw Error(what_ + ": empty image data");
  if (!open_header(jpeg_.get(), data_.data(), data_.size())) {
    const std::string why = jpeg_->message;
    if (jpeg_->created) jpeg_destroy_decompress(&jpeg_->cinfo);
    jpeg_->created = false;
    throw Error(what_ + ": not a JPEG: " + why);
  }
  gray_.create(static_cast<int>(jpeg_->cinfo.image_height),
               static_cast<int>(jpeg_->cinfo.image_width), CV_8UC1);
}

RowDecoder::~RowDecoder() {
  if (jpeg_->created) jpeg_destroy_decompress(&jpeg_->cinfo);
}

void RowDecoder::on_rows(void *self, int rows) {
  static_cast<RowDecoder *>(self)->progress(rows, false);
}

void RowDecoder::progress(int rows, bool failed) {
  bool wake = false;
  {
    std::lock_guard<std::mutex> l(m_);
    rows_done_ = rows;
    failed_ = failed;
    // Only when a waiter's rows are in: each wake-up is a context switch (tens of us in a VM),
    // and a frame has ~90 batches of rows.
    wake = failed || rows >= waiting_for_;
  }
  if (wake) cv_.notify_all();
}

void RowDecoder::decode() {
  {
    std::lock_guard<std::mutex> l(m_);
    if (decoded_) return;
    decoded_ = true;
  }
  if (!read_rows(jpeg_.get(), gray_.data, gray_.step[0], &RowDecoder::on_rows, this)) {
    progress(rows_done_, true);
    throw Error(what_ + ": cannot decode the JPEG: " + jpeg_->message);
  }
}

bool RowDecoder::wait_rows(int rows) const {
  std::unique_lock<std::mutex> l(m_);
  const int need = std::min(rows, gray_.rows);
  if (!failed_ && rows_done_ < need) {
    waiting_for_ = need;
    cv_.wait(l, [&] { return failed_ || rows_done_ >= need; });
    waiting_for_ = std::numeric_limits<int>::max();
  }
  return !failed_;
}

}  // namespace eye
