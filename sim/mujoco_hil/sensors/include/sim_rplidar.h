/* sim_rplidar: an emulated SLAMTEC RPLIDAR A1 on a pseudo-terminal.
 *
 * The runtime's real RPLIDAR driver opens the pty symlink (e.g. <run-dir>/nigel1-lidar) at
 * 115200 baud and talks the device's serial protocol; this module answers it byte for byte:
 *   requests   A5 <cmd> [<size> <payload...> <xor checksum>] (payload only when cmd & 0x80)
 *   STOP 0x25, RESET 0x40: no response; SCAN 0x20 / FORCE_SCAN 0x21: descriptor
 *   A5 5A 05 00 00 40 81 then 5-byte measurement nodes until STOP;
 *   GET_INFO 0x50 -> A5 5A 14 00 00 00 04 + 20 bytes; GET_HEALTH 0x52 -> A5 5A 03 00 00 00 06
 *   + 3 bytes; GET_SAMPLERATE 0x59 -> A5 5A 04 00 00 00 15 + 4 bytes. Others are ignored.
 *   node: [0] quality<<2 | !S<<1 | S  (S = first node of a new revolution)
 *         [1] angle_q6[6:0]<<1 | 1     (check bit C = 1)
 *         [2] angle_q6[14:7]           (angle in degrees * 64, clockwise seen from above)
 *         [3..4] distance_q2 LE        (distance in mm * 4; 0 = no return)
 * Bytes leave at the configured baud (10 bits per byte, 8N1) against the caller's clock, like
 * the real UART: 115200 baud carries at most 2304 nodes/s, i.e. 6.4 revolutions/s of 360
 * nodes. Like the real device (fixed sample rate), a faster spin gives fewer nodes per
 * revolution: each pushed scan is thinned evenly to what the wire carries in the time since
 * the previous push (97 %; ~322 nodes at 7 Hz). If the queue still holds more than two
 * revolutions, the oldest nodes are dropped (counted).
 * The device angle 0 is the car's forward axis; a ray at CCW angle a reads (360 - a) mod 360.
 *
 * Not thread-safe: call everything from one thread (the sim's main loop).
 */
#ifndef SIM_RPLIDAR_H
#define SIM_RPLIDAR_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

#define SIM_RPLIDAR_BAUD 115200

typedef struct sim_rplidar sim_rplidar_t;

typedef struct sim_rplidar_stats {
  uint64_t bytes_tx;      /* bytes written to the pty */
  uint64_t nodes_tx;      /* measurement nodes sent */
  uint64_t nodes_dropped; /* nodes dropped because the wire was too slow or the pty full */
  uint64_t requests_rx;   /* well-formed requests received */
  uint64_t bad_requests;  /* bad checksum or unknown command */
} sim_rplidar_stats_t;

/* Opens a pty and points the symlink link_path at its slave (replacing an old symlink there;
 * refuses to replace a non-symlink). baud is the emulated wire rate (SIM_RPLIDAR_BAUD).
 * Returns NULL with a message in err on failure. Caller owns the result. */
sim_rplidar_t *sim_rplidar_create(const char *link_path, uint32_t baud, char *err, size_t err_len);
/* Closes the pty and removes the symlink. */
void sim_rplidar_destroy(sim_rplidar_t *r);

/* The pty slave path (/dev/pts/N). Borrowed string. */
const char *sim_rplidar_slave_path(const sim_rplidar_t *r);

/* Queues one revolution for sending if the device is scanning (ignored otherwise), in the
 * real A1's order: clockwise, device angles growing (sim_lidar_sweep_ray).
 * ranges_m[i] is the ray at CCW angle i * 360 / num_rays deg (as sim_lidar_scan_t),
 * +inf / out of range -> distance 0 and quality 0; quality may be NULL (then 47 on a return). */
void sim_rplidar_push_scan(sim_rplidar_t *r, const float *ranges_m, const float *quality,
                           int num_rays);

/* Streams sweep steps [from, to) of the revolution being measured (sim_lidar_last_cast), as a
 * real A1 sends nodes while it spins (a whole-revolution push delays every node by up to one
 * revolution, ~143 ms at 7 Hz). Step 0 starts a revolution (the S flag). Same node subset and
 * encoding as push_scan. */
void sim_rplidar_push_rays(sim_rplidar_t *r, const float *ranges_m, const float *quality, int from,
                           int to, int num_rays);

/* Reads and answers requests and writes the bytes the wire could carry up to now_us (sim or
 * wall clock, monotonic, [us]). Never blocks. Call often (e.g. every physics step).
 * Returns 0, or -1 on a fatal pty error (message in err). */
int sim_rplidar_poll(sim_rplidar_t *r, int64_t now_us, char *err, size_t err_len);

/* 1 while a SCAN is running (between SCAN and STOP/RESET/client hang-up). */
int sim_rplidar_scanning(const sim_rplidar_t *r);

void sim_rplidar_get_stats(const sim_rplidar_t *r, sim_rplidar_stats_t *out);

/* Encodes one measurement node into out[5] (exposed for tests and fuzzing).
 * angle_deg is the device's clockwise angle [deg], distance_mm 0 = no return. */
void sim_rplidar_encode_node(uint8_t out[5], int start, uint8_t quality, double angle_deg,
                             double distance_mm);

#ifdef __cplusplus
}
#endif
#endif /* SIM_RPLIDAR_H */
