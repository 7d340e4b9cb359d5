// Firmware-in-the-loop tests: the real Nano ELF in simavr (see sil_board.h). Everything is in
// simulated time; nothing here depends on wall time.
#include <gtest/gtest.h>

#include "sil_board.h"

namespace {

using sil::Board;
using sil::make_command;

constexpr uint64_t kMs = 1000;  // [us]

// Streams one COMMAND every period_us for duration_us.
void stream(Board &b, uint16_t &seq, uint64_t duration_us, int16_t throttle, int16_t steering,
            bool engaged, uint8_t head = 0, uint8_t ind = 0, uint64_t period_us = 10 * kMs) {
  for (uint64_t t = 0; t < duration_us; t += period_us) {
    b.send_command(make_command(seq++, throttle, steering, engaged, head, ind));
    ASSERT_TRUE(b.run_us(period_us));
  }
}

// Boots and arms: engaged=0 then engaged=1 (the failsafe's arming sequence).
void arm(Board &b, uint16_t &seq) {
  ASSERT_TRUE(b.run_us(20 * kMs));
  stream(b, seq, 30 * kMs, 0, 0, false);
  stream(b, seq, 30 * kMs, 0, 0, true);
  protocol_state_t s{};
  ASSERT_TRUE(b.last_state(&s));
  ASSERT_EQ(s.mode, PROTOCOL_MODE_ENGAGED);
}

bool find_hello(const Board &b, size_t index, protocol_hello_t *h) {
  size_t k = 0;
  for (const auto &fr : b.frames()) {
    if (fr.f.id != PROTOCOL_ID_HELLO) continue;
    if (k++ == index) return protocol_hello_unpack(fr.f.payload, fr.f.len, h) == 0;
  }
  return false;
}

TEST(Sil, hello_handshake) {
  Board b(NANO_ELF);
  // boot + the schema hash (FNV-1a over ~700 flash bytes, ~4.5 ms on the AVR)
  ASSERT_TRUE(b.run_us(10 * kMs));
  ASSERT_EQ(b.count(PROTOCOL_ID_HELLO), 1u) << "HELLO is sent once at boot";
  protocol_hello_t h{};
  ASSERT_TRUE(find_hello(b, 0, &h));
  EXPECT_EQ(h.schema_hash, protocol_schema_hash());
  EXPECT_EQ(h.proto_version, PROTOCOL_VERSION);
  EXPECT_EQ(h.fw_major, 1u);
  // a HELLO_REQUEST is answered with the same HELLO
  b.send_frame(PROTOCOL_ID_HELLO_REQUEST, nullptr, 0);
  ASSERT_TRUE(b.run_until([&] { return b.count(PROTOCOL_ID_HELLO) == 2; }, 10 * kMs));
  protocol_hello_t h2{};
  ASSERT_TRUE(find_hello(b, 1, &h2));
  EXPECT_EQ(h2.schema_hash, h.schema_hash);
  EXPECT_EQ(h2.build_id, h.build_id);
  EXPECT_EQ(b.rx_stats().bad_crc, 0u);
}

TEST(Sil, boots_disarmed) {
  Board b(NANO_ELF);
  ASSERT_TRUE(b.run_us(100 * kMs));
  protocol_state_t s{};
  ASSERT_TRUE(b.last_state(&s));
  EXPECT_EQ(s.mode, PROTOCOL_MODE_DISARMED);
  EXPECT_EQ(b.servo_pulse_us(), 1500);
  EXPECT_EQ(b.motor_duty(), 0);
  EXPECT_TRUE(b.motor_brake());
  // engaged=1 from a host that never sent engaged=0 first does not arm the car
  uint16_t seq = 1;
  stream(b, seq, 200 * kMs, 800, 0, true);
  ASSERT_TRUE(b.last_state(&s));
  EXPECT_EQ(s.mode, PROTOCOL_MODE_DISARMED);
  EXPECT_EQ(b.motor_duty(), 0);
  EXPECT_TRUE(b.motor_brake());
  EXPECT_EQ(s.throttle_milli, 0);
  EXPECT_EQ(s.faults & PROTOCOL_FAULT_WATCHDOG_RESET, 0);
}

TEST(Sil, command_to_servo_and_motor) {
  Board b(NANO_ELF);
  uint16_t seq = 1;
  arm(b, seq);
  // full left, half forward; the servo is rate limited (0.65 s for full scale), the throttle
  // slew-limited (0.25 s for full scale): after 0.7 s both have arrived
  stream(b, seq, 700 * kMs, 500, 1000, true);
  ASSERT_TRUE(b.run_us(12 * kMs));  // one more STATE after the last COMMAND was parsed
  EXPECT_EQ(b.servo_pulse_us(), 2000);
  EXPECT_EQ(b.motor_duty(), 128);  // 0.5 * 255, rounded
  EXPECT_FALSE(b.motor_reverse());
  EXPECT_FALSE(b.motor_brake());
  protocol_state_t s{};
  ASSERT_TRUE(b.last_state(&s));
  EXPECT_EQ(s.throttle_milli, 500);
  EXPECT_EQ(s.steering_milli, 1000);
  EXPECT_EQ(s.last_cmd_seq, static_cast<uint16_t>(seq - 1));
  // reverse, right: 1.4 full scale of steering takes 0.91 s
  stream(b, seq, 1000 * kMs, -300, -400, true);
  EXPECT_EQ(b.servo_pulse_us(), 1300);
  EXPECT_EQ(b.motor_duty(), 77);  // 0.3 * 255, rounded
  EXPECT_TRUE(b.motor_reverse());
  EXPECT_FALSE(b.motor_brake());
  EXPECT_TRUE(b.lamp_pins() & NANO_CORE_LAMP_REVERSE);
}

TEST(Sil, encoder_edges_to_counts) {
  Board b(NANO_ELF);
  ASSERT_TRUE(b.run_us(10 * kMs));
  for (int i = 0; i < 500; i++) {
    b.encoder_edge(0, +1);
    if (i < 300) b.encoder_edge(1, +1);
    ASSERT_TRUE(b.run_us(50));
  }
  ASSERT_TRUE(b.run_us(25 * kMs));  // two telemetry periods
  protocol_state_t s{};
  ASSERT_TRUE(b.last_state(&s));
  EXPECT_EQ(s.enc_counts[0], 500);
  EXPECT_EQ(s.enc_counts[1], 300);
}

TEST(Sil, encoder_reverse_counts) {
  Board b(NANO_ELF);
  ASSERT_TRUE(b.run_us(10 * kMs));
  b.encoder_rate(4000.0, -1);  // 4000 edges/s per wheel, backwards, for 250 ms
  ASSERT_TRUE(b.run_us(250 * kMs));
  b.encoder_rate(0);
  ASSERT_TRUE(b.run_us(25 * kMs));
  protocol_state_t s{};
  ASSERT_TRUE(b.last_state(&s));
  EXPECT_NEAR(s.enc_counts[0], -1000, 2);
  EXPECT_EQ(s.enc_counts[0], s.enc_counts[1]);
  EXPECT_LT(s.enc_counts[0], 0);
}

TEST(Sil, failsafe_on_link_loss) {
  Board b(NANO_ELF);
  uint16_t seq = 1;
  arm(b, seq);
  stream(b, seq, 400 * kMs, 600, 0, true);
  ASSERT_GT(b.motor_duty(), 100);
  ASSERT_FALSE(b.motor_brake());
  // link lost: within 150 ms throttle 0, brake on, hazards, latched fault
  const uint64_t lost_us = b.now_us();
  ASSERT_TRUE(b.run_until([&] { return b.motor_brake() && b.motor_duty() == 0; }, 150 * kMs));
  EXPECT_LE(b.now_us() - lost_us, 150 * kMs);
  ASSERT_TRUE(b.run_us(20 * kMs));
  protocol_state_t s{};
  ASSERT_TRUE(b.last_state(&s));
  EXPECT_EQ(s.mode, PROTOCOL_MODE_FAILSAFE);
  EXPECT_TRUE(s.faults & PROTOCOL_FAULT_LINK_LOST);
  EXPECT_EQ((s.lights & PROTOCOL_LIGHTS_IND_MASK) >> PROTOCOL_LIGHTS_IND_SHIFT, 3u) << "hazards";
  EXPECT_EQ(s.throttle_milli, 0);
  // both indicator lamps blink together
  bool both_lit = false;
  ASSERT_TRUE(b.run_until(
      [&] {
        const uint8_t l = b.lamp_pins();
        both_lit = (l & NANO_CORE_LAMP_IND_LEFT) && (l & NANO_CORE_LAMP_IND_RIGHT);
        return both_lit;
      },
      800 * kMs));
  // the stream comes back with engaged=1: still in failsafe, fault still latched
  stream(b, seq, 100 * kMs, 600, 0, true);
  ASSERT_TRUE(b.last_state(&s));
  EXPECT_EQ(s.mode, PROTOCOL_MODE_FAILSAFE);
  EXPECT_TRUE(s.faults & PROTOCOL_FAULT_LINK_LOST);
  EXPECT_EQ(b.motor_duty(), 0);
  // re-arm: engaged=0 then engaged=1 clears the fault and drives again
  stream(b, seq, 30 * kMs, 0, 0, false);
  stream(b, seq, 300 * kMs, 600, 0, true);
  ASSERT_TRUE(b.last_state(&s));
  EXPECT_EQ(s.mode, PROTOCOL_MODE_ENGAGED);
  EXPECT_EQ(s.faults & PROTOCOL_FAULT_LINK_LOST, 0);
  EXPECT_GT(b.motor_duty(), 100);
}

TEST(Sil, out_of_range_rejected) {
  Board b(NANO_ELF);
  uint16_t seq = 1;
  arm(b, seq);
  stream(b, seq, 300 * kMs, 400, 0, true);
  const uint8_t duty_before = b.motor_duty();
  ASSERT_GT(duty_before, 0);
  const size_t nacks_before = b.count(PROTOCOL_ID_NACK);
  const uint16_t bad_seq = seq;
  b.send_command(make_command(seq++, 1500, 0, true));  // throttle beyond 1000
  ASSERT_TRUE(b.run_until([&] { return b.count(PROTOCOL_ID_NACK) > nacks_before; }, 5 * kMs));
  protocol_nack_t k{};
  const auto &last = b.frames().back();
  for (auto it = b.frames().rbegin(); it != b.frames().rend(); ++it) {
    if (it->f.id == PROTOCOL_ID_NACK) {
      ASSERT_EQ(protocol_nack_unpack(it->f.payload, it->f.len, &k), 0);
      break;
    }
  }
  (void)last;
  EXPECT_EQ(k.rejected_id, PROTOCOL_ID_COMMAND);
  EXPECT_EQ(k.reason, PROTOCOL_NACK_OUT_OF_RANGE);
  EXPECT_EQ(k.seq, bad_seq);
  ASSERT_TRUE(b.run_us(15 * kMs));
  protocol_state_t s{};
  ASSERT_TRUE(b.last_state(&s));
  EXPECT_EQ(s.throttle_milli, 400) << "the out-of-range value was never applied";
  EXPECT_EQ(b.motor_duty(), duty_before);
  EXPECT_TRUE(s.faults & PROTOCOL_FAULT_CMD_INVALID);
  // an invalid frame does not feed the failsafe: with only invalid frames, the link is lost
  for (int i = 0; i < 20; i++) {
    b.send_command(make_command(seq++, 400, 2000, true));
    ASSERT_TRUE(b.run_us(10 * kMs));
  }
  ASSERT_TRUE(b.last_state(&s));
  EXPECT_EQ(s.mode, PROTOCOL_MODE_FAILSAFE);
  EXPECT_EQ(b.motor_duty(), 0);
}

TEST(Sil, lights_follow_command) {
  Board b(NANO_ELF);
  uint16_t seq = 1;
  arm(b, seq);
  stream(b, seq, 100 * kMs, 0, 0, true, 2, 1);  // high beams, left indicator
  EXPECT_TRUE(b.lamp_pins() & NANO_CORE_LAMP_HEAD_HIGH);
  EXPECT_TRUE(b.lamp_pins() & NANO_CORE_LAMP_HEAD_LOW) << "high beams keep the low beams lit";
  stream(b, seq, 50 * kMs, 0, 0, true, 1, 1);  // low beams only
  EXPECT_FALSE(b.lamp_pins() & NANO_CORE_LAMP_HEAD_HIGH);
  EXPECT_TRUE(b.lamp_pins() & NANO_CORE_LAMP_HEAD_LOW);
  bool left_on = false, left_off = false, right_on = false;
  for (int i = 0; i < 100; i++) {  // 1 s: the indicator blinks at ~1.5 Hz
    b.send_command(make_command(seq++, 0, 0, true, 1, 1));
    ASSERT_TRUE(b.run_us(10 * kMs));
    const uint8_t l = b.lamp_pins();
    (l & NANO_CORE_LAMP_IND_LEFT ? left_on : left_off) = true;
    right_on = right_on || (l & NANO_CORE_LAMP_IND_RIGHT);
  }
  EXPECT_TRUE(left_on);
  EXPECT_TRUE(left_off);
  EXPECT_FALSE(right_on);
  EXPECT_TRUE(b.lamp_pins() & NANO_CORE_LAMP_TAIL) << "standing with the brake on";
}

TEST(Sil, imu_present_values) {
  Board b(NANO_ELF);
  b.imu().set_sample({100, -200, 8192}, {11, -22, 33}, {300, -400, 500});
  ASSERT_TRUE(b.run_us(100 * kMs));
  protocol_state_t s{};
  ASSERT_TRUE(b.last_state(&s));
  EXPECT_EQ(s.faults & PROTOCOL_FAULT_IMU_LOST, 0);
  EXPECT_EQ(s.accel_raw[0], 100);
  EXPECT_EQ(s.accel_raw[1], -200);
  EXPECT_EQ(s.accel_raw[2], 8192);
  EXPECT_EQ(s.gyro_raw[0], 11);
  EXPECT_EQ(s.gyro_raw[1], -22);
  EXPECT_EQ(s.gyro_raw[2], 33);
  // AK8963 axes turned into the accel frame: x = y_mag, y = x_mag, z = -z_mag
  EXPECT_EQ(s.mag_raw[0], -400);
  EXPECT_EQ(s.mag_raw[1], 300);
  EXPECT_EQ(s.mag_raw[2], -500);
  EXPECT_EQ(b.imu().mpu_reg(0x1C), 0x08) << "accel configured to +-4 g";
  EXPECT_EQ(b.imu().mpu_reg(0x1B), 0x08) << "gyro configured to +-500 deg/s";
  EXPECT_EQ(b.imu().ak_reg(0x0A), 0x16) << "AK8963 continuous 100 Hz, 16 bit";
}

TEST(Sil, imu_absent_fault) {
  Board b(NANO_ELF, /*imu_present=*/false);
  ASSERT_TRUE(b.run_us(100 * kMs));
  const size_t states_before = b.states().size();
  const uint64_t passes_before = b.loop_passes();
  ASSERT_TRUE(b.run_us(500 * kMs));
  protocol_state_t s{};
  ASSERT_TRUE(b.last_state(&s));
  EXPECT_TRUE(s.faults & PROTOCOL_FAULT_IMU_LOST);
  EXPECT_EQ(s.faults & PROTOCOL_FAULT_LOOP_OVERRUN, 0) << "the loop never stalled";
  EXPECT_GE(b.states().size() - states_before, 45u) << "telemetry continues (100 Hz)";
  // The loop sleeps between passes and runs at least on every Timer0 tick (1.024 ms): 488
  // passes in 500 ms.
  EXPECT_GE(b.loop_passes() - passes_before, 480u) << "the loop runs on every 1.024 ms tick";
  EXPECT_LT(b.loop_cycles_max(), 48000u) << "no pass took 3 ms";
  // the IMU comes back: the firmware re-probes it and the fault clears
  b.imu().set_present(true);
  b.imu().set_sample({1, 2, 3}, {4, 5, 6}, {7, 8, 9});
  ASSERT_TRUE(b.run_us(300 * kMs));
  ASSERT_TRUE(b.last_state(&s));
  EXPECT_EQ(s.faults & PROTOCOL_FAULT_IMU_LOST, 0);
  EXPECT_EQ(s.accel_raw[2], 3);
}

// The test ELF has a RAM flag (hal_avr_test_hang) that makes the main loop spin: the watchdog must
// reset the board, which comes back disarmed, silent and reports the watchdog reset.
TEST(Sil, watchdog_reset_safe_state) {
  Board b(NANO_TEST_ELF);
  const uint32_t hang = b.symbol("hal_avr_test_hang");
  ASSERT_NE(hang, 0u) << "the test ELF exports hal_avr_test_hang";
  uint16_t seq = 1;
  arm(b, seq);
  stream(b, seq, 300 * kMs, 500, 300, true);
  ASSERT_GT(b.motor_duty(), 0);
  ASSERT_EQ(b.resets(), 0u);
  const size_t hellos = b.count(PROTOCOL_ID_HELLO);
  b.write_ram(hang, 1);
  // keep streaming valid commands: only the watchdog can stop a hung loop
  for (int i = 0; i < 40 && b.resets() == 0; i++) {
    b.send_command(make_command(seq++, 500, 300, true));
    ASSERT_TRUE(b.run_us(10 * kMs));
  }
  ASSERT_EQ(b.resets(), 1u) << "the watchdog reset the board";
  ASSERT_TRUE(b.run_until([&] { return b.count(PROTOCOL_ID_HELLO) > hellos; }, 50 * kMs));
  stream(b, seq, 100 * kMs, 500, 300, true);  // the host keeps sending engaged=1
  protocol_state_t s{};
  ASSERT_TRUE(b.last_state(&s));
  EXPECT_EQ(s.mode, PROTOCOL_MODE_DISARMED);
  EXPECT_TRUE(s.faults & PROTOCOL_FAULT_WATCHDOG_RESET);
  EXPECT_EQ(b.motor_duty(), 0);
  EXPECT_TRUE(b.motor_brake());
  EXPECT_EQ(s.throttle_milli, 0);
}

}  // namespace

