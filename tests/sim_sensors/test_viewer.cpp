// The optional GLFW viewer on a real X server (Xvfb started by the test), sharing the process
// with the headless EGL camera renderer.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <GLFW/glfw3.h>
#include <png.h>

#include <string>
#include <vector>

#include "room.hpp"

extern "C" {
#include "sim_camera.h"
#include "sim_render.h"
#include "sim_viewer.h"
}

namespace {

// An Xvfb of our own on a display number unlikely to be taken; stopped by its pid.
struct Xvfb {
  pid_t pid = -1;
  std::string display;
  bool ready = false;
  Xvfb() {
    if (access("/usr/bin/Xvfb", X_OK) != 0) return;
    int n = 200 + (int)(getpid() % 700);
    display = ":" + std::to_string(n);
    pid = fork();
    if (pid == 0) {
      execl("/usr/bin/Xvfb", "Xvfb", display.c_str(), "-screen", "0", "800x600x24", "-nolisten",
            "tcp", (char *)nullptr);
      _exit(127);
    }
    std::string sock = "/tmp/.X11-unix/X" + std::to_string(n);
    for (int i = 0; i < 300 && !ready; i++) {  // readiness wait, not a timing assertion
      struct stat st;
      if (stat(sock.c_str(), &st) == 0)
        ready = true;
      else
        usleep(50000);
    }
    if (ready) setenv("DISPLAY", display.c_str(), 1);
  }
  ~Xvfb() {
    if (pid > 0) {
      kill(pid, SIGTERM);
      waitpid(pid, nullptr, 0);
    }
  }
};

}  // namespace

TEST(SimViewer, RendersViewsAndReportsKeysNextToHeadlessCameras) {
  if (access("/usr/bin/Xvfb", X_OK) != 0) GTEST_SKIP() << "Xvfb not installed";
  Xvfb x;
  ASSERT_TRUE(x.ready) << "Xvfb " << x.display << " did not start";
  room::Room room;
  ASSERT_NE(room.m, nullptr);
  char err[256] = "";
  sim_render_t *r = sim_render_create(room.m, 640, 480, SIM_RENDER_EGL, err, sizeof err);
  ASSERT_NE(r, nullptr) << err;
  sim_camera_t *cam =
      sim_camera_create(r, room.m, "car_cam_front", "f", 640, 480, 90, err, sizeof err);
  ASSERT_NE(cam, nullptr) << err;
  ASSERT_EQ(sim_camera_capture(cam, room.m, room.d, 0), 0);
  std::vector<uint8_t> before(sim_camera_rgb(cam), sim_camera_rgb(cam) + 640 * 480 * 3);

  ASSERT_EQ(sim_viewer_display_available(), 1);
  sim_viewer_t *v = sim_viewer_create(room.m, 1, "car", "car_cam_front", 640, 480, err, sizeof err);
  ASSERT_NE(v, nullptr) << err;
  sim_viewer_capture(v, 1);
  int w = 0, h = 0;
  sim_viewer_size(v, &w, &h);
  ASSERT_EQ(w, 640);
  ASSERT_EQ(h, 480);
  std::vector<uint8_t> shot((size_t)w * h * 3);
  sim_viewer_input_t in;
  sim_viewer_key(v, GLFW_KEY_M);  // the Menu Panel and the HUD off: this test reads whole frames
  sim_viewer_key(v, GLFW_KEY_H);

  // driver's view = the front camera: blue pillar in the centre, green floor at the bottom
  sim_viewer_key(v, GLFW_KEY_1);
  ASSERT_EQ(sim_viewer_frame(v, room.m, room.d, &in), 0);
  EXPECT_EQ(in.view, SIM_VIEW_DRIVER);
  ASSERT_EQ(sim_viewer_read_rgb(v, shot.data()), 0);
  const uint8_t *c = shot.data() + 3 * (240 * w + 320), *b = shot.data() + 3 * (470 * w + 320);
  EXPECT_GT(c[2], c[0] + 40);
  EXPECT_GT(b[1], b[0] + 40);

  // god's view = the "eye" camera: mostly green floor
  sim_viewer_key(v, GLFW_KEY_3);
  ASSERT_EQ(sim_viewer_frame(v, room.m, room.d, &in), 0);
  ASSERT_EQ(sim_viewer_read_rgb(v, shot.data()), 0);
  int green = 0;
  for (int i = 0; i < w * h; i++) green += shot[3 * i + 1] > shot[3 * i] + 40;
  EXPECT_GT(green, w * h / 2);

  // bird's view renders something other than the god's view
  sim_viewer_key(v, GLFW_KEY_2);
  ASSERT_EQ(sim_viewer_frame(v, room.m, room.d, &in), 0);
  std::vector<uint8_t> bird((size_t)w * h * 3);
  ASSERT_EQ(sim_viewer_read_rgb(v, bird.data()), 0);
  EXPECT_NE(bird, shot);

  // keys: pause toggles, reset is an edge reported once, N night darkens the frame
  sim_viewer_key(v, GLFW_KEY_SPACE);
  sim_viewer_key(v, GLFW_KEY_R);
  ASSERT_EQ(sim_viewer_frame(v, room.m, room.d, &in), 0);
  EXPECT_EQ(in.paused, 1);
  EXPECT_EQ(in.reset_requested, 1);
  EXPECT_EQ(in.quit, 0);
  long day_sum = 0;
  ASSERT_EQ(sim_viewer_read_rgb(v, bird.data()), 0);
  for (uint8_t p : bird) day_sum += p;
  sim_viewer_key(v, GLFW_KEY_N);
  ASSERT_EQ(sim_viewer_frame(v, room.m, room.d, &in), 0);
  EXPECT_EQ(in.reset_requested, 0);
  EXPECT_EQ(in.day, 0);
  long night_sum = 0;
  ASSERT_EQ(sim_viewer_read_rgb(v, bird.data()), 0);
  for (uint8_t p : bird) night_sum += p;
  EXPECT_LT(night_sum, day_sum * 3 / 4);
  sim_viewer_key(v, GLFW_KEY_ESCAPE);
  ASSERT_EQ(sim_viewer_frame(v, room.m, room.d, &in), 0);
  EXPECT_EQ(in.quit, 1);

  // the headless camera still renders the same frame with the window's context in between
  ASSERT_EQ(sim_camera_capture(cam, room.m, room.d, 0), 0);
  EXPECT_EQ(before, std::vector<uint8_t>(sim_camera_rgb(cam), sim_camera_rgb(cam) + 640 * 480 * 3));
  sim_viewer_destroy(v);
  sim_camera_destroy(cam);
  sim_render_destroy(r);
}

