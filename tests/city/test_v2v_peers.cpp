// V2V peer table: own broadcasts ignored, newest state per peer kept, states older than the
// stale limit dropped and counted, and the runtime config's V2V keys read strictly. The per-peer
// account: time in the table and time holding the car, per name and certificate serial.
#include <autodrive/v2v/peer_account.hpp>
#include <autodrive/v2v/v2v_peers.hpp>
#include <gtest/gtest.h>

#include <autodrive/core/config.hpp>

namespace {

autodrive::v2v_state_t state(const std::string &vehicle, int64_t utime_us, double x_m = 0.0) {
  autodrive::v2v_state_t s{};
  s.vehicle = vehicle;
  s.utime = utime_us;
  s.x_m = x_m;
  s.route = "loop_ccw";
  s.route_s_m = -1.0f;
  return s;
}

}  // namespace

TEST(PeerTable, IgnoresItselfAndKeepsTheNewestStatePerPeer) {
  autodrive::v2v::PeerTable t("NIGEL1");
  t.on_state(state("NIGEL1", 1000), 1000);
  t.on_state(state("NIGEL2", 1000, 1.0), 1000);
  t.on_state(state("NIGEL2", 3000, 2.0), 3000);
  t.on_state(state("NIGEL2", 2000, 9.0), 3100);  // reordered by the network: ignored
  t.on_state(state("NIGEL3", 2500, 3.0), 3100);
  const auto f = t.fresh(3200);
  ASSERT_EQ(f.size(), 2u);
  EXPECT_EQ(f[0].vehicle, "NIGEL2");
  EXPECT_DOUBLE_EQ(f[0].x_m, 2.0);
  EXPECT_EQ(f[1].vehicle, "NIGEL3");
  EXPECT_EQ(t.received(), 3u);
  EXPECT_EQ(t.dropped_stale(), 0u);
}

TEST(PeerTable, DropsAndCountsStatesOlderThan200ms) {
  autodrive::v2v::PeerTable t("NIGEL1");  // default limit: 200 ms
  EXPECT_EQ(t.stale_us(), 200000);
  t.on_state(state("NIGEL2", 1000000), 1000000);
  t.on_state(state("NIGEL3", 1150000), 1150000);
  EXPECT_EQ(t.fresh(1200000).size(), 2u);  // 200 ms old exactly: still fresh
  const auto f = t.fresh(1200001);         // NIGEL2 is 200.001 ms old now
  ASSERT_EQ(f.size(), 1u);
  EXPECT_EQ(f[0].vehicle, "NIGEL3");
  EXPECT_EQ(t.dropped_stale(), 1u);
  EXPECT_TRUE(t.fresh(2000000).empty());
  EXPECT_EQ(t.dropped_stale(), 2u);
  EXPECT_EQ(autodrive::v2v::status_line({}, t.dropped_stale()),
            "0 fresh peer(s), 2 stale state(s) dropped");
  // A peer that speaks again is back.
  t.on_state(state("NIGEL2", 2100000), 2100000);
  EXPECT_EQ(autodrive::v2v::status_line(t.fresh(2150000), t.dropped_stale()),
            "1 fresh peer(s) (NIGEL2), 2 stale state(s) dropped");
}

TEST(PeerTable, OwnLimit) {
  autodrive::v2v::PeerTable t("NIGEL4", 50000);
  t.on_state(state("NIGEL1", 0), 0);
  EXPECT_EQ(t.fresh(50000).size(), 1u);
  EXPECT_TRUE(t.fresh(50001).empty());
}

namespace {
const char *kBase =
    "lcm_url: \"memq://\"\nclock: sim\nvehicle: {name: NIGEL2}\nestimator: {rate_hz: 100";
}

TEST(RuntimeConfigV2v, DefaultsAndKeys) {
  auto c = autodrive::config::parse(std::string(kBase) + "}\n", "t.yaml");
  EXPECT_DOUBLE_EQ(c.v2v_hz, 20.0);
  EXPECT_EQ(c.v2v_stale_ms, 200);
  EXPECT_EQ(c.route, "");
  EXPECT_FALSE(c.estimator.has_initial_pose_map);
  c = autodrive::config::parse(
      std::string(kBase) + ", initial_pose_map: [1.5, -2.0, 0.5]}\nv2v_hz: 10\nroute: loop_cw\n",
      "t.yaml");
  EXPECT_DOUBLE_EQ(c.v2v_hz, 10.0);
  EXPECT_EQ(c.route, "loop_cw");
  ASSERT_TRUE(c.estimator.has_initial_pose_map);
  EXPECT_DOUBLE_EQ(c.estimator.initial_pose_map[1], -2.0);
}

