// The bridge's token bucket and idle heartbeat (nano_bridge/command_pacer.hpp), driven with
// explicit times: the cap is checked against the bucket's arithmetic, never against wall time.
#include <gtest/gtest.h>

#include <autodrive/nano_bridge/command_pacer.hpp>

namespace {

using autodrive::bridge::CommandPacer;

constexpr int kBurst = 4;
constexpr double kRateHz = 100.0;
constexpr int64_t kHeartbeatUs = 20000;  // 50 Hz

TEST(CommandPacer, AFreshCommandGoesAtOnce) {
  CommandPacer p(kBurst, kRateHz, kHeartbeatUs);
  p.restart(1000000);
  EXPECT_TRUE(p.due(1000000));  // the first heartbeat on linking
  // A command 5 ms after a frame (a quarter of the heartbeat period) goes in the same call.
  EXPECT_TRUE(p.command(1005000));
  EXPECT_FALSE(p.holding());
  EXPECT_FALSE(p.due(1005000));
}

TEST(CommandPacer, HeartbeatOnlyWhenNoCommandWentOutWithinItsPeriod) {
  CommandPacer p(kBurst, kRateHz, kHeartbeatUs);
  p.restart(0);
  ASSERT_TRUE(p.due(0));
  // Commands every 15 ms (under the 20 ms period): no heartbeat in between, ever.
  int heartbeats = 0;
  for (int64_t t = 1000; t < 1000000; t += 1000) {
    if (t % 15000 == 0) {
      EXPECT_TRUE(p.command(t));
    } else {
      heartbeats += p.due(t) ? 1 : 0;
    }
  }
  EXPECT_EQ(heartbeats, 0);
  // Silence: a heartbeat one period after the last command, then every period.
  const int64_t last = 990000;  // the last multiple of 15 ms below 1 s
  EXPECT_FALSE(p.due(last + kHeartbeatUs - 1));
  EXPECT_TRUE(p.due(last + kHeartbeatUs));
  EXPECT_EQ(p.next_due_us(), last + 2 * kHeartbeatUs);
  EXPECT_TRUE(p.due(last + 2 * kHeartbeatUs));
}

TEST(CommandPacer, AFloodIsCappedAtTheBucketRate) {
  CommandPacer p(kBurst, kRateHz, kHeartbeatUs);
  p.restart(0);
  // 40 000 commands a second for 10 s, and the loop polls due() between them.
  const int64_t span_us = 10000000;
  int64_t frames = 0;
  for (int64_t t = 0; t < span_us; t += 25) {
    frames += p.command(t) ? 1 : 0;
    frames += p.due(t) ? 1 : 0;
  }
  // At most burst + span * rate, and the bucket never sits idle with a command held.
  const int64_t cap = kBurst + static_cast<int64_t>(span_us * kRateHz / 1e6);
  EXPECT_LE(frames, cap);
  EXPECT_GE(frames, cap - 1);
}

TEST(CommandPacer, AHeldCommandGoesWhenItsTokenIsBack) {
  CommandPacer p(2, kRateHz, kHeartbeatUs);  // 10 ms per token
  p.restart(0);
  EXPECT_TRUE(p.command(0));
  EXPECT_TRUE(p.command(0));
  EXPECT_FALSE(p.command(0));  // the bucket is empty: held
  EXPECT_TRUE(p.holding());
  EXPECT_EQ(p.next_due_us(), 10000);
  EXPECT_FALSE(p.due(9999));
  EXPECT_TRUE(p.due(10000));
  EXPECT_FALSE(p.holding());
}

TEST(CommandPacer, HeartbeatAfterAFloodStillFindsAToken) {
  CommandPacer p(kBurst, kRateHz, kHeartbeatUs);
  p.restart(0);
  for (int64_t t = 0; t < 100000; t += 10) p.command(t);
  // The flood stops with a command held; it goes with the next token, then heartbeats follow
  // at their period, each with a token (rate >= heartbeat rate).
  int64_t t = 100000;
  while (!p.due(t)) ++t;
  EXPECT_FALSE(p.holding());
  for (int k = 1; k <= 5; ++k) EXPECT_TRUE(p.due(t + k * kHeartbeatUs));
}

}  // namespace
