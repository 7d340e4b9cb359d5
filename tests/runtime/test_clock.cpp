// Clock sources: wall mode stamps with the system clock; sim mode follows SIM_CLOCK.
#include <gtest/gtest.h>
#include <lcm/lcm-cpp.hpp>

#include <autodrive/sim_clock_t.hpp>

#include "common/clock.hpp"

TEST(Clock, WallModeIsSystemTime) {
  clk::Clock c(cfg::ClockMode::wall);
  const int64_t a = clk::wall_us();
  const int64_t t = c.now_us();
  EXPECT_GE(t, a);
  EXPECT_FALSE(c.sim());
}

TEST(Clock, SimModeFollowsSimClock) {
  lcm::LCM lcm("memq://");
  ASSERT_TRUE(lcm.good());
  clk::Clock c(cfg::ClockMode::sim);
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