TEST(RuntimeConfigV2v, BadValuesNameTheKey) {
  try {
    autodrive::config::parse(std::string(kBase) + "}\nv2v_hz: 500\n", "t.yaml");
    FAIL() << "accepted v2v_hz 500";
  } catch (const autodrive::config::Error &e) {
    EXPECT_NE(std::string(e.what()).find("v2v_hz"), std::string::npos) << e.what();
  }
  try {
    autodrive::config::parse(std::string(kBase) + ", initial_pose_map: [1, 2]}\n", "t.yaml");
    FAIL() << "accepted a 2-number pose";
  } catch (const autodrive::config::Error &e) {
    EXPECT_NE(std::string(e.what()).find("estimator.initial_pose_map"), std::string::npos)
        << e.what();
  }
}

// The stale limit on a sim clock the test advances (event order, no wall time): age in sim
// time, and no peer at all while the clock has no SIM_CLOCK yet or is frozen.
TEST(PeerTable, StaleLimitOnTheSimClock) {
  using autodrive::clock::Clock;
  Clock clock(autodrive::config::ClockMode::sim);
  autodrive::v2v::PeerTable t("NIGEL1", 200000);
  t.on_state(state("NIGEL2", 1000000), 0);
  EXPECT_TRUE(t.fresh(clock).empty());  // no SIM_CLOCK yet: nothing believed
  EXPECT_EQ(t.dropped_stale(), 1u);
  const int64_t mono = autodrive::clock::monotonic_us();  // the backstop's time, held still
  ASSERT_TRUE(clock.set_sim_us(1100000, mono));
  t.on_state(state("NIGEL2", 1000000), clock.now_us());
  EXPECT_EQ(t.fresh(clock).size(), 1u);  // 100 ms of sim time old
  ASSERT_TRUE(clock.set_sim_us(1200000, mono));
  EXPECT_EQ(t.fresh(clock).size(), 1u);  // 200 ms: the limit itself is fresh
  ASSERT_TRUE(clock.set_sim_us(1200001, mono));
  EXPECT_TRUE(t.fresh(clock).empty());
  EXPECT_EQ(t.dropped_stale(), 2u);
}

TEST(PeerTable, FrozenSimClockDropsEveryPeer) {
  using autodrive::clock::Clock;
  Clock clock(autodrive::config::ClockMode::sim);
  autodrive::v2v::PeerTable t("NIGEL1", 200000);
  // The last tick came kFrozenAfterUs + 1 us of monotonic time ago: the simulator froze.
  ASSERT_TRUE(clock.set_sim_us(1000000,
                               autodrive::clock::monotonic_us() - Clock::kFrozenAfterUs - 1000000));
  t.on_state(state("NIGEL2", 1000000), clock.now_us());
  EXPECT_TRUE(clock.frozen());
  EXPECT_TRUE(t.fresh(clock).empty());  // age 0 in sim time, yet not believed
  EXPECT_EQ(t.dropped_stale(), 1u);
}

// Each step's peers are charged the time until the next step [s of the receiver's clock]; the
// holding one also its held time; a name under another certificate is a peer of its own.
TEST(PeerAccount, ChargesTableAndHeldTimePerNameAndCertificate) {
  autodrive::v2v::PeerAccount a;
  const auto n2 = state("NIGEL2", 1000000), n3 = state("NIGEL3", 1000000);
  a.accepted(n2, 22);
  a.accepted(n3, 33);
  a.step(1000000, {n2, n3}, 1);   // NIGEL3 holds the car from 1.0 s
  a.step(1020000, {n2, n3}, -1);  // 20 ms later: nobody holds it
  a.step(1040000, {n2}, 0);       // NIGEL2 holds it from 1.04 s ...
  a.step(1100000, {}, -1);        // ... to 1.1 s
  auto forged = state("NIGEL2", 1200000);
  a.accepted(forged, 99);  // the newest NIGEL2 state came from another certificate
  a.step(1200000, {forged}, 0);
  a.step(1250000, {}, -1);
  const auto r = a.records();
  ASSERT_EQ(r.size(), 3u);
  EXPECT_EQ(r[0].name, "NIGEL2");
  EXPECT_EQ(r[0].serial, 22u);
  EXPECT_NEAR(r[0].in_table_s, 0.1, 1e-9);
  EXPECT_NEAR(r[0].held_s, 0.06, 1e-9);
  EXPECT_EQ(r[1].serial, 99u);
  EXPECT_NEAR(r[1].held_s, 0.05, 1e-9);
  EXPECT_EQ(r[2].name, "NIGEL3");
  EXPECT_NEAR(r[2].in_table_s, 0.04, 1e-9);
  EXPECT_NEAR(r[2].held_s, 0.02, 1e-9);
  EXPECT_EQ(r[2].accepted, 1u);
}

TEST(PeerAccount, ReportsOneJsonArray) {
  autodrive::v2v::PeerAccount a;
  EXPECT_EQ(a.json(), "[]");
  const auto odd = state("N\"2", 0);  // a name the wire could carry: escaped
  a.accepted(odd, 18446744073709551615ull);
  a.step(0, {odd}, 0);
  a.step(500000, {}, -1);
  EXPECT_EQ(a.json(),
            "[{\"name\":\"N\\\"2\",\"serial\":\"18446744073709551615\",\"accepted\":1,"
            "\"in_table_s\":0.500,\"held_s\":0.500}]");
}
