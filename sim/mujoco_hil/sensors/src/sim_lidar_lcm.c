/* sim_lidar_lcm: see sim_lidar_lcm.h. */
#include "sim_lidar_lcm.h"

#include <autodrive_lidar_scan_t.h>

static void sim_lidar_msg(const char *frame_id, const sim_lidar_scan_t *scan,
                          autodrive_lidar_scan_t *out) {
  autodrive_lidar_scan_t msg;
  msg.utime = scan->utime;
  msg.frame_id = (char *)frame_id;
  msg.angle_min_rad = scan->angle_min_rad;
  msg.angle_increment_rad = scan->angle_increment_rad;
  msg.angle_max_rad = scan->angle_min_rad + scan->angle_increment_rad * (float)(scan->num_rays - 1);
  msg.time_increment_s = scan->time_increment_s;
  msg.scan_time_s = scan->scan_time_s;
  msg.range_min_m = scan->range_min_m;
  msg.range_max_m = scan->range_max_m;
  msg.num_ranges = scan->num_rays;
  msg.ranges_m = (float *)scan->ranges_m;
  msg.intensities = (float *)scan->intensities;
  *out = msg;
}

int sim_lidar_publish(lcm_t *lcm, const char *channel, const char *frame_id,
                      const sim_lidar_scan_t *scan) {
  if (!scan || scan->num_rays <= 0) return -1;
  autodrive_lidar_scan_t msg;
  sim_lidar_msg(frame_id, scan, &msg);
  return autodrive_lidar_scan_t_publish(lcm, channel, &msg);
}

int sim_lidar_encoded_size(const char *frame_id, const sim_lidar_scan_t *scan) {
  if (!scan || scan->num_rays <= 0) return -1;
  autodrive_lidar_scan_t msg;
  sim_lidar_msg(frame_id, scan, &msg);
  return autodrive_lidar_scan_t_encoded_size(&msg);
}

int sim_lidar_encode(uint8_t *buf, int size, const char *frame_id, const sim_lidar_scan_t *scan) {
  if (!scan || scan->num_rays <= 0) return -1;
  autodrive_lidar_scan_t msg;
  sim_lidar_msg(frame_id, scan, &msg);
  return autodrive_lidar_scan_t_encode(buf, 0, size, &msg);
}
