/* Asynchronous LCM publishing (see publish_queue.h). */
#include "publish_queue.h"

#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define LCMQ_SLOTS 1024                /* 5 s of 16 cars' ground truth at 1x real time */
#define LCMQ_MAX_MSG_BYTES (64u << 20) /* far above any image the sim renders */
#define LCMQ_CHANNEL_BYTES 64

typedef struct publish_queue_slot {
  char channel[LCMQ_CHANNEL_BYTES];
  uint8_t *data;
  size_t len, cap;
} publish_queue_slot_t;

struct publish_queue {
  lcm_t *lcm;
  pthread_t worker;
  pthread_mutex_t mu;
  pthread_cond_t has_msg, has_room;
  publish_queue_slot_t slot[LCMQ_SLOTS];
  size_t head, count; /* the worker sends slot[head]; the producer fills slot[head + count] */
  int worker_waiting, producer_waiting, stop;
  uint64_t failures;
};

static void *publish_queue_run(void *arg) {
  publish_queue_t *q = arg;
  pthread_mutex_lock(&q->mu);
  for (;;) {
    while (q->count == 0 && !q->stop) {
      q->worker_waiting = 1;
      pthread_cond_wait(&q->has_msg, &q->mu);
      q->worker_waiting = 0;
    }
    if (q->count == 0) break; /* stopped and drained */
    /* Everything committed so far goes in one batch, with the lock released: one lock and
     * unlock per batch rather than per message, so the stepping thread (which takes the lock
     * to reserve and commit) seldom finds it held. */
    const size_t head = q->head, batch = q->count;
    pthread_mutex_unlock(&q->mu); /* the producer never touches a committed slot */
    uint64_t failed = 0;
    for (size_t i = 0; i < batch; i++) {
      const publish_queue_slot_t *sl = &q->slot[(head + i) % LCMQ_SLOTS];
      if (lcm_publish(q->lcm, sl->channel, sl->data, (unsigned)sl->len) != 0) failed++;
    }
    pthread_mutex_lock(&q->mu);
    q->failures += failed;
    q->head = (head + batch) % LCMQ_SLOTS;
    q->count -= batch;
    if (q->producer_waiting) pthread_cond_signal(&q->has_room);
  }
  pthread_mutex_unlock(&q->mu);
  return NULL;
}

publish_queue_t *publish_queue_create(lcm_t *lcm, char *err, size_t err_sz) {
  publish_queue_t *q = calloc(1, sizeof *q);
  if (!q) {
    snprintf(err, err_sz, "LCM publish queue: out of memory");
    return NULL;
  }
  q->lcm = lcm;
  pthread_mutex_init(&q->mu, NULL);
  pthread_cond_init(&q->has_msg, NULL);
  pthread_cond_init(&q->has_room, NULL);
  if (pthread_create(&q->worker, NULL, publish_queue_run, q) != 0) {
    snprintf(err, err_sz, "LCM publish queue: cannot start its thread");
    pthread_cond_destroy(&q->has_room);
    pthread_cond_destroy(&q->has_msg);
    pthread_mutex_destroy(&q->mu);
    free(q);
    return NULL;
  }
  return q;
}

uint8_t *publish_queue_reserve(publish_queue_t *q, const char *channel, size_t n) {
  if (n > LCMQ_MAX_MSG_BYTES || strlen(channel) >= LCMQ_CHANNEL_BYTES) return NULL;
  pthread_mutex_lock(&q->mu);
  while (q->count == LCMQ_SLOTS) { /* the worker is behind: wait rather than drop */
    q->producer_waiting = 1;
    pthread_cond_wait(&q->has_room, &q->mu);
    q->producer_waiting = 0;
  }
  publish_queue_slot_t *sl = &q->slot[(q->head + q->count) % LCMQ_SLOTS];
  pthread_mutex_unlock(&q->mu);
  if (n > sl->cap) {
    uint8_t *grown = realloc(sl->data, n);
    if (!grown) return NULL;
    sl->data = grown;
    sl->cap = n;
  }
  strcpy(sl->channel, channel);
  sl->len = n;
  return sl->data;
}

void publish_queue_commit(publish_queue_t *q) {
  pthread_mutex_lock(&q->mu);
  q->count++;
  /* a waking thread costs a system call each: wake the worker for a batch (publish_queue_flush), or
   * when half the queue is waiting so that the producer never has to */
  if (q->worker_waiting && q->count >= LCMQ_SLOTS / 2) pthread_cond_signal(&q->has_msg);
  pthread_mutex_unlock(&q->mu);
}

void publish_queue_flush(publish_queue_t *q) {
  pthread_mutex_lock(&q->mu);
  if (q->worker_waiting && q->count > 0) pthread_cond_signal(&q->has_msg);
  pthread_mutex_unlock(&q->mu);
}

uint64_t publish_queue_failures(const publish_queue_t *q) {
  pthread_mutex_lock((pthread_mutex_t *)&q->mu);
  const uint64_t n = q->failures;
  pthread_mutex_unlock((pthread_mutex_t *)&q->mu);
  return n;
}

void publish_queue_destroy(publish_queue_t *q) {
  if (!q) return;
  pthread_mutex_lock(&q->mu);
  q->stop = 1;
  pthread_cond_signal(&q->has_msg);
  pthread_mutex_unlock(&q->mu);
  pthread_join(q->worker, NULL);
  for (size_t i = 0; i < LCMQ_SLOTS; i++) free(q->slot[i].data);
  pthread_cond_destroy(&q->has_room);
  pthread_cond_destroy(&q->has_msg);
  pthread_mutex_destroy(&q->mu);
  free(q);
}
