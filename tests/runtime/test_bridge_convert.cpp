// Bridge conversions: protocol.h fixed point -> SI LCM fields, and LCM command -> COMMAND frame.
#include <gtest/gtest.h>

#include <cmath>

#include <autodrive/nano_bridge/bridge_convert.hpp>

namespace {
protocol_state_t sample_state() {
  protocol_state_t s{};
  s.nano_time_us = 123456789u;
  s.enc_counts[0] = 1920;
  s.enc_counts[1] = -960;
  s.wheel_speed_mrad_s[0] = 8200;
  s.wheel_speed_mrad_s[1] = -4100;
  s.throttle_milli = 500;
  s.steering_milli = -1000;
  s.accel_raw[0] = 8192;   // 1 g
  s.accel_raw[2] = -4096;  // -0.5 g
  s.gyro_raw[2] = 655;     // 10 deg/s
  s.mag_raw[0] = 100;      // 15 uT
  s.quat_q14[0] = 16384;   // identity
  s.battery_mv = 11100;
  s.lights = 2 | (3u << PROTOCOL_LIGHTS_IND_SHIFT) | PROTOCOL_LIGHTS_TAIL;
  s.mode = PROTOCOL_MODE_ENGAGED;
  s.faults = PROTOCOL_FAULT_BATTERY_LOW;
  s.last_cmd_seq = 77;
  s.frames_ok = 1000;
  s.frames_bad_crc = 3;
  s.frames_dropped = 2;
  return s;
}
}  // namespace

TEST(BridgeConvert, StateFieldsInSiUnits) {
  autodrive::config::Vehicle veh;
  autodrive::bridge::HostLinkStats host{500, 7, 1};
  autodrive::vehicle_state_t out{};
  autodrive::bridge::fill_state(sample_state(), veh, host, 42, &out);
  EXPECT_EQ(out.utime, 42);
  EXPECT_EQ(out.nano_time_us, 123456789);
  EXPECT_EQ(out.encoder_counts[0], 1920);
  EXPECT_EQ(out.encoder_counts[1], -960);
  EXPECT_NEAR(out.wheel_speed_rad_s[0], 8.2, 1e-6);
  EXPECT_NEAR(out.wheel_speed_rad_s[1], -4.1, 1e-6);
  EXPECT_NEAR(out.throttle_applied, 0.5, 1e-6);
  EXPECT_NEAR(out.steering_applied, -1.0, 1e-6);
  EXPECT_NEAR(out.steering_angle_rad, -0.5236, 1e-5);
  EXPECT_NEAR(out.battery_voltage_v, 11.1, 1e-5);
  EXPECT_EQ(out.headlights, 2);
  EXPECT_EQ(out.indicators, 3);
  EXPECT_TRUE(out.taillights_on);
  EXPECT_FALSE(out.reverse_lights_on);
  EXPECT_EQ(out.mode, 1);
  EXPECT_EQ(out.fault_flags, PROTOCOL_FAULT_BATTERY_LOW);
  EXPECT_EQ(out.last_command_seq, 77);
  EXPECT_EQ(out.nano_frames_ok, 1000);
  EXPECT_EQ(out.nano_frames_bad_crc, 3);
  EXPECT_EQ(out.nano_frames_dropped, 2);
  EXPECT_EQ(out.host_frames_ok, 500);
  EXPECT_EQ(out.host_frames_bad_crc, 7);
  EXPECT_EQ(out.host_frames_dropped, 1);
}

