/* Asynchronous LCM publishing: the stepping thread encodes a message into the queue and a
 * worker thread sends it. A UDP send costs tens of microseconds of system time, as much as a
 * tenth of a physics step; moved off the stepping thread it overlaps with the physics on the
 * second core. Messages leave in the order they were queued. A full queue makes the caller
 * wait (nothing is dropped), and publish_queue_destroy sends everything still queued before it
 * returns.
 *
 * Use: uint8_t *buf = publish_queue_reserve(q, channel, n); type_encode(buf, 0, n, &msg);
 *      publish_queue_commit(q); ... publish_queue_flush(q); */
#ifndef SIM_PUBLISH_QUEUE_H
#define SIM_PUBLISH_QUEUE_H

#include <stddef.h>
#include <stdint.h>

#include <lcm/lcm.h>

typedef struct publish_queue publish_queue_t;

/* A queue whose worker publishes on lcm (which the caller keeps alive until publish_queue_destroy).
 * Returns NULL with a message in err. */
publish_queue_t *publish_queue_create(lcm_t *lcm, char *err, size_t err_sz);
/* Room for one message of n bytes on channel; NULL if n is larger than the queue. Waits while
 * the queue is full. Every reserve must be followed by one commit before the next reserve. */
uint8_t *publish_queue_reserve(publish_queue_t *q, const char *channel, size_t n);
/* Hands the reserved message to the worker, which sends it at the next publish_queue_flush (or once
 * half the queue is waiting). */
void publish_queue_commit(publish_queue_t *q);
/* Wakes the worker for what is queued. Call it every millisecond of wall time or so: the
 * latency of a message is then at most that, at one thread wake-up per batch. */
void publish_queue_flush(publish_queue_t *q);
/* Messages the worker failed to publish so far (LCM refused them). */
uint64_t publish_queue_failures(const publish_queue_t *q);
/* Sends what is queued, stops the worker and frees the queue. NULL is fine. */
void publish_queue_destroy(publish_queue_t *q);

#endif
