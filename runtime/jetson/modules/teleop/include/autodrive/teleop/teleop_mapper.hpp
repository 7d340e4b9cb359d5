// Teleop input -> vehicle_command_t (no I/O). Dead-man everywhere: the car moves only while
// the operator is actively holding the control.
//  - Keyboard (a terminal sends no key-release events): w/s drive forward/back and a/d steer
//    while their key auto-repeats; no repeat for `key_hold_us` = released -> throttle 0,
//    steering centred, disengaged. A fresh press is held for `key_first_hold_us` instead: the
//    first repeat only comes after the platform's autorepeat delay (X11: 660 ms by default). Space
//    stops at once. +/- change the drive level. h cycles headlights (off/low/high); z left, c
//    right, x hazard indicators (again = off).
//  - Gamepad (Linux joystick API): the dead-man button must be held; left stick Y = throttle,
//    right stick X = steering. Buttons cycle headlights and toggle indicators.
#pragma once

#include <autodrive/vehicle_command_t.hpp>

#include <cstdint>

namespace autodrive::teleop {

constexpr int64_t kKeyRepeatMarginUs = 150000;  // hold beyond the autorepeat delay [us]

struct Params {
  double max_throttle = 0.6;     // full stick / top key level [-]
  double key_level = 0.4;        // initial keyboard drive level [-]
  int64_t key_hold_us = 600000;  // no repeat for this long = key released [us]
  // A fresh press, before its first repeat: the autorepeat delay (X11's default 660 ms) plus
  // kKeyRepeatMarginUs. autodrive-teleop sets it from the platform's delay where it can.
  int64_t key_first_hold_us = 660000 + kKeyRepeatMarginUs;
  int deadman_button = 4;  // gamepad button (LB on most pads)
  int headlight_button = 0;
  int left_button = 2, right_button = 1, hazard_button = 3;
  int throttle_axis = 1;        // left stick Y (up is negative)
  int steering_axis = 3;        // right stick X (right is positive)
  double axis_deadzone = 0.08;  // [-], fraction of full scale
};

class Mapper {
 public:
  explicit Mapper(Params p = {}) : p_(p) {}
  // Keyboard byte at time t_us. Returns false for 'q' (quit).
  bool key(char c, int64_t t_us);
  void js_axis(int number, int16_t value);
  void js_button(int number, bool pressed);
  void js_lost();  // gamepad unplugged: treat as released
  // The command to publish now (seq increments per call).
  autodrive::vehicle_command_t command(int64_t t_us);
  double key_level() const { return level_; }

 private:
  void toggle_indicator(int8_t which);
  Params p_;
  double level_ = p_.key_level;
  int key_drive_ = 0, key_steer_ = 0;  // -1, 0, +1
  int64_t drive_t_us_ = -1, steer_t_us_ = -1;
  bool drive_repeating_ = false, steer_repeating_ = false;  // the key has repeated since its press
  bool held(int64_t since_us, bool repeating, int64_t t_us) const;
  void press(int *axis, int value, int64_t *since_us, bool *repeating, int64_t t_us);
  bool deadman_ = false;
  double js_throttle_ = 0, js_steer_ = 0;
  int8_t headlights_ = 0, indicators_ = 0;
  int32_t seq_ = 0;
};

}  // namespace autodrive::teleop
