/* A kernel-side channel filter for an lcm_t that subscribes to one or two channels: a classic BPF
 * socket filter (SO_ATTACH_FILTER) on LCM's receive socket that keeps only the small messages
 * ("LC02") of those channels. LCM's UDP multicast provider reads every message on its group and
 * port in a thread of its own and drops the ones nobody subscribed to in user space; the simulator,
 * which publishes ground truth, SIM_CLOCK, LIDAR scans and light states at hundreds of messages per
 * simulated second, then woke that thread for each of its own messages (thousands a second
 * of wall time in lockstep) only to find the rare TRAFFIC_LIGHT_COMMAND. With the filter the
 * kernel drops them before they are queued: no wake-up, no copy, no system call. */
#ifndef SIM_LCM_RECEIVE_FILTER_H
#define SIM_LCM_RECEIVE_FILTER_H

#include <stddef.h>

#include <lcm/lcm.h>

#ifdef __cplusplus
extern "C" {
#endif

/* Attaches the filter to the receive socket of lcm (made with url, after its subscriptions to
 * the count (1 or 2) channels, and to nothing else). Returns 1 when attached, 0 when there is
 * nothing to filter (not udpm://), -1 with a message in err (the socket was not found, or the
 * kernel refused the filter). Fragmented messages ("LC03") of the channels are dropped too: keep
 * them to messages under 1400 bytes. */
int lcm_receive_filter_keep(lcm_t *lcm, const char *url, const char *const *channels, int count,
                            char *err, size_t err_sz);

#ifdef __cplusplus
}
#endif
#endif
