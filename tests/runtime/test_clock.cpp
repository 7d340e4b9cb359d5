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

// Staleness on a sim clock the test advances (event order, no wall time): fresh() judges age in
// sim time, so a run paced at 0.1x real time judges as one at full speed.
TEST(Clock, FreshJudgesAgeInSimTime) {
  autodrive::clock::Clock c(autodrive::config::ClockMode::sim);
  const int64_t mono = 1000000;  // the test's monotonic time [us]: it never moves here
  EXPECT_FALSE(c.ready());
  EXPECT_FALSE(c.fresh(0, 500000, mono));  // no SIM_CLOCK yet: nothing is fresh
  ASSERT_TRUE(c.set_sim_us(10000000, mono));
  EXPECT_TRUE(c.ready());
  EXPECT_TRUE(c.fresh(9500000, 500000, mono));
  EXPECT_FALSE(c.fresh(9499999, 500000, mono));
  EXPECT_TRUE(c.fresh(10100000, 500000, mono));  // a sender slightly ahead: age <= 0
  ASSERT_TRUE(c.set_sim_us(10010000, mono));
  EXPECT_FALSE(c.fresh(9500000, 500000, mono));  // 10 ms of sim time later: stale
}

// The safety rule: a frozen simulator still fails safe. SIM_CLOCK that stops moving for
// kFrozenAfterUs of monotonic time makes everything stale; a tick that repeats the time is no
// sign of life; the next forward tick thaws it. Wall mode is never frozen.
TEST(Clock, FrozenSimClockMakesEverythingStale) {
  using autodrive::clock::Clock;
  Clock c(autodrive::config::ClockMode::sim);
  int64_t mono = 50000000;
  ASSERT_TRUE(c.set_sim_us(2000000, mono));
  EXPECT_FALSE(c.frozen(mono));
  EXPECT_TRUE(c.fresh(2000000, 100000, mono));
  mono += Clock::kFrozenAfterUs - 1;
  EXPECT_TRUE(c.set_sim_us(2000000, mono));  // the same time again: believed, not alive
  EXPECT_FALSE(c.frozen(mono));
  mono += 2;
  EXPECT_TRUE(c.frozen(mono));
  EXPECT_FALSE(c.fresh(2000000, 100000, mono));  // age 0 in sim time, yet stale
  ASSERT_TRUE(c.set_sim_us(2010000, mono));
  EXPECT_FALSE(c.frozen(mono));
  EXPECT_TRUE(c.fresh(2000000, 100000, mono));
  Clock w(autodrive::config::ClockMode::wall);
  EXPECT_FALSE(w.frozen(mono + 100 * Clock::kFrozenAfterUs));
  EXPECT_TRUE(w.ready());
}

TEST(Clock, ModeNamed) {
  EXPECT_EQ(autodrive::clock::clock_mode_named("sim"), autodrive::config::ClockMode::sim);
  EXPECT_EQ(autodrive::clock::clock_mode_named("wall"), autodrive::config::ClockMode::wall);
  EXPECT_FALSE(autodrive::clock::clock_mode_named("Sim").has_value());
}
