// The firmware core on the host fake HAL with fake time: boot, arming, failsafe timing,
// re-arm rules, range rejection, actuators, lights, battery, IMU faults, telemetry, hello.
#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <vector>

#include "fake_hal.h"
#include "nano_core.h"

namespace {

constexpr uint32_t kMs = 1000;  // [us]

class Core : public ::testing::Test {
 protected:
  void SetUp() override { Boot(0, 0); }
  void Boot(uint32_t t0_us, uint8_t wdt) {
    t_us = t0_us;
    nano_core_init(&n, fake.hal(), t_us, wdt, 0xC0FFEE01u);
  }
  // Runs the loop at 1 kHz for ms milliseconds, encoders advancing by enc_rate [counts/s].
  void Run(uint32_t ms) {
    for (uint32_t i = 0; i < ms; ++i) {
      t_us += kMs;
      enc_l += enc_rate_l;
      enc_r += enc_rate_r;
      nano_core_step(&n, t_us, static_cast<int32_t>(enc_l / 1000),
                     static_cast<int32_t>(enc_r / 1000));
    }
  }
  void Send(uint8_t id, const uint8_t *payload, uint8_t len) {
    uint8_t f[PROTOCOL_MAX_FRAME];
    size_t sz = protocol_frame_encode(id, tx_seq++, payload, len, f, sizeof f);
    ASSERT_GT(sz, 0u);
    nano_core_rx(&n, f, static_cast<uint8_t>(sz), t_us);
  }
  void Command(int16_t thr, int16_t steer, bool engaged, uint8_t head = 0, uint8_t ind = 0,
               uint8_t extra_flags = 0) {
    protocol_command_t c{
        cmd_seq++, thr, steer,
        head,      ind, static_cast<uint8_t>((engaged ? PROTOCOL_CMD_ENGAGED : 0) | extra_flags)};
    uint8_t p[PROTOCOL_LEN_COMMAND];
    protocol_command_pack(&c, p);
    Send(PROTOCOL_ID_COMMAND, p, PROTOCOL_LEN_COMMAND);
  }
  void Config(int16_t trim, uint16_t period_ms, uint16_t timeout_ms) {
    protocol_config_t c{trim, period_ms, timeout_ms};
    uint8_t p[PROTOCOL_LEN_CONFIG];
    protocol_config_pack(&c, p);
    Send(PROTOCOL_ID_CONFIG, p, PROTOCOL_LEN_CONFIG);
  }
  // Streams commands every period_ms for ms milliseconds.
  void Stream(uint32_t ms, int16_t thr, int16_t steer, bool engaged, uint32_t period_ms = 20,
              uint8_t head = 0, uint8_t ind = 0) {
    for (uint32_t t = 0; t < ms; t += period_ms) {
      Command(thr, steer, engaged, head, ind);
      Run(period_ms);
    }
  }
  void Arm() {
    Command(0, 0, false);
    Run(10);
    Command(0, 0, true);
    Run(1);
    ASSERT_EQ(n.failsafe.mode, PROTOCOL_MODE_ENGAGED);
  }
  protocol_state_t LastState() {
    auto s = fake.Take(PROTOCOL_ID_STATE);
    EXPECT_FALSE(s.empty());
    protocol_state_t st{};
    if (!s.empty()) {
      EXPECT_EQ(protocol_state_unpack(s.back().payload, s.back().len, &st), 0);
    }
    return st;
  }
  std::vector<protocol_nack_t> Nacks() {
    std::vector<protocol_nack_t> out;
    for (auto &f : fake.Take(PROTOCOL_ID_NACK)) {
      protocol_nack_t k{};
      EXPECT_EQ(protocol_nack_unpack(f.payload, f.len, &k), 0);
      out.push_back(k);
    }
    return out;
  }

