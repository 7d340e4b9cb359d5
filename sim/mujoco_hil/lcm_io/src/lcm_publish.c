/* LCM publishing (see lcm_publish.h). */
#include <autodrive_channels.h>
#include "lcm_publish.h"

#include <stdlib.h>
#include <string.h>

#include "autodrive_ground_truth_t.h"
#include "autodrive_sim_clock_t.h"

/* prefix followed by car's decimal digits (car >= 0), into dst of dst_sz >= 16 bytes: 100 ground
 * truths a car every sim second, where two snprintf calls were ~0.6 % of a 1-car step */
static void publish_join_name(char *dst, size_t dst_sz, const char *prefix, int car,
                              const char *suffix) {
  char digits[12];
  int n = 0;
  do {
    digits[n++] = (char)('0' + car % 10);
    car /= 10;
  } while (car > 0 && n < (int)sizeof digits);
  size_t k = 0;
  for (const char *p = prefix; *p && k + 1 < dst_sz; p++) dst[k++] = *p;
  while (n > 0 && k + 1 < dst_sz) dst[k++] = digits[--n];
  for (const char *p = suffix; *p && k + 1 < dst_sz; p++) dst[k++] = *p;
  dst[k] = '\0';
}

int publish_ground_truth(publish_queue_t *q, const sim_t *s, int car, FILE *log) {
  sim_truth_t t;
  sim_get_truth(s, car, &t);
  char vehicle[16], channel[48];
  publish_join_name(vehicle, sizeof vehicle, AUTODRIVE_VEHICLE_PREFIX, car, "");
  publish_join_name(channel, sizeof channel, AUTODRIVE_VEHICLE_PREFIX, car,
                    AUTODRIVE_CH_GROUND_TRUTH_SUFFIX);
  autodrive_ground_truth_t msg;
  memset(&msg, 0, sizeof msg);
  msg.utime = sim_time_us(s);
  msg.vehicle = vehicle;
  memcpy(msg.position_m, t.pos_m, sizeof msg.position_m);
  memcpy(msg.orientation_wxyz, t.quat_wxyz, sizeof msg.orientation_wxyz);
  msg.yaw_rad = t.yaw_rad;
  memcpy(msg.linear_velocity_m_s, t.vel_body_m_s, sizeof msg.linear_velocity_m_s);
  memcpy(msg.angular_velocity_rad_s, t.gyro_body_rad_s, sizeof msg.angular_velocity_rad_s);
  msg.steering_angle_rad = t.steering_rad;
  msg.in_collision = (int8_t)t.in_collision;
  msg.command_throttle = (float)t.command_throttle;
  msg.command_steering = (float)t.command_steering;
  msg.expert_steering = (float)t.expert_steering;
  uint8_t buf[512];
  const int n = autodrive_ground_truth_t_encode(buf, 0, sizeof buf, &msg);
  if (n <= 0) return -1;
  if (log) {
    const uint8_t len[4] = {(uint8_t)(n >> 24), (uint8_t)(n >> 16), (uint8_t)(n >> 8), (uint8_t)n};
    fwrite(len, 1, 4, log);
    fwrite(buf, 1, (size_t)n, log);
  }
  if (!q) return 0;
  uint8_t *out = publish_queue_reserve(q, channel, (size_t)n);
  if (!out) return -1;
  memcpy(out, buf, (size_t)n);
  publish_queue_commit(q);
  return 0;
}

int publish_sim_clock(publish_queue_t *q, int64_t utime, double rtf, int paused) {
  if (!q) return 0;
  autodrive_sim_clock_t msg = {utime, rtf, (int8_t)paused};
  const int n = autodrive_sim_clock_t_encoded_size(&msg);
  uint8_t *out = publish_queue_reserve(q, AUTODRIVE_CH_SIM_CLOCK, (size_t)n);
  if (!out || autodrive_sim_clock_t_encode(out, 0, n, &msg) != n) return -1;
  publish_queue_commit(q);
  return 0;
}

int publish_lidar_scan(publish_queue_t *q, const char *channel, const char *frame_id,
                       const sim_lidar_scan_t *scan) {
  const int n = sim_lidar_encoded_size(frame_id, scan);
  if (n <= 0) return -1;
  uint8_t *out = publish_queue_reserve(q, channel, (size_t)n);
  if (!out || sim_lidar_encode(out, n, frame_id, scan) != n) return -1;
  publish_queue_commit(q);
  return 0;
}
