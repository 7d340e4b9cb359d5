#include <autodrive/teleop/teleop_mapper.hpp>

#include <algorithm>
#include <cmath>

namespace autodrive::teleop {

void Mapper::toggle_indicator(int8_t which) {
  indicators_ = indicators_ == which ? 0 : which;
}

bool Mapper::held(int64_t since_us, bool repeating, int64_t t_us) const {
  return since_us >= 0 && t_us - since_us <= (repeating ? p_.key_hold_us : p_.key_first_hold_us);
}

// The same key again while it is held is its autorepeat; anything else is a fresh press.
void Mapper::press(int *axis, int value, int64_t *since_us, bool *repeating, int64_t t_us) {
  *repeating = *axis == value && held(*since_us, *repeating, t_us);
  *axis = value;
  *since_us = t_us;
}

bool Mapper::key(char c, int64_t t) {
  switch (c) {
    case 'w':
    case 'W': press(&key_drive_, 1, &drive_t_us_, &drive_repeating_, t); break;
    case 's':
    case 'S': press(&key_drive_, -1, &drive_t_us_, &drive_repeating_, t); break;
    case 'a':
    case 'A': press(&key_steer_, 1, &steer_t_us_, &steer_repeating_, t); break;  // + left
    case 'd':
    case 'D': press(&key_steer_, -1, &steer_t_us_, &steer_repeating_, t); break;
    case ' ':
      key_drive_ = 0;
      key_steer_ = 0;
      drive_t_us_ = steer_t_us_ = -1;
      break;
    case '+':
    case '=': level_ = std::min(p_.max_throttle, level_ + 0.05); break;
    case '-':
    case '_': level_ = std::max(0.05, level_ - 0.05); break;
    case 'h':
    case 'H': headlights_ = static_cast<int8_t>((headlights_ + 1) % 3); break;
    case 'z':
    case 'Z': toggle_indicator(1); break;
    case 'c':
    case 'C': toggle_indicator(2); break;
    case 'x':
    case 'X': toggle_indicator(3); break;
    case 'q':
    case 'Q':
    case 3 /* Ctrl-C in raw mode */: return false;
    default: break;
  }
  return true;
}

void Mapper::js_axis(int number, int16_t value) {
  double v = value / 32767.0;
  if (std::fabs(v) < p_.axis_deadzone) v = 0.0;
  v = std::clamp(v, -1.0, 1.0);
  if (number == p_.throttle_axis) js_throttle_ = -v;  // stick up = forward
  if (number == p_.steering_axis) js_steer_ = -v;     // stick right = steer right (negative)
}

void Mapper::js_button(int number, bool pressed) {
  if (number == p_.deadman_button) deadman_ = pressed;
  if (!pressed) return;
  if (number == p_.headlight_button) headlights_ = static_cast<int8_t>((headlights_ + 1) % 3);
  if (number == p_.left_button) toggle_indicator(1);
  if (number == p_.right_button) toggle_indicator(2);
  if (number == p_.hazard_button) toggle_indicator(3);
}

void Mapper::js_lost() {
  deadman_ = false;
  js_throttle_ = js_steer_ = 0.0;
}

autodrive::vehicle_command_t Mapper::command(int64_t t) {
  autodrive::vehicle_command_t c{};
  c.utime = t;
  c.seq = seq_++;
  c.headlights = headlights_;
  c.indicators = indicators_;
  const bool drive_held = held(drive_t_us_, drive_repeating_, t);
  const bool steer_held = held(steer_t_us_, steer_repeating_, t);
  if (deadman_) {
    c.throttle = static_cast<float>(js_throttle_ * p_.max_throttle);
    c.steering = static_cast<float>(js_steer_);
    c.engaged = true;
  } else if (drive_held || steer_held) {
    c.throttle = drive_held ? static_cast<float>(key_drive_ * level_) : 0.0f;
    c.steering = steer_held ? static_cast<float>(key_steer_) : 0.0f;
    c.engaged = drive_held;
  } else {
    c.engaged = false;  // nothing held: stop
  }
  if (!c.engaged) c.throttle = 0.0f;
  return c;
}

}  // namespace autodrive::teleop