  FakeHal fake;
  nano_core_t n{};
  uint32_t t_us = 0;
  int64_t enc_l = 0, enc_r = 0;            // [counts/1000]
  int64_t enc_rate_l = 0, enc_rate_r = 0;  // [counts/1000 per 1 ms step] = [counts/s]
  uint8_t tx_seq = 0;
  uint16_t cmd_seq = 1;
};

TEST_F(Core, BootsDisarmedSilentAndSendsHello) {
  EXPECT_EQ(fake.duty, 0);
  EXPECT_EQ(fake.brake, 1);
  EXPECT_EQ(fake.servo_us, 1500);
  EXPECT_EQ(fake.lamps, 0);
  auto hello = fake.Take(PROTOCOL_ID_HELLO);
  ASSERT_EQ(hello.size(), 1u);
  protocol_hello_t h{};
  ASSERT_EQ(protocol_hello_unpack(hello[0].payload, hello[0].len, &h), 0);
  EXPECT_EQ(h.fw_major, NIGEL_FW_MAJOR);
  EXPECT_EQ(h.proto_version, PROTOCOL_VERSION);
  EXPECT_EQ(h.schema_hash, protocol_schema_hash());
  EXPECT_EQ(h.build_id, 0xC0FFEE01u);
  Run(100);
  protocol_state_t s = LastState();
  EXPECT_EQ(s.mode, PROTOCOL_MODE_DISARMED);
  EXPECT_EQ(s.faults, 0);
  EXPECT_EQ(fake.duty, 0);
  EXPECT_EQ(fake.brake, 1);
}

TEST_F(Core, HelloRequestAnswered) {
  fake.Take(PROTOCOL_ID_HELLO);
  Send(PROTOCOL_ID_HELLO_REQUEST, nullptr, 0);
  EXPECT_EQ(fake.Take(PROTOCOL_ID_HELLO).size(), 1u);
  uint8_t junk = 0;
  Send(PROTOCOL_ID_HELLO_REQUEST, &junk, 1);  // wrong length
  auto k = Nacks();
  ASSERT_EQ(k.size(), 1u);
  EXPECT_EQ(k[0].reason, PROTOCOL_NACK_BAD_LENGTH);
  EXPECT_TRUE(fake.Take(PROTOCOL_ID_HELLO).empty());
}

TEST_F(Core, EngagedStreamWithoutDisengagedFirstDoesNotMove) {
  Stream(500, 800, 0, true);
  EXPECT_EQ(n.failsafe.mode, PROTOCOL_MODE_DISARMED);
  EXPECT_EQ(fake.duty, 0);
  EXPECT_EQ(fake.brake, 1);
}

TEST_F(Core, EngageSequenceDrivesWithSlewLimit) {
  Arm();
  Command(1000, 0, true);
  Run(50);
  // 4.0 full scale/s: 50 ms -> 0.2 -> duty 51 (+-1 for the step quantisation)
  EXPECT_NEAR(fake.duty, 51, 1);
  EXPECT_EQ(fake.brake, 0);
  EXPECT_EQ(fake.reverse, 0);
  Command(1000, 0, true);
  Run(50);
  Command(1000, 0, true);
  Run(50);
  Command(1000, 0, true);
  Run(50);
  Command(1000, 0, true);
  Run(50);
  EXPECT_EQ(fake.duty, 255);
  Command(1000, 0, true);
  Run(10);
  protocol_state_t s = LastState();
  EXPECT_EQ(s.mode, PROTOCOL_MODE_ENGAGED);
  EXPECT_EQ(s.throttle_milli, 1000);
  EXPECT_EQ(s.last_cmd_seq, cmd_seq - 1);
  // disengage: stops at once, no fault
  Command(1000, 0, false);
  Run(1);
  EXPECT_EQ(fake.duty, 0);
  EXPECT_EQ(fake.brake, 1);
  EXPECT_EQ(n.failsafe.mode, PROTOCOL_MODE_DISARMED);
  EXPECT_EQ(nano_core_faults(&n), 0);
}

TEST_F(Core, ReverseSlewsThroughZero) {
  Arm();
  Stream(400, 1000, 0, true);
  EXPECT_EQ(fake.duty, 255);
  Command(-1000, 0, true);
  Run(20);  // 0.08 down from 1.0
  EXPECT_EQ(fake.reverse, 0);
  EXPECT_NEAR(fake.duty, 235, 1);
  Stream(600, -1000, 0, true);
  EXPECT_EQ(fake.reverse, 1);
  EXPECT_EQ(fake.duty, 255);
  EXPECT_TRUE(fake.lamps & NANO_CORE_LAMP_REVERSE);
}

TEST_F(Core, FailsafeTripsAtTimeoutNotBefore) {
  Arm();
  Stream(300, 600, 0, true);
  Command(600, 0, true);
  const uint32_t t_last = t_us;
  while (t_us - t_last < 99 * kMs) Run(1);
  EXPECT_EQ(n.failsafe.mode, PROTOCOL_MODE_ENGAGED) << "tripped early";
  EXPECT_GT(fake.duty, 0);
  Run(1);  // 100 ms since the last valid command
  EXPECT_EQ(n.failsafe.mode, PROTOCOL_MODE_FAILSAFE);
  EXPECT_EQ(fake.duty, 0);
  EXPECT_EQ(fake.brake, 1);
  EXPECT_EQ(fake.lamps & (NANO_CORE_LAMP_IND_LEFT | NANO_CORE_LAMP_IND_RIGHT),
            NANO_CORE_LAMP_IND_LEFT | NANO_CORE_LAMP_IND_RIGHT);  // hazards, first half period lit
  EXPECT_TRUE(fake.lamps & NANO_CORE_LAMP_TAIL);
  Run(20);
  protocol_state_t s = LastState();
  EXPECT_EQ(s.mode, PROTOCOL_MODE_FAILSAFE);
  EXPECT_TRUE(s.faults & PROTOCOL_FAULT_LINK_LOST);
  EXPECT_EQ(s.throttle_milli, 0);
  EXPECT_EQ((s.lights & PROTOCOL_LIGHTS_IND_MASK) >> PROTOCOL_LIGHTS_IND_SHIFT, 3u);
}

TEST_F(Core, FailsafeWhenCommandArrivesLateBeforeAnyStep) {
  Arm();
  Stream(100, 500, 0, true);
  t_us += 200 * kMs;  // the loop stalled, then a command arrives first
  Command(500, 0, true);
  EXPECT_EQ(n.failsafe.mode, PROTOCOL_MODE_FAILSAFE);
  Run(1);
  EXPECT_EQ(fake.duty, 0);
  EXPECT_TRUE(nano_core_faults(&n) & PROTOCOL_FAULT_LINK_LOST);
}

TEST_F(Core, FailsafeReArmNeedsDisengagedThenEngaged) {
  Arm();
  Stream(100, 500, 0, true);
  Run(150);
  ASSERT_EQ(n.failsafe.mode, PROTOCOL_MODE_FAILSAFE);
  // the stream coming back with engaged=1 does not re-arm
  Stream(300, 500, 0, true);
  EXPECT_EQ(n.failsafe.mode, PROTOCOL_MODE_FAILSAFE);
  EXPECT_EQ(fake.duty, 0);
  EXPECT_TRUE(nano_core_faults(&n) & PROTOCOL_FAULT_LINK_LOST);
  // engaged=0 alone keeps the latched fault and the failsafe
  Stream(100, 0, 0, false);
  EXPECT_EQ(n.failsafe.mode, PROTOCOL_MODE_FAILSAFE);
  EXPECT_TRUE(nano_core_faults(&n) & PROTOCOL_FAULT_LINK_LOST);
  // a stale engaged=0 (older than the timeout) does not count
  Run(200);
  Command(500, 0, true);
  Run(1);
  EXPECT_EQ(n.failsafe.mode, PROTOCOL_MODE_FAILSAFE);
  // engaged=0 then engaged=1, fresh: re-armed, fault cleared, drives
  Command(0, 0, false);
  Run(20);
  Command(500, 0, true);
  Run(1);
  EXPECT_EQ(n.failsafe.mode, PROTOCOL_MODE_ENGAGED);
  EXPECT_EQ(nano_core_faults(&n) & PROTOCOL_FAULT_LINK_LOST, 0);
  Stream(200, 500, 0, true);
  EXPECT_NEAR(fake.duty, 128, 1);
}

TEST_F(Core, NoFailsafeWhileDisarmed) {
  Stream(100, 0, 0, false);
  Run(500);
  EXPECT_EQ(n.failsafe.mode, PROTOCOL_MODE_DISARMED);
  EXPECT_EQ(nano_core_faults(&n), 0);
}

TEST_F(Core, ConfiguredTimeoutAndInvalidConfig) {
  Config(0, 10, 50);
  EXPECT_TRUE(Nacks().empty());
  Arm();
  Stream(100, 300, 0, true);
  Command(300, 0, true);
  Run(49);
  EXPECT_EQ(n.failsafe.mode, PROTOCOL_MODE_ENGAGED);
  Run(1);
  EXPECT_EQ(n.failsafe.mode, PROTOCOL_MODE_FAILSAFE);
  // out of range: rejected and the 50 ms timeout stays
  Config(0, 10, 151);
  auto k = Nacks();
  ASSERT_EQ(k.size(), 1u);
  EXPECT_EQ(k[0].rejected_id, PROTOCOL_ID_CONFIG);
  EXPECT_EQ(k[0].reason, PROTOCOL_NACK_OUT_OF_RANGE);
  EXPECT_EQ(n.failsafe.timeout_us, 50 * kMs);
  Config(300, 10, 100);
  EXPECT_EQ(Nacks().size(), 1u);
  Config(0, 2, 100);
  EXPECT_EQ(Nacks().size(), 1u);
  uint8_t short_cfg[5] = {0};
  Send(PROTOCOL_ID_CONFIG, short_cfg, 5);
  k = Nacks();
  ASSERT_EQ(k.size(), 1u);
  EXPECT_EQ(k[0].reason, PROTOCOL_NACK_BAD_LENGTH);
}

TEST_F(Core, OutOfRangeCommandRejectedNeverApplied) {
  Arm();
  Stream(300, 400, 0, true);
  const uint8_t duty_before = fake.duty;
  struct Bad {
    int16_t thr, steer;
    uint8_t head, ind, flags;
  } bad[] = {{1001, 0, 0, 0, 0}, {-1001, 0, 0, 0, 0}, {400, 1001, 0, 0, 0}, {400, -1001, 0, 0, 0},
             {400, 0, 3, 0, 0},  {400, 0, 0, 4, 0},   {400, 0, 0, 0, 0x80}};
  for (const Bad &b : bad) {
    uint16_t seq = cmd_seq;
    Command(b.thr, b.steer, true, b.head, b.ind, b.flags);
    Run(5);
    auto k = Nacks();
    ASSERT_EQ(k.size(), 1u);
    EXPECT_EQ(k[0].rejected_id, PROTOCOL_ID_COMMAND);
    EXPECT_EQ(k[0].reason, PROTOCOL_NACK_OUT_OF_RANGE);
    EXPECT_EQ(k[0].seq, seq);
    EXPECT_EQ(fake.duty, duty_before);
    EXPECT_EQ(fake.servo_us, 1500);
    EXPECT_EQ(n.cmd.throttle_milli, 400);
  }
  EXPECT_TRUE(nano_core_faults(&n) & PROTOCOL_FAULT_CMD_INVALID);
  EXPECT_EQ(n.failsafe.mode, PROTOCOL_MODE_ENGAGED);
  // invalid commands do not feed the failsafe: a stream of them trips it
  for (int i = 0; i < 10; ++i) {
    Command(2000, 0, true);
    Run(20);
  }
  EXPECT_EQ(n.failsafe.mode, PROTOCOL_MODE_FAILSAFE);
  EXPECT_EQ(fake.duty, 0);
  // latched until re-armed
  Command(0, 0, false);
  Run(5);
  EXPECT_TRUE(nano_core_faults(&n) & PROTOCOL_FAULT_CMD_INVALID);
  Command(0, 0, true);
  Run(5);
  EXPECT_EQ(nano_core_faults(&n) & PROTOCOL_FAULT_CMD_INVALID, 0);
}

TEST_F(Core, BadLengthAndUnknownIdNacked) {
  uint8_t p[PROTOCOL_LEN_COMMAND + 1] = {0};
  Send(PROTOCOL_ID_COMMAND, p, PROTOCOL_LEN_COMMAND + 1);
  Send(0x55, p, 3);
  Send(PROTOCOL_ID_STATE, p, 2);  // a Nano->Jetson id sent to the Nano
  auto k = Nacks();
  ASSERT_EQ(k.size(), 3u);
  EXPECT_EQ(k[0].reason, PROTOCOL_NACK_BAD_LENGTH);
  EXPECT_EQ(k[1].reason, PROTOCOL_NACK_UNKNOWN_ID);
  EXPECT_EQ(k[1].rejected_id, 0x55);
  EXPECT_EQ(k[2].reason, PROTOCOL_NACK_UNKNOWN_ID);
  EXPECT_EQ(n.failsafe.fresh, 0) << "a bad frame must not count as a command";
}

TEST_F(Core, ServoHoldsWhileNotEngaged) {
  Stream(300, 0, 1000, false);  // disarmed: steering commands do not move the servo
  EXPECT_EQ(fake.servo_us, 1500);
  Arm();
  Stream(300, 0, 1000, true);
  const uint16_t turned = fake.servo_us;
  EXPECT_GT(turned, 1700);
  Run(100);  // failsafe: from here the servo holds, no sudden move
  ASSERT_EQ(n.failsafe.mode, PROTOCOL_MODE_FAILSAFE);
  const uint16_t held = fake.servo_us;
  Run(200);
  EXPECT_EQ(fake.servo_us, held);
  Stream(300, 0, -1000, false);
  EXPECT_EQ(fake.servo_us, held);
}

TEST_F(Core, SteeringRateLimitTrimAndSaturation) {
  Arm();
  Command(0, 1000, true);
  Run(50);
  Command(0, 1000, true);
  Run(50);
  // 0.805 rad/s over 0.5236 rad: 100 ms -> 0.1537 -> 1500 + 76.9 us
  EXPECT_NEAR(fake.servo_us, 1577, 1);
  protocol_state_t s = LastState();
  EXPECT_NEAR(s.steering_milli, 153, 2);
  Stream(700, 0, 1000, true);
  EXPECT_EQ(fake.servo_us, 2000);
  // full right takes 2 / 1.5374 = 1.30 s
  Stream(1200, 0, -1000, true);
  EXPECT_GT(fake.servo_us, 1000);
  Stream(200, 0, -1000, true);
  EXPECT_EQ(fake.servo_us, 1000);
  // trim shifts the pulse, saturation clips at 1000..2000
  Config(-150, 10, 100);
  Stream(40, 0, -1000, true);
  EXPECT_EQ(fake.servo_us, 1000);
  Config(150, 10, 100);
  Stream(40, 0, -1000, true);
  EXPECT_EQ(fake.servo_us, 1150);
  Stream(2000, 0, 1000, true);
  EXPECT_EQ(fake.servo_us, 2000);
  Stream(1000, 0, 0, true);
  EXPECT_EQ(fake.servo_us, 1650);
}

TEST_F(Core, HeadlightsIndicatorsAndBlinkRate) {
  Stream(40, 0, 0, false, 20, 1, 0);
  EXPECT_EQ(fake.lamps & (NANO_CORE_LAMP_HEAD_LOW | NANO_CORE_LAMP_HEAD_HIGH),
            NANO_CORE_LAMP_HEAD_LOW);
  Stream(40, 0, 0, false, 20, 2, 0);
  EXPECT_EQ(fake.lamps & (NANO_CORE_LAMP_HEAD_LOW | NANO_CORE_LAMP_HEAD_HIGH),
            NANO_CORE_LAMP_HEAD_LOW | NANO_CORE_LAMP_HEAD_HIGH);
  Stream(40, 0, 0, false, 20, 0, 0);
  EXPECT_EQ(fake.lamps & (NANO_CORE_LAMP_HEAD_LOW | NANO_CORE_LAMP_HEAD_HIGH), 0);
  // left indicator: count rising edges of the lamp over 4 s -> 1.5 Hz = 6 cycles
  int rises = 0, on_ms = 0;
  uint8_t prev = 0;
  for (int i = 0; i < 4000; ++i) {
    if (i % 20 == 0) Command(0, 0, false, 0, 1);
    Run(1);
    uint8_t left = fake.lamps & NANO_CORE_LAMP_IND_LEFT;
    if (left && !prev) ++rises;
    if (left) ++on_ms;
    EXPECT_EQ(fake.lamps & NANO_CORE_LAMP_IND_RIGHT, 0);
    prev = left;
  }
  EXPECT_EQ(rises, 6);
  EXPECT_NEAR(on_ms, 2000, 5);
  // right
  Stream(100, 0, 0, false, 20, 0, 2);
  EXPECT_EQ(fake.lamps & NANO_CORE_LAMP_IND_LEFT, 0);
  EXPECT_EQ(fake.lamps & NANO_CORE_LAMP_IND_RIGHT, NANO_CORE_LAMP_IND_RIGHT);
  protocol_state_t s = LastState();
  EXPECT_EQ((s.lights & PROTOCOL_LIGHTS_IND_MASK) >> PROTOCOL_LIGHTS_IND_SHIFT, 2u);
  EXPECT_TRUE(s.lights & PROTOCOL_LIGHTS_BLINK_RIGHT);
}

TEST_F(Core, TaillightsWhenBrakingReverseLightsWhenReversing) {
  Arm();
  Stream(300, 800, 0, true);
  EXPECT_FALSE(fake.lamps & NANO_CORE_LAMP_TAIL);
  EXPECT_FALSE(fake.lamps & NANO_CORE_LAMP_REVERSE);
  Command(200, 0, true);  // slowing down: decelerating -> tail on
  Run(5);
  EXPECT_TRUE(fake.lamps & NANO_CORE_LAMP_TAIL);
  Stream(300, 200, 0, true);  // steady again
  EXPECT_FALSE(fake.lamps & NANO_CORE_LAMP_TAIL);
  Stream(200, 0, 0, true);  // stopped, engaged: motor brake -> tail on
  EXPECT_EQ(fake.brake, 1);
  EXPECT_TRUE(fake.lamps & NANO_CORE_LAMP_TAIL);
  Stream(300, -500, 0, true);
  EXPECT_TRUE(fake.lamps & NANO_CORE_LAMP_REVERSE);
  EXPECT_FALSE(fake.lamps & NANO_CORE_LAMP_TAIL);
  protocol_state_t s = LastState();
  EXPECT_TRUE(s.lights & PROTOCOL_LIGHTS_REVERSE);
  EXPECT_FALSE(s.lights & PROTOCOL_LIGHTS_TAIL);
}

TEST_F(Core, BatteryWarningCutoffAndHysteresis) {
  Arm();
  Stream(200, 500, 0, true);
  EXPECT_GT(fake.duty, 0);
  fake.battery_mv = 10300;  // below warning, above cut-off
  Stream(300, 500, 0, true);
  EXPECT_TRUE(nano_core_faults(&n) & PROTOCOL_FAULT_BATTERY_LOW);
  EXPECT_FALSE(nano_core_faults(&n) & PROTOCOL_FAULT_BATTERY_CUTOFF);
  EXPECT_GT(fake.duty, 0);
  fake.battery_mv = 9500;  // below cut-off: drive refused though engaged
  Stream(300, 500, 0, true);
  EXPECT_TRUE(nano_core_faults(&n) & PROTOCOL_FAULT_BATTERY_CUTOFF);
  EXPECT_EQ(n.failsafe.mode, PROTOCOL_MODE_ENGAGED);
  EXPECT_EQ(fake.duty, 0);
  EXPECT_EQ(fake.brake, 1);
  fake.battery_mv = 10200;  // recovers above cut-off but inside the hysteresis band
  Stream(300, 500, 0, true);
  EXPECT_TRUE(nano_core_faults(&n) & PROTOCOL_FAULT_BATTERY_CUTOFF);
  EXPECT_EQ(fake.duty, 0);
  fake.battery_mv = 10600;  // above the cut-off clear level, still inside the warning band
  Stream(300, 500, 0, true);
  EXPECT_FALSE(nano_core_faults(&n) & PROTOCOL_FAULT_BATTERY_CUTOFF);
  EXPECT_TRUE(nano_core_faults(&n) & PROTOCOL_FAULT_BATTERY_LOW);
  EXPECT_GT(fake.duty, 0);
  fake.battery_mv = 11000;
  Stream(300, 500, 0, true);
  EXPECT_EQ(nano_core_faults(&n) & (PROTOCOL_FAULT_BATTERY_LOW | PROTOCOL_FAULT_BATTERY_CUTOFF), 0);
  protocol_state_t s = LastState();
  EXPECT_NEAR(s.battery_mv, 11000, 20);
}

TEST_F(Core, BatteryFilterIgnoresShortSag) {
  Arm();
  Stream(100, 500, 0, true);
  fake.battery_mv = 8000;  // one 10 ms sample of a load spike
  Command(500, 0, true);
  Run(10);
  fake.battery_mv = 11800;
  Stream(100, 500, 0, true);
  EXPECT_FALSE(nano_core_faults(&n) & PROTOCOL_FAULT_BATTERY_CUTOFF);
  EXPECT_GT(fake.duty, 0);
}

TEST_F(Core, FlatBatteryAtBootRefusesDrive) {
  fake.battery_mv = 9000;
  Boot(0, 0);
  EXPECT_TRUE(nano_core_faults(&n) & PROTOCOL_FAULT_BATTERY_CUTOFF)
      << "known at init, before any pass";
  Arm();
  Stream(200, 800, 0, true);
  EXPECT_EQ(fake.duty, 0);
  EXPECT_TRUE(nano_core_faults(&n) & PROTOCOL_FAULT_BATTERY_CUTOFF);
}

TEST_F(Core, ImuAbsentRaisesFaultLoopKeepsRunning) {
  fake.imu_absent = true;
  Run(100);
  protocol_state_t s = LastState();
  EXPECT_TRUE(s.faults & PROTOCOL_FAULT_IMU_LOST);
  EXPECT_EQ(s.accel_raw[2], 0);
  EXPECT_EQ(s.quat_q14[0], PROTOCOL_QUAT_ONE);
  Arm();
  Stream(200, 500, 0, true);
  EXPECT_GT(fake.duty, 0) << "an IMU fault must not stop the car";
  fake.imu_absent = false;
  Run(20);
  s = LastState();
  EXPECT_FALSE(s.faults & PROTOCOL_FAULT_IMU_LOST);
  EXPECT_EQ(s.accel_raw[2], PROTOCOL_ACCEL_LSB_PER_G);
  // IMU read at 100 Hz, not every loop pass
  unsigned before = fake.imu_reads;
  Run(1000);
  EXPECT_EQ(fake.imu_reads - before, 100u);
}

TEST_F(Core, TelemetryPeriodDefaultAndConfigured) {
  fake.Take(PROTOCOL_ID_STATE);
  Run(1000);
  auto st = fake.Take(PROTOCOL_ID_STATE);
  EXPECT_EQ(st.size(), 100u);
  for (size_t i = 1; i < st.size(); ++i) {
    protocol_state_t a{}, b{};
    protocol_state_unpack(st[i - 1].payload, st[i - 1].len, &a);
    protocol_state_unpack(st[i].payload, st[i].len, &b);
    EXPECT_EQ(b.nano_time_us - a.nano_time_us, 10 * kMs);
    EXPECT_EQ(static_cast<uint8_t>(st[i].seq - st[i - 1].seq), 1);
  }
  Config(0, 20, 100);
  Run(20);  // the frame already scheduled at the old period goes first
  fake.Take(PROTOCOL_ID_STATE);
  Run(1000);
  EXPECT_EQ(fake.Take(PROTOCOL_ID_STATE).size(), 50u);
  Config(0, 5, 100);
  Run(20);
  fake.Take(PROTOCOL_ID_STATE);
  Run(1000);
  EXPECT_EQ(fake.Take(PROTOCOL_ID_STATE).size(), 200u);
  EXPECT_EQ(fake.tx_stats().bad_crc, 0u);
  EXPECT_EQ(fake.tx_stats().frames_dropped, 0u) << "our tx seq must have no gaps";
}

TEST_F(Core, EncoderCountsAndWheelSpeedsInTelemetry) {
  enc_rate_l = 1920;  // [counts/1000 per 1 ms step]: 1 rev/s = 6283 mrad/s
  enc_rate_r = -960;  // -0.5 rev/s
  Run(500);
  protocol_state_t s = LastState();
  EXPECT_EQ(s.enc_counts[0], 960);
  EXPECT_EQ(s.enc_counts[1], -480);
  EXPECT_NEAR(s.wheel_speed_mrad_s[0], 6283, 40);
  EXPECT_NEAR(s.wheel_speed_mrad_s[1], -3142, 40);
}

TEST_F(Core, LinkStatisticsReported) {
  uint8_t f[PROTOCOL_MAX_FRAME];
  protocol_command_t c{1, 0, 0, 0, 0, 0};
  uint8_t p[PROTOCOL_LEN_COMMAND];
  protocol_command_pack(&c, p);
  size_t sz = protocol_frame_encode(PROTOCOL_ID_COMMAND, 0, p, PROTOCOL_LEN_COMMAND, f, sizeof f);
  nano_core_rx(&n, f, static_cast<uint8_t>(sz), t_us);
  f[6] ^= 1;  // corrupt
  nano_core_rx(&n, f, static_cast<uint8_t>(sz), t_us);
  f[6] ^= 1;
  f[4] = 5;  // seq 0 -> 5: four dropped; recompute the CRC
  sz = protocol_frame_encode(PROTOCOL_ID_COMMAND, 5, p, PROTOCOL_LEN_COMMAND, f, sizeof f);
  nano_core_rx(&n, f, static_cast<uint8_t>(sz), t_us);
  Run(10);
  protocol_state_t s = LastState();
  EXPECT_EQ(s.frames_ok, 2);
  EXPECT_EQ(s.frames_bad_crc, 1);
  EXPECT_EQ(s.frames_dropped, 4);
}

TEST_F(Core, WatchdogResetFlagLatchedUntilArmed) {
  Boot(0, 1);
  Run(20);
  EXPECT_TRUE(LastState().faults & PROTOCOL_FAULT_WATCHDOG_RESET);
  Arm();
  EXPECT_FALSE(nano_core_faults(&n) & PROTOCOL_FAULT_WATCHDOG_RESET);
}

TEST_F(Core, LoopOverrunFlagged) {
  Run(10);
  EXPECT_FALSE(nano_core_faults(&n) & PROTOCOL_FAULT_LOOP_OVERRUN);
  t_us += 30 * kMs;
  Run(1);
  EXPECT_TRUE(nano_core_faults(&n) & PROTOCOL_FAULT_LOOP_OVERRUN);
}

TEST_F(Core, WorksAcrossTheMicrosecondWrap) {
  Boot(0xFFFFFFFFu - 300 * kMs, 0);
  Arm();
  Stream(600, 500, 0, true);  // crosses 2^32 us
  EXPECT_EQ(n.failsafe.mode, PROTOCOL_MODE_ENGAGED);
  EXPECT_NEAR(fake.duty, 128, 1);
  Command(500, 0, true);
  Run(99);
  EXPECT_EQ(n.failsafe.mode, PROTOCOL_MODE_ENGAGED);
  Run(1);
  EXPECT_EQ(n.failsafe.mode, PROTOCOL_MODE_FAILSAFE);
  fake.Take(PROTOCOL_ID_STATE);
  Run(100);
  EXPECT_EQ(fake.Take(PROTOCOL_ID_STATE).size(), 10u);
}

TEST_F(Core, BytesInAnyChunkingGiveTheSameResult) {
  // a command split across three nano_core_rx calls
  protocol_command_t c{9, 0, 0, 0, 0, 0};
  uint8_t p[PROTOCOL_LEN_COMMAND], f[PROTOCOL_MAX_FRAME];
  protocol_command_pack(&c, p);
  size_t sz = protocol_frame_encode(PROTOCOL_ID_COMMAND, 0, p, PROTOCOL_LEN_COMMAND, f, sizeof f);
  nano_core_rx(&n, f, 3, t_us);
  nano_core_rx(&n, f + 3, 7, t_us);
  EXPECT_EQ(n.failsafe.fresh, 0);
  nano_core_rx(&n, f + 10, static_cast<uint8_t>(sz - 10), t_us);
  EXPECT_EQ(n.failsafe.fresh, 1);
  EXPECT_EQ(n.cmd.seq, 9);
}

}  // namespace
