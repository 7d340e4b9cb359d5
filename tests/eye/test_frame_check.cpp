// Frames from the bus are checked before they are decoded: the header (libjpeg / libpng, no
// pixels decoded) must name the calibrated size. Probe findings: a wrong-size frame made the
// Eye exit 1; a 335-byte JPEG claiming 20000x20000 px took 459 MB, then the Eye exited.
#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include <vector>

#include "eye_frame_check.hpp"
#include "eye_test_util.hpp"

namespace {
std::vector<uchar> encode(const char *ext, int w, int h) {
  std::vector<uchar> out;
  cv::imencode(ext, cv::Mat(h, w, CV_8UC1, cv::Scalar(90)), out);
  return out;
}
}  // namespace

TEST(FrameCheck, HeadersGiveTheSizeWithoutDecoding) {
  for (const char *fmt : {"jpeg", "png"}) {
    const auto img = encode(std::string(fmt) == "png" ? ".png" : ".jpg", 640, 480);
    eye::ImageHeader h;
    ASSERT_EQ(eye::read_image_header(img.data(), img.size(), fmt, &h), "") << fmt;
    EXPECT_EQ(h.width_px, 640);
    EXPECT_EQ(h.height_px, 480);
    EXPECT_EQ(eye::check_frame(img.data(), img.size(), fmt, 640, 480), "") << fmt;
  }
}

TEST(FrameCheck, WrongSizeIsRefusedNamingBothSizes) {
  const auto img = encode(".jpg", 320, 240);
  const std::string why = eye::check_frame(img.data(), img.size(), "jpeg", 640, 480);
  EXPECT_NE(why.find("header says 320x240 px, the calibrated size is 640x480 px"),
            std::string::npos)
      << why;
}

TEST(FrameCheck, DecompressionBombIsRefusedBeforeDecoding) {
  const auto bomb = eye_test::jpeg_claiming(20000, 20000);
  ASSERT_LT(bomb.size(), 1000u);
  eye::ImageHeader h;
  ASSERT_EQ(eye::read_image_header(bomb.data(), bomb.size(), "jpeg", &h), "");
  EXPECT_EQ(h.width_px, 20000);
  EXPECT_NE(eye::check_frame(bomb.data(), bomb.size(), "jpeg", 640, 480).find("20000x20000"),
            std::string::npos);
}

TEST(FrameCheck, GarbageAndUnknownFormatsAreRefusedNotFatal) {
  std::vector<uint8_t> garbage(335);
  for (size_t i = 0; i < garbage.size(); ++i) garbage[i] = static_cast<uint8_t>(i * 91 + 7);
  EXPECT_NE(eye::check_frame(garbage.data(), garbage.size(), "jpeg", 640, 480).find("not a JPEG"),
            std::string::npos);
  EXPECT_NE(eye::check_frame(garbage.data(), garbage.size(), "png", 640, 480).find("not a PNG"),
            std::string::npos);
  EXPECT_NE(eye::check_frame(garbage.data(), garbage.size(), "bmp", 640, 480).find("format 'bmp'"),
            std::string::npos);
  EXPECT_NE(eye::check_frame(garbage.data(), 0, "jpeg", 640, 480), "");
  // A truncated real JPEG header.
  const auto img = encode(".jpg", 640, 480);
  EXPECT_NE(eye::check_frame(img.data(), 20, "jpeg", 640, 480), "");
}
