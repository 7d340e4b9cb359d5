/* Asynchronous LCM publishing: the stepping thread encodes a message into the queue and a
 * worker thread sends it. A UDP send costs tens of microseconds of system time, as much as a
 * tenth of a physics step; moved off the stepping thread it overlaps with the physics on the
 * second core. Messages leave in the order they were queued. A full queue makes the caller
 * wait (nothing is dropped), and lcmq_destroy sends everything still queued before it returns.
 *
 * Use: uint8_t *buf = lcmq_reserve(q, channel, n); type_encode(buf, 0, n, &msg);
 *      lcmq_commit(q); ... lcmq_flush(q); */
#ifndef SIM_LCMQ_H
#define SIM_LCMQ_H

#include <stddef.h>
#include <stdint.h>

#include <lcm/lcm.h>

typedef struct lcmq lcmq_t;

/* A queue whose worker publishes on lcm (which the caller keeps alive until lcmq_destroy).
 * Returns NULL with a message in err. */
lcmq_t *lcmq_create(lcm_t *lcm, char *err, size_t err_sz);
/* Room for one message of n bytes on channel; NULL if n is larger than the queue. Waits while
 * the queue is full. Every reserve must be followed by one commit before the next reserve. */
uint8_t *lcmq_reserve(lcmq_t *q, const char *channel, size_t n);
/* Hands the reserved message to the worker, which sends it at the next lcmq_flush (or once
 * half the queue is waiting). */
void lcmq_commit(lcmq_t *q);
/* Wakes the worker for what is queued. Call it every millisecond of wall time or so: the
 * latency of a message is then at most that, at one thread wake-up per batch. */
void lcmq_flush(lcmq_t *q);
/* Messages the worker failed to publish so far (LCM refused them). */
uint64_t lcmq_failures(const lcmq_t *q);
/* Sends what is queued, stops the worker and frees the queue. NULL is fine. */
void lcmq_destroy(lcmq_t *q);

#endif