TEST(BridgeConvert, ImuScalesAndCovariances) {
  autodrive::config::Bridge br;
  br.imu_gyro_var_rad2_s2 = 0.25;
  autodrive::imu_t m{};
  autodrive::bridge::fill_imu(sample_state(), br, 7, &m);
  EXPECT_NEAR(m.linear_acceleration_m_s2[0], 9.80665, 1e-9);
  EXPECT_NEAR(m.linear_acceleration_m_s2[2], -4.903325, 1e-9);
  EXPECT_NEAR(m.angular_velocity_rad_s[2], 10.0 * M_PI / 180.0, 1e-9);
  EXPECT_NEAR(m.magnetic_field_ut[0], 15.0, 1e-9);
  EXPECT_DOUBLE_EQ(m.orientation_wxyz[0], 1.0);
  EXPECT_DOUBLE_EQ(m.angular_velocity_covariance[0], 0.25);
  EXPECT_DOUBLE_EQ(m.angular_velocity_covariance[4], 0.25);
  EXPECT_DOUBLE_EQ(m.angular_velocity_covariance[1], 0.0);
  EXPECT_EQ(m.frame_id, "imu_link");
}

TEST(BridgeConvert, ImuQuaternionRenormalised) {
  protocol_state_t s = sample_state();
  s.quat_q14[0] = 8000;  // w = x, not unit length on the wire
  s.quat_q14[1] = 8000;
  autodrive::imu_t m{};
  autodrive::bridge::fill_imu(s, autodrive::config::Bridge{}, 0, &m);
  EXPECT_NEAR(m.orientation_wxyz[0], std::sqrt(0.5), 1e-9);
  EXPECT_NEAR(m.orientation_wxyz[1], std::sqrt(0.5), 1e-9);
}

TEST(BridgeConvert, FreshCommandForwarded) {
  autodrive::vehicle_command_t c{};
  c.throttle = 0.5f;
  c.steering = -0.25f;
  c.headlights = 1;
  c.indicators = 2;
  c.engaged = true;
  const protocol_command_t m = autodrive::bridge::make_command(&c, true, 9);
  EXPECT_EQ(m.seq, 9);
  EXPECT_EQ(m.throttle_milli, 500);
  EXPECT_EQ(m.steering_milli, -250);
  EXPECT_EQ(m.headlights, 1);
  EXPECT_EQ(m.indicators, 2);
  EXPECT_EQ(m.flags, PROTOCOL_CMD_ENGAGED);
  EXPECT_TRUE(protocol_command_valid(&m));
}

TEST(BridgeConvert, StaleCommandDisengagesKeepsLights) {
  autodrive::vehicle_command_t c{};
  c.throttle = 0.8f;
  c.steering = 0.5f;
  c.headlights = 2;
  c.indicators = 3;
  c.engaged = true;
  const protocol_command_t m = autodrive::bridge::make_command(&c, false, 1);
  EXPECT_EQ(m.throttle_milli, 0);
  EXPECT_EQ(m.steering_milli, 0);
  EXPECT_EQ(m.flags, 0);
  EXPECT_EQ(m.headlights, 2);
  EXPECT_EQ(m.indicators, 3);
}

TEST(BridgeConvert, NoCommandYetIsSilent) {
  const protocol_command_t m = autodrive::bridge::make_command(nullptr, true, 0);
  EXPECT_EQ(m.throttle_milli, 0);
  EXPECT_EQ(m.flags, 0);
}

TEST(BridgeConvert, OutOfRangeCommandsNamed) {
  autodrive::vehicle_command_t c{};
  EXPECT_EQ(autodrive::bridge::command_problem(c), "");
  c.throttle = 1.5f;
  EXPECT_NE(autodrive::bridge::command_problem(c).find("throttle"), std::string::npos);
  c.throttle = NAN;
  EXPECT_NE(autodrive::bridge::command_problem(c).find("throttle"), std::string::npos);
  c.throttle = 0;
  c.steering = -2;
  EXPECT_NE(autodrive::bridge::command_problem(c).find("steering"), std::string::npos);
  c.steering = 0;
  c.headlights = 3;
  EXPECT_NE(autodrive::bridge::command_problem(c).find("headlights"), std::string::npos);
  c.headlights = 0;
  c.indicators = -1;
  EXPECT_NE(autodrive::bridge::command_problem(c).find("indicators"), std::string::npos);
}