namespace {

TEST(Sil, imu_stuck_fault) {
  Board b(NANO_ELF);
  b.imu().set_sample({0, 0, 8192}, {0, 0, 0}, {100, 0, 0});
  ASSERT_TRUE(b.run_us(100 * kMs));
  protocol_state_t s{};
  ASSERT_TRUE(b.last_state(&s));
  ASSERT_EQ(s.faults & PROTOCOL_FAULT_IMU_LOST, 0);
  b.imu().set_stuck(true);
  const size_t states_before = b.states().size();
  ASSERT_TRUE(b.run_us(200 * kMs));
  ASSERT_TRUE(b.last_state(&s));
  EXPECT_TRUE(s.faults & PROTOCOL_FAULT_IMU_LOST);
  EXPECT_EQ(s.faults & PROTOCOL_FAULT_LOOP_OVERRUN, 0);
  EXPECT_GE(b.states().size() - states_before, 18u) << "telemetry continues";
}

// ADC7 through the 10k:3.3k divider: pack [mV] = pin [mV] * 13.3 / 3.3.
TEST(Sil, battery_monitoring) {
  Board b(NANO_ELF);
  b.set_adc7_mv(2850);  // 11.49 V pack
  uint16_t seq = 1;
  arm(b, seq);
  stream(b, seq, 500 * kMs, 400, 0, true);
  protocol_state_t s{};
  ASSERT_TRUE(b.last_state(&s));
  EXPECT_NEAR(s.battery_mv, 11486, 60);
  EXPECT_EQ(s.faults & (PROTOCOL_FAULT_BATTERY_LOW | PROTOCOL_FAULT_BATTERY_CUTOFF), 0);
  ASSERT_GT(b.motor_duty(), 0);
  b.set_adc7_mv(2400);  // 9.67 V: below the 9.9 V cut-off
  stream(b, seq, 800 * kMs, 400, 0, true);
  ASSERT_TRUE(b.last_state(&s));
  EXPECT_NEAR(s.battery_mv, 9673, 60);
  EXPECT_TRUE(s.faults & PROTOCOL_FAULT_BATTERY_LOW);
  EXPECT_TRUE(s.faults & PROTOCOL_FAULT_BATTERY_CUTOFF);
  EXPECT_EQ(b.motor_duty(), 0) << "drive refused below cut-off";
  EXPECT_TRUE(b.motor_brake());
}

TEST(Sil, config_applied) {
  Board b(NANO_ELF);
  ASSERT_TRUE(b.run_us(20 * kMs));
  protocol_config_t c{};
  c.servo_trim_us = 50;
  c.telemetry_period_ms = 20;
  c.failsafe_timeout_ms = 50;
  uint8_t p[PROTOCOL_LEN_CONFIG];
  protocol_config_pack(&c, p);
  b.send_frame(PROTOCOL_ID_CONFIG, p, PROTOCOL_LEN_CONFIG);
  ASSERT_TRUE(b.run_us(50 * kMs));
  const size_t before = b.count(PROTOCOL_ID_STATE);
  ASSERT_TRUE(b.run_us(1000 * kMs));
  const size_t n = b.count(PROTOCOL_ID_STATE) - before;
  EXPECT_GE(n, 49u) << "STATE every 20 ms";
  EXPECT_LE(n, 51u);
  EXPECT_EQ(b.servo_pulse_us(), 1550) << "trim moves the centre";
  EXPECT_EQ(b.count(PROTOCOL_ID_NACK), 0u);
  // a CONFIG out of range is refused with a NACK and changes nothing
  c.telemetry_period_ms = 1;
  protocol_config_pack(&c, p);
  b.send_frame(PROTOCOL_ID_CONFIG, p, PROTOCOL_LEN_CONFIG);
  ASSERT_TRUE(b.run_until([&] { return b.count(PROTOCOL_ID_NACK) == 1; }, 10 * kMs));
  const size_t before2 = b.count(PROTOCOL_ID_STATE);
  ASSERT_TRUE(b.run_us(200 * kMs));
  EXPECT_LE(b.count(PROTOCOL_ID_STATE) - before2, 11u) << "still 50 Hz";
}

}  // namespace
