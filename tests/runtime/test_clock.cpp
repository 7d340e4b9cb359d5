// Clock sources: wall mode stamps with the system clock; sim mode follows SIM_CLOCK.
#include <gtest/gtest.h>
#include <lcm/lcm-cpp.hpp>

#include <autodrive/sim_clock_t.hpp>

#include <autodrive/core/clock.hpp>

TEST(Clock, WallModeIsSystemTime) {
  autodrive::clock::Clock c(autodrive::config::ClockMode::wall);
  const int64_t a = autodrive::clock::wall_us();
  const int64_t t = c.now_us();
  EXPECT_GE(t, a);
  EXPECT_FALSE(c.sim());
}

TEST(Clock, SimModeFollowsSimClock) {
  lcm::LCM lcm("memq://");
  ASSERT_TRUE(lcm.good());
  autodrive::clock::Clock c(autodrive::config::ClockMode::sim);
  c.attach(lcm);
  EXPECT_EQ(c.now_us(), 0);  // no SIM_CLOCK yet
  autodrive::sim_clock_t m{};
  m.utime = 123456789;
  m.real_time_factor = 4.0;
  lcm.publish("SIM_CLOCK", &m);
  ASSERT_GT(lcm.handleTimeout(1000), 0);
  EXPECT_EQ(c.now_us(), 123456789);
  m.utime = 123466789;
  lcm.publish("SIM_CLOCK", &m);
  ASSERT_GT(lcm.handleTimeout(1000), 0);
  EXPECT_EQ(c.now_us(), 123466789);
}

// Probe finding: a forged SIM_CLOCK of 0 stopped odometry for 4.7 s. Ticks are believed only
// in sim mode and only when they move forward (by at most Clock::kMaxSimStepUs).
TEST(Clock, SimClockBackwardsOrFarAheadIsRefusedAndCounted) {
  lcm::LCM lcm("memq://");
  ASSERT_TRUE(lcm.good());
  autodrive::clock::Clock c(autodrive::config::ClockMode::sim);
  c.attach(lcm);
  autodrive::sim_clock_t m{};
  auto tick = [&](int64_t t_us) {
    m.utime = t_us;
    lcm.publish("SIM_CLOCK", &m);
    ASSERT_GT(lcm.handleTimeout(1000), 0);
  };
  tick(5000000);
  EXPECT_EQ(c.now_us(), 5000000);
  tick(0);  // the forged reset
  EXPECT_EQ(c.now_us(), 5000000);
  tick(4999999);  // backwards
  EXPECT_EQ(c.now_us(), 5000000);
  tick(5000000 + autodrive::clock::Clock::kMaxSimStepUs +
       1);  // far ahead: would freeze every later tick
  EXPECT_EQ(c.now_us(), 5000000);
  EXPECT_EQ(c.sim_ticks_refused(), 3u);
  tick(5010000);  // the honest next tick still moves it
  EXPECT_EQ(c.now_us(), 5010000);
}

TEST(Clock, SimClockIgnoredInWallMode) {
  lcm::LCM lcm("memq://");
  ASSERT_TRUE(lcm.good());
  autodrive::clock::Clock c(autodrive::config::ClockMode::wall);
  c.attach(lcm);
  autodrive::sim_clock_t m{};
  m.utime = 0;
  lcm.publish("SIM_CLOCK", &m);
  lcm.handleTimeout(50);
  const int64_t before = autodrive::clock::wall_us();
  EXPECT_GE(c.now_us(), before);  // still the wall clock, not 0
  EXPECT_EQ(c.sim_ticks_refused(), 0u);
}
