/* sim_lidar_lcm: a sim_lidar scan as autodrive_lidar_scan_t on LCM (<VEH>_LIDAR, 7 Hz). */
#ifndef SIM_LIDAR_LCM_H
#define SIM_LIDAR_LCM_H

#include <stdint.h>

#include <lcm/lcm.h>

#include "sim_lidar.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Publishes scan on channel (e.g. "NIGEL1_LIDAR") with frame_id (e.g. "laser").
 * Returns lcm_publish's result (0 on success), -1 on an empty scan. */
int sim_lidar_publish(lcm_t *lcm, const char *channel, const char *frame_id,
                      const sim_lidar_scan_t *scan);

/* The same message encoded, for a publisher of its own (a queue off the stepping thread):
 * its size in bytes (-1 on an empty scan), and the encoding into buf of that size (returns
 * the bytes written, or -1). */
int sim_lidar_encoded_size(const char *frame_id, const sim_lidar_scan_t *scan);
int sim_lidar_encode(uint8_t *buf, int size, const char *frame_id, const sim_lidar_scan_t *scan);

#ifdef __cplusplus
}
#endif
#endif /* SIM_LIDAR_LCM_H */
