#include <autodrive/nano_bridge/bridge_convert.hpp>

#include <algorithm>
#include <cmath>

namespace autodrive::bridge {

void fill_state(const protocol_state_t &s, const autodrive::config::Vehicle &veh,
                const HostLinkStats &host, int64_t utime_us, autodrive::vehicle_state_t *out) {
  out->utime = utime_us;
  out->nano_time_us = s.nano_time_us;
  for (int i = 0; i < 2; ++i) {
    out->encoder_counts[i] = s.enc_counts[i];
    out->wheel_speed_rad_s[i] = static_cast<float>(s.wheel_speed_mrad_s[i] / 1000.0);
  }
  out->throttle_applied = static_cast<float>(s.throttle_milli / double(PROTOCOL_MILLI));
  out->steering_applied = static_cast<float>(s.steering_milli / double(PROTOCOL_MILLI));
  out->steering_angle_rad =
      static_cast<float>(s.steering_milli / double(PROTOCOL_MILLI) * veh.steering_limit_rad);
  out->battery_voltage_v = static_cast<float>(s.battery_mv / 1000.0);
  out->headlights = static_cast<int8_t>(s.lights & PROTOCOL_LIGHTS_HEAD_MASK);
  out->indicators =
      static_cast<int8_t>((s.lights & PROTOCOL_LIGHTS_IND_MASK) >> PROTOCOL_LIGHTS_IND_SHIFT);
  out->taillights_on = (s.lights & PROTOCOL_LIGHTS_TAIL) != 0;
  out->reverse_lights_on = (s.lights & PROTOCOL_LIGHTS_REVERSE) != 0;
  out->mode = static_cast<int8_t>(s.mode);
  out->fault_flags = s.faults;
  out->last_command_seq = s.last_cmd_seq;
  out->nano_frames_ok = s.frames_ok;
  out->nano_frames_bad_crc = s.frames_bad_crc;
  out->nano_frames_dropped = s.frames_dropped;
  out->host_frames_ok = static_cast<int32_t>(host.frames_ok);
  out->host_frames_bad_crc = static_cast<int32_t>(host.bad_crc);
  out->host_frames_dropped = static_cast<int32_t>(host.dropped);
}

void fill_imu(const protocol_state_t &s, const autodrive::config::Bridge &br, int64_t utime_us,
              autodrive::imu_t *out) {
  out->utime = utime_us;
  out->frame_id = br.imu_frame_id;
  double q[4];
  double norm2 = 0.0;
  for (int i = 0; i < 4; ++i) {
    q[i] = s.quat_q14[i] / double(PROTOCOL_QUAT_ONE);
    norm2 += q[i] * q[i];
  }
  // Fixed point leaves the quaternion a little off unit length; renormalise (identity if 0).
  const double norm = std::sqrt(norm2);
  for (int i = 0; i < 4; ++i) out->orientation_wxyz[i] = norm > 0 ? q[i] / norm : (i == 0);
  const double dps_to_rad = M_PI / 180.0;
  for (int i = 0; i < 3; ++i) {
    out->angular_velocity_rad_s[i] = s.gyro_raw[i] / PROTOCOL_GYRO_LSB_PER_DPS * dps_to_rad;
    out->linear_acceleration_m_s2[i] =
        s.accel_raw[i] / double(PROTOCOL_ACCEL_LSB_PER_G) * kGravity_m_s2;
    out->magnetic_field_ut[i] = s.mag_raw[i] * PROTOCOL_MAG_UT_PER_LSB;
  }
  for (int i = 0; i < 9; ++i) {
    const bool diag = (i % 4) == 0;
    out->orientation_covariance[i] = diag ? br.imu_orientation_var_rad2 : 0.0;
    out->angular_velocity_covariance[i] = diag ? br.imu_gyro_var_rad2_s2 : 0.0;
    out->linear_acceleration_covariance[i] = diag ? br.imu_accel_var_m2_s4 : 0.0;
  }
}

std::string command_problem(const autodrive::vehicle_command_t &c) {
  if (!std::isfinite(c.throttle) || c.throttle < -1.0f || c.throttle > 1.0f)
    return "throttle " + std::to_string(c.throttle) + " outside [-1, 1]";
  if (!std::isfinite(c.steering) || c.steering < -1.0f || c.steering > 1.0f)
    return "steering " + std::to_string(c.steering) + " outside [-1, 1]";
  if (c.headlights < 0 || c.headlights > 2)
    return "headlights " + std::to_string(c.headlights) + " outside 0..2";
  if (c.indicators < 0 || c.indicators > 3)
    return "indicators " + std::to_string(c.indicators) + " outside 0..3";
  return "";
}

std::string state_problem(const protocol_state_t &s) {
  if (s.throttle_milli < -PROTOCOL_MILLI || s.throttle_milli > PROTOCOL_MILLI)
    return "applied throttle " + std::to_string(s.throttle_milli) + " outside +-" +
           std::to_string(PROTOCOL_MILLI);
  if (s.steering_milli < -PROTOCOL_MILLI || s.steering_milli > PROTOCOL_MILLI)
    return "applied steering " + std::to_string(s.steering_milli) + " outside +-" +
           std::to_string(PROTOCOL_MILLI);
  if (s.mode > PROTOCOL_MODE_FAILSAFE) return "unknown mode " + std::to_string(s.mode);
  if ((s.lights & PROTOCOL_LIGHTS_HEAD_MASK) > 2)
    return "unknown headlight level " + std::to_string(s.lights & PROTOCOL_LIGHTS_HEAD_MASK);
  return "";
}

protocol_command_t make_command(const autodrive::vehicle_command_t *latest, bool fresh,
                                uint16_t seq) {
  protocol_command_t m{};
  m.seq = seq;
  if (latest) {
    m.headlights = static_cast<uint8_t>(latest->headlights);
    m.indicators = static_cast<uint8_t>(latest->indicators);
  }
  if (latest && fresh) {
    m.throttle_milli = static_cast<int16_t>(std::lround(latest->throttle * PROTOCOL_MILLI));
    m.steering_milli = static_cast<int16_t>(std::lround(latest->steering * PROTOCOL_MILLI));
    m.flags = latest->engaged ? PROTOCOL_CMD_ENGAGED : 0;
  }
  return m;
}

}  // namespace autodrive::bridge