TEST(SimViewer, NoDisplayIsAClearError) {
  const char *saved = getenv("DISPLAY");
  std::string keep = saved ? saved : "";
  unsetenv("DISPLAY");
  unsetenv("WAYLAND_DISPLAY");
  room::Room room;
  ASSERT_NE(room.m, nullptr);
  char err[256] = "";
  EXPECT_EQ(sim_viewer_create(room.m, 1, "car", "car_cam_front", 640, 480, err, sizeof err),
            nullptr);
  EXPECT_NE(std::string(err).find("no display"), std::string::npos) << err;
  if (saved) setenv("DISPLAY", keep.c_str(), 1);
}

namespace {

long frame_sum(const std::vector<uint8_t> &rgb, int w, int x0, int y0, int x1, int y1) {
  long sum = 0;
  for (int y = y0; y < y1; y++)
    for (int x = x0; x < x1; x++)
      for (int k = 0; k < 3; k++) sum += rgb[3 * ((size_t)y * w + x) + k];
  return sum;
}

// The frame as a PNG in $AUTODRIVE_SCREENSHOT_DIR (the docs' screenshots), when it is set.
void screenshot(const std::vector<uint8_t> &rgb, int w, int h, const char *name) {
  const char *dir = getenv("AUTODRIVE_SCREENSHOT_DIR");
  if (!dir || !*dir) return;
  std::string path = std::string(dir) + "/" + name + ".png";
  FILE *f = fopen(path.c_str(), "wb");
  ASSERT_NE(f, nullptr) << path;
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
  png_infop info = png_create_info_struct(png);
  png_init_io(png, f);
  png_set_IHDR(png, info, w, h, 8, PNG_COLOR_TYPE_RGB, PNG_INTERLACE_NONE,
               PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
  png_write_info(png, info);
  for (int y = 0; y < h; y++) png_write_row(png, rgb.data() + (size_t)y * w * 3);
  png_write_end(png, nullptr);
  png_destroy_write_struct(&png, &info);
  fclose(f);
}

}  // namespace

// The Menu Panel and the HUD, driven by scripted clicks at the panel's own item positions
// (the same path as the window's mouse callback): each item changes the state it names.
TEST(SimViewer, MenuPanelItemsChangeWhatTheySayAndTheHudIsDrawn) {
  if (access("/usr/bin/Xvfb", X_OK) != 0) GTEST_SKIP() << "Xvfb not installed";
  Xvfb x;
  ASSERT_TRUE(x.ready) << "Xvfb " << x.display << " did not start";
  room::Room room;
  ASSERT_NE(room.m, nullptr);
  char err[256] = "";
  // a headless renderer beside the window, as in the program: it keeps Mesa's EGL loaded past
  // glfwTerminate, so that LeakSanitizer can name (and lsan.supp suppress) Mesa's own
  // per-display allocations instead of reporting them from an unloaded "unknown module"
  sim_render_t *r = sim_render_create(room.m, 64, 64, SIM_RENDER_EGL, err, sizeof err);
  ASSERT_NE(r, nullptr) << err;
  sim_viewer_t *v = sim_viewer_create(room.m, 1, "car", "car_cam_front", 800, 600, err, sizeof err);
  ASSERT_NE(v, nullptr) << err;
  sim_viewer_capture(v, 1);
  sim_viewer_set_map_name(v, "test_room");
  sim_viewer_set_hud(v, "sim time\nreal-time factor\nNIGEL1 speed", "12.34 s\n0.98\n0.50 m/s");
  int w = 0, h = 0;
  sim_viewer_size(v, &w, &h);
  std::vector<uint8_t> shot((size_t)w * h * 3), other((size_t)w * h * 3);
  sim_viewer_input_t in;
  ASSERT_EQ(sim_viewer_frame(v, room.m, room.d, &in), 0);
  ASSERT_EQ(sim_viewer_read_rgb(v, shot.data()), 0);
  screenshot(shot, w, h, "window-panel-hud");
  double cx = 0, cy = 0;
  auto click = [&](const char *item) {
    ASSERT_EQ(sim_viewer_item_at(v, item, &cx, &cy), 0) << item;
    sim_viewer_click(v, cx, cy);
    ASSERT_EQ(sim_viewer_frame(v, room.m, room.d, &in), 0);
  };
  EXPECT_EQ(sim_viewer_item_at(v, "No such item", &cx, &cy), -1);
  click("Pause");
  EXPECT_EQ(in.paused, 1);
  click("Pause");
  EXPECT_EQ(in.paused, 0);
  click("Step");
  EXPECT_EQ(in.step_requested, 1);
  click("Reset");
  EXPECT_EQ(in.reset_requested, 1);
  ASSERT_EQ(sim_viewer_frame(v, room.m, room.d, &in), 0);
  EXPECT_EQ(in.reset_requested, 0);  // an edge
  click("Camera/God");
  EXPECT_EQ(in.view, SIM_VIEW_GOD);
  click("Camera/Driver");
  EXPECT_EQ(in.view, SIM_VIEW_DRIVER);
  click("Shadows");
  EXPECT_EQ(in.shadows, 1);
  click("View scale");  // the window's render scale slider's middle
  EXPECT_NEAR(in.render_scale, 0.625, 0.15);
  // the View section's Cam scale line: the sensor cameras' render scale the caller applies
  EXPECT_EQ(in.camera_scale, 1.0);
  // tests/sim/test_window_camera_scale.py clicks the real program's line at these [px]
  const auto expect_item_at = [&](const char *item, double x_px, double y_px) {
    ASSERT_EQ(sim_viewer_item_at(v, item, &cx, &cy), 0);
    printf("%s at (%.0f, %.0f) px\n", item, cx, cy);
    EXPECT_NEAR(cx, x_px, 2);
    EXPECT_NEAR(cy, y_px, 2);
  };
  expect_item_at("Cam scale/0.25", 221, 453);
  click("Cam scale/0.25");
  EXPECT_EQ(in.camera_scale, 0.25);
  expect_item_at("Cam scale/1", 134, 453);
  click("Cam scale/0.5");
  EXPECT_EQ(in.camera_scale, 0.5);
  click("Cam scale/1");
  EXPECT_EQ(in.camera_scale, 1.0);
  // the Sensors section's Cameras box: the ego car's front camera drawn at the bottom left
  ASSERT_EQ(sim_viewer_read_rgb(v, shot.data()), 0);
  click("Cameras");
  EXPECT_EQ(in.thumbnails, 1);
  ASSERT_EQ(sim_viewer_read_rgb(v, other.data()), 0);
  EXPECT_NE(frame_sum(shot, w, 0, h - 100, w / 2, h), frame_sum(other, w, 0, h - 100, w / 2, h));
  sim_viewer_key(v, GLFW_KEY_C);  // and C hides it again
  ASSERT_EQ(sim_viewer_frame(v, room.m, room.d, &in), 0);
  EXPECT_EQ(in.thumbnails, 0);
  // the Car section's Driving radio, and the drive keys it lets the caller read
  ASSERT_EQ(sim_viewer_item_at(v, "Driving/Manual", &cx, &cy), 0);
  printf("Driving/Manual at (%.0f, %.0f) px\n", cx, cy);
  // tests/sim/test_window_manual.py clicks the real program's radio here
  EXPECT_NEAR(cx, 210, 2);
  EXPECT_NEAR(cy, 197, 2);
  click("Driving/Manual");
  EXPECT_EQ(in.manual, 1);
  sim_viewer_key_state(v, GLFW_KEY_UP, 1);
  sim_viewer_key_state(v, GLFW_KEY_A, 1);
  ASSERT_EQ(sim_viewer_frame(v, room.m, room.d, &in), 0);
  EXPECT_EQ(in.drive_keys, SIM_VIEWER_KEY_FORWARD | SIM_VIEWER_KEY_LEFT);
  sim_viewer_key_state(v, GLFW_KEY_UP, 0);
  ASSERT_EQ(sim_viewer_frame(v, room.m, room.d, &in), 0);
  EXPECT_EQ(in.drive_keys, SIM_VIEWER_KEY_LEFT);
  sim_viewer_key_state(v, GLFW_KEY_A, 0);
  ASSERT_EQ(sim_viewer_item_at(v, "Driving/Autonomous", &cx, &cy), 0);
  printf("Driving/Autonomous at (%.0f, %.0f) px\n", cx, cy);
  EXPECT_NEAR(cx, 145, 2);
  EXPECT_NEAR(cy, 197, 2);
  click("Driving/Autonomous");
  EXPECT_EQ(in.manual, 0);
  EXPECT_EQ(in.drive_keys, 0);
  ASSERT_EQ(sim_viewer_item_at(v, "Start or stop", &cx, &cy), 0);
  // tests/sim/test_window.py clicks the real program's Record button here
  EXPECT_NEAR(cx, 68, 2);
  EXPECT_NEAR(cy, 581, 2);
  printf("Record button at (%.0f, %.0f) px\n", cx, cy);
  click("Start or stop");
  EXPECT_EQ(in.record_toggled, 1);
  // the HUD: its text at the top right, gone with H
  ASSERT_EQ(sim_viewer_read_rgb(v, shot.data()), 0);
  sim_viewer_key(v, GLFW_KEY_H);
  ASSERT_EQ(sim_viewer_frame(v, room.m, room.d, &in), 0);
  EXPECT_EQ(in.hud, 0);
  ASSERT_EQ(sim_viewer_read_rgb(v, other.data()), 0);
  EXPECT_NE(frame_sum(shot, w, w - 200, 0, w, 60), frame_sum(other, w, w - 200, 0, w, 60));
  // the light level slider: its middle halves the light, the scene right of the panel darkens
  const long day = frame_sum(other, w, w / 2, h / 4, w, h);
  click("Light level");
  EXPECT_NEAR(in.light_level, 0.5, 0.15);
  ASSERT_EQ(sim_viewer_read_rgb(v, other.data()), 0);
  EXPECT_LT(frame_sum(other, w, w / 2, h / 4, w, h), day * 9 / 10);
  click("Quit");
  EXPECT_EQ(in.quit, 1);
  sim_viewer_destroy(v);
  sim_render_destroy(r);
}
