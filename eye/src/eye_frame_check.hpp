// Checks on a compressed frame from the bus before it is decoded: a frame is believed only if
// its header (read with libjpeg / libpng, nothing decoded) names the calibrated size. A wrong
// size or a decompression bomb (a few hundred bytes claiming 20000x20000 px) is skipped, never
// decoded, and never ends the Eye.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

namespace eye {

struct ImageHeader {
  int width_px = 0;
  int height_px = 0;
};

// Reads the dimensions from a JPEG or PNG header (format "jpeg" or "png"). Returns "" and
// fills *h, or what is wrong ("not a JPEG header: ...").
std::string read_image_header(const uint8_t *data, size_t n, const std::string &format,
                              ImageHeader *h);

// "" if the frame may be decoded: a known format, a readable header naming exactly
// width_px x height_px; else the reason it is skipped (names the sizes).
std::string check_frame(const uint8_t *data, size_t n, const std::string &format, int width_px,
                        int height_px);

}  // namespace eye
