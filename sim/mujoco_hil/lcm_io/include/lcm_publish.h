/* LCM output of the simulator: <VEH>_GROUND_TRUTH (100 Hz), SIM_CLOCK, <VEH>_LIDAR, and the
 * ground-truth
 * record file used to check determinism (encoded ground_truth_t, each prefixed by its size as
 * a 4-byte big-endian length). */
#ifndef SIM_LCM_PUBLISH_H
#define SIM_LCM_PUBLISH_H

#include <stdint.h>
#include <stdio.h>

#include <lcm/lcm.h>

#include "publish_queue.h"
#include "sim.h"
#include "sim_lidar_lcm.h"

/* Queues car's ground truth for NIGEL<car>_GROUND_TRUTH on q (NULL: no LCM); appends it to
 * log if non-NULL. Returns 0, or -1 when the message could not be encoded. */
int publish_ground_truth(publish_queue_t *q, const sim_t *s, int car, FILE *log);
int publish_sim_clock(publish_queue_t *q, int64_t utime, double rtf, int paused);
/* Queues a LIDAR scan on channel (the send leaves the stepping thread, like ground truth). */
int publish_lidar_scan(publish_queue_t *q, const char *channel, const char *frame_id,
                       const sim_lidar_scan_t *scan);

#endif
