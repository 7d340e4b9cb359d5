#include "eye_frame_check.hpp"

#include <jpeglib.h>
#include <png.h>

#include <csetjmp>
#include <cstdio>

namespace eye {
namespace {

// libjpeg's default error handler exits the process: jump back out instead.
struct JpegError {
  jpeg_error_mgr mgr;
  std::jmp_buf jump;
  char message[JMSG_LENGTH_MAX];
};

void jpeg_on_error(j_common_ptr cinfo) {
  auto *e = reinterpret_cast<JpegError *>(cinfo->err);
  (*cinfo->err->format_message)(cinfo, e->message);
  std::longjmp(e->jump, 1);
}

void jpeg_quiet(j_common_ptr, int) {}  // warnings: the header read decides

// Returns false with *why filled if the header cannot be read. No C++ object with a destructor
// lives between setjmp and longjmp.
bool jpeg_header(const uint8_t *data, size_t n, ImageHeader *h, char *why, size_t why_len) {
  jpeg_decompress_struct cinfo;
  JpegError err;
  cinfo.err = jpeg_std_error(&err.mgr);
  err.mgr.error_exit = jpeg_on_error;
  err.mgr.emit_message = jpeg_quiet;
  if (setjmp(err.jump)) {
    std::snprintf(why, why_len, "%s", err.message);
    jpeg_destroy_decompress(&cinfo);
    return false;
  }
  jpeg_create_decompress(&cinfo);
  jpeg_mem_src(&cinfo, data, static_cast<unsigned long>(n));
  jpeg_read_header(&cinfo, TRUE);
  h->width_px = static_cast<int>(cinfo.image_width);
  h->height_px = static_cast<int>(cinfo.image_height);
  jpeg_destroy_decompress(&cinfo);
  return true;
}

struct PngInput {
  const uint8_t *data;
  size_t n, pos;
};

void png_read_mem(png_structp png, png_bytep out, png_size_t len) {
  auto *in = static_cast<PngInput *>(png_get_io_ptr(png));
  if (len > in->n - in->pos) png_error(png, "truncated PNG header");
  for (png_size_t i = 0; i < len; ++i) out[i] = in->data[in->pos + i];
  in->pos += len;
}

void png_on_error(png_structp png, png_const_charp msg) {
  auto *why = static_cast<char *>(png_get_error_ptr(png));
  std::snprintf(why, 200, "%s", msg);
  png_longjmp(png, 1);
}

void png_quiet(png_structp, png_const_charp) {}

bool png_header(const uint8_t *data, size_t n, ImageHeader *h, char *why, size_t why_len) {
  if (n < 8 || png_sig_cmp(data, 0, 8) != 0) {
    std::snprintf(why, why_len, "no PNG signature");
    return false;
  }
  char msg[200] = "";
  png_structp png = png_create_read_struct(PNG_LIBPNG_VER_STRING, msg, png_on_error, png_quiet);
  png_infop info = png ? png_create_info_struct(png) : nullptr;
  if (!png || !info) {
    png_destroy_read_struct(&png, nullptr, nullptr);
    std::snprintf(why, why_len, "libpng: out of memory");
    return false;
  }
  PngInput in{data, n, 0};
  if (setjmp(png_jmpbuf(png))) {
    std::snprintf(why, why_len, "%s", msg);
    png_destroy_read_struct(&png, &info, nullptr);
    return false;
  }
  png_set_read_fn(png, &in, png_read_mem);
  png_read_info(png, info);
  h->width_px = static_cast<int>(png_get_image_width(png, info));
  h->height_px = static_cast<int>(png_get_image_height(png, info));
  png_destroy_read_struct(&png, &info, nullptr);
  return true;
}

}  // namespace

std::string read_image_header(const uint8_t *data, size_t n, const std::string &format,
                              ImageHeader *h) {
  if (n == 0) return "empty image data";
  char why[JMSG_LENGTH_MAX + 64] = "";
  if (format == "jpeg") {
    if (!jpeg_header(data, n, h, why, sizeof why)) return std::string("not a JPEG: ") + why;
  } else if (format == "png") {
    if (!png_header(data, n, h, why, sizeof why)) return std::string("not a PNG: ") + why;
  } else {
    return "format '" + format + "' is not jpeg or png";
  }
  return "";
}

std::string check_frame(const uint8_t *data, size_t n, const std::string &format, int width_px,
                        int height_px) {
  ImageHeader h;
  const std::string why = read_image_header(data, n, format, &h);
  if (!why.empty()) return why;
  if (h.width_px != width_px || h.height_px != height_px)
    return "header says " + std::to_string(h.width_px) + "x" + std::to_string(h.height_px) +
           " px, the calibrated size is " + std::to_string(width_px) + "x" +
           std::to_string(height_px) + " px (" + std::to_string(n) + " bytes)";
  return "";
}

}  // namespace eye
