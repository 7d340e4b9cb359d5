// OdomHistory: odometry looked up at a scan's time, interpolated, clamped and reset.
#include <gtest/gtest.h>

#include <autodrive/autonomy/odom_history.hpp>

using namespace autodrive::autonomy;

TEST(OdomHistory, InterpolatesBetweenSamplesAcrossTheHeadingWrap) {
  OdomHistory h;
  EXPECT_FALSE(h.at(0).has_value());
  h.add(1000000, {0.0, 0.0, 3.10});
  h.add(1010000, {0.002, 0.0, -3.10});  // crossed +-pi: +0.083 rad of turn [rad]
  const Pose2 mid = *h.at(1005000);
  EXPECT_NEAR(mid.x_m, 0.001, 1e-4);
  EXPECT_NEAR(std::abs(mid.yaw_rad), kPi, 1e-3);  // half way, on the wrap, not at 0 rad
}

TEST(OdomHistory, ClampsOutsideTheKeptSpanAndForgetsOldSamples) {
  OdomHistory h(100000);                                                 // keep 0.1 s
  for (int i = 0; i <= 50; ++i) h.add(i * 10000, {0.01 * i, 0.0, 0.0});  // 1 m/s for 0.5 s
  EXPECT_NEAR(h.at(900000)->x_m, 0.50, 1e-9);   // after the newest: the newest
  EXPECT_NEAR(h.at(0)->x_m, 0.40, 1e-9);        // older than kept: the oldest kept (0.4 s)
  EXPECT_NEAR(h.at(455000)->x_m, 0.455, 1e-9);  // 0.455 s at 1 m/s [m]
}

TEST(OdomHistory, AClockThatGoesBackStartsAfresh) {
  OdomHistory h;
  h.add(5000000, {1.0, 0.0, 0.0});
  h.add(1000000, {2.0, 0.0, 0.0});  // a restarted sim clock
  EXPECT_NEAR(h.at(5000000)->x_m, 2.0, 1e-12);
}
