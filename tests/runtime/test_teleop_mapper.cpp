// Teleop mapping: dead-man on keyboard (auto-repeat) and gamepad, lights, quit.
#include <gtest/gtest.h>

#include <autodrive/teleop/teleop_mapper.hpp>

TEST(Teleop, NothingHeldIsDisengaged) {
  autodrive::teleop::Mapper m;
  const auto c = m.command(0);
  EXPECT_FALSE(c.engaged);
  EXPECT_EQ(c.throttle, 0.0f);
}

TEST(Teleop, KeyHeldDrivesReleaseStops) {
  autodrive::teleop::Params p;
  p.key_hold_us = 600000;
  autodrive::teleop::Mapper m(p);
  m.key('w', 1000000);
  auto c = m.command(1100000);
  EXPECT_TRUE(c.engaged);
  EXPECT_FLOAT_EQ(c.throttle, static_cast<float>(p.key_level));
  m.key('w', 1500000);  // auto-repeat keeps it alive
  c = m.command(2000000);
  EXPECT_TRUE(c.engaged);
  c = m.command(2200000);  // no repeat for 700 ms: released
  EXPECT_FALSE(c.engaged);
  EXPECT_EQ(c.throttle, 0.0f);
}

TEST(Teleop, AFreshPressIsHeldThroughTheAutorepeatDelay) {
  // X11's default: the first repeat 660 ms after the press, then every 40 ms (25 Hz).
  autodrive::teleop::Params p;
  ASSERT_GT(p.key_first_hold_us, 660000) << "the default must outlast X11's autorepeat delay";
  autodrive::teleop::Mapper m(p);
  m.key('w', 0);
  for (int64_t t = 0; t < 660000; t += 20000)  // 50 Hz publishing before the first repeat
    EXPECT_TRUE(m.command(t).engaged) << "stuttered at " << t << " us";
  m.key('w', 660000);                                   // the first repeat
  for (int64_t t = 680000; t <= 1000000; t += 40000) {  // then every 40 ms, the last at 1 s
    m.key('w', t);
    EXPECT_TRUE(m.command(t + 20000).engaged);
  }
  // Once repeating, the release is seen after key_hold_us as before.
  EXPECT_TRUE(m.command(1000000 + p.key_hold_us).engaged);
  EXPECT_FALSE(m.command(1000000 + p.key_hold_us + 1).engaged);
  // A fresh press with no repeat at all (a tap) ends after key_first_hold_us.
  m.key('s', 5000000);
  EXPECT_TRUE(m.command(5000000 + p.key_first_hold_us).engaged);
  EXPECT_FALSE(m.command(5000000 + p.key_first_hold_us + 1).engaged);
}

TEST(Teleop, SpaceStopsAtOnce) {
  autodrive::teleop::Mapper m;
  m.key('s', 0);
  EXPECT_LT(m.command(1000).throttle, 0.0f);
  m.key(' ', 2000);
  EXPECT_FALSE(m.command(3000).engaged);
}

TEST(Teleop, SteeringAloneDoesNotDrive) {
  autodrive::teleop::Mapper m;
  m.key('a', 0);
  const auto c = m.command(1000);
  EXPECT_FLOAT_EQ(c.steering, 1.0f);
  EXPECT_FALSE(c.engaged);
  EXPECT_EQ(c.throttle, 0.0f);
}

TEST(Teleop, GamepadNeedsDeadman) {
  autodrive::teleop::Params p;
  autodrive::teleop::Mapper m(p);
  m.js_axis(p.throttle_axis, -32767);  // stick fully up
  m.js_axis(p.steering_axis, 16384);   // half right
  EXPECT_FALSE(m.command(0).engaged);
  m.js_button(p.deadman_button, true);
  auto c = m.command(1);
  EXPECT_TRUE(c.engaged);
  EXPECT_NEAR(c.throttle, p.max_throttle, 1e-3);
  EXPECT_NEAR(c.steering, -0.5, 1e-3);
  m.js_button(p.deadman_button, false);
  c = m.command(2);
  EXPECT_FALSE(c.engaged);
  EXPECT_EQ(c.throttle, 0.0f);
}

TEST(Teleop, GamepadLostStops) {
  autodrive::teleop::Params p;
  autodrive::teleop::Mapper m(p);
  m.js_button(p.deadman_button, true);
  m.js_axis(p.throttle_axis, -32767);
  m.js_lost();
  EXPECT_FALSE(m.command(0).engaged);
}

TEST(Teleop, LightsCycleAndToggle) {
  autodrive::teleop::Mapper m;
  m.key('h', 0);
  m.key('h', 0);
  EXPECT_EQ(m.command(0).headlights, 2);
  m.key('h', 0);
  EXPECT_EQ(m.command(0).headlights, 0);
  m.key('z', 0);
  EXPECT_EQ(m.command(0).indicators, 1);
  m.key('x', 0);
  EXPECT_EQ(m.command(0).indicators, 3);
  m.key('x', 0);
  EXPECT_EQ(m.command(0).indicators, 0);
}

TEST(Teleop, QuitKey) {
  autodrive::teleop::Mapper m;
  EXPECT_TRUE(m.key('w', 0));
  EXPECT_FALSE(m.key('q', 0));
}

TEST(Teleop, SeqIncrements) {
  autodrive::teleop::Mapper m;
  EXPECT_EQ(m.command(0).seq, 0);
  EXPECT_EQ(m.command(0).seq, 1);
}
