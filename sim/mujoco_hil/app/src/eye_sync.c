/* --eye-sync: the overhead cameras' frames in lockstep with the Eye (eye_sync.h). */
#include "eye_sync.h"

#include <poll.h>
#include <stdio.h>
#include <stdlib.h>

#include <autodrive_channels.h>
#include <autodrive_eye_frame_done_t.h>

#include "app_common.h"

#define EYE_SYNC_MAX_LATENCY_US 10000000 /* a latency beyond 10 s of sim time is not believed */

struct eye_sync {
  lcm_t *lcm;
  autodrive_eye_frame_done_t_subscription_t *sub;
  int heard;          /* an Eye answered and was not given up since */
  int64_t latency_us; /* its latency (sim time) */
  int64_t done_us;    /* capture time of the newest frame it is done with; -1: none */
  int64_t lost_at_us; /* done_us when it was given up (heard again after it); INT64_MIN: never */
  int first_sent;     /* the first frame went out (the sim waited for an Eye before it) */
  int64_t pending[EYE_SYNC_MAX_PENDING]; /* capture times sent, oldest first from head */
  int head, n;
  long waits, given_up, refused;
  double waited_s, wait_s; /* wall time waited in all; the limit for a silent Eye [s] */
};

static void eye_sync_handle(eye_sync_t *e, int timeout_ms);

/* Frames the Eye is done with leave the queue. */
static void eye_sync_drop_done(eye_sync_t *e) {
  while (e->n > 0 && e->pending[e->head] <= e->done_us) {
    e->head = (e->head + 1) % EYE_SYNC_MAX_PENDING;
    e->n--;
  }
}

static void eye_sync_on_done(const lcm_recv_buf_t *rbuf, const char *channel,
                             const autodrive_eye_frame_done_t *msg, void *user) {
  (void)rbuf;
  eye_sync_t *e = user;
  if (msg->latency_us < 0 || msg->latency_us > EYE_SYNC_MAX_LATENCY_US || msg->utime < -1) {
    if (e->refused++ == 0)
      fprintf(stderr,
              "[autodrive-sim] %s: frame %lld us with latency %lld us refused (want a capture "
              "time >= 0, or -1, and a latency of 0..%d us); further ones are counted only\n",
              channel, (long long)msg->utime, (long long)msg->latency_us, EYE_SYNC_MAX_LATENCY_US);
    return;
  }
  e->latency_us = msg->latency_us;
  if (msg->utime < 0) { /* an Eye that is ready and has had no frame yet */
    e->heard = 1;
    return;
  }
  if (msg->utime > e->done_us) e->done_us = msg->utime;
  if (!e->heard && msg->utime > e->lost_at_us) e->heard = 1;
  eye_sync_drop_done(e);
}

eye_sync_t *eye_sync_create(lcm_t *lcm, double wait_s, char *err, size_t err_sz) {
  if (!(wait_s >= EYE_SYNC_WAIT_MIN_S && wait_s <= EYE_SYNC_WAIT_MAX_S)) {
    snprintf(err, err_sz, "--eye-sync-wait-s %g: expected %g..%g s", wait_s, EYE_SYNC_WAIT_MIN_S,
             EYE_SYNC_WAIT_MAX_S);
    return NULL;
  }
  eye_sync_t *e = calloc(1, sizeof *e);
  if (!e) {
    snprintf(err, err_sz, "--eye-sync: out of memory");
    return NULL;
  }
  e->lcm = lcm;
  e->wait_s = wait_s;
  e->done_us = -1;
  e->lost_at_us = INT64_MIN;
  e->sub =
      autodrive_eye_frame_done_t_subscribe(lcm, AUTODRIVE_CH_EYE_FRAME_DONE, eye_sync_on_done, e);
  if (!e->sub) {
    snprintf(err, err_sz, "--eye-sync: cannot subscribe to " AUTODRIVE_CH_EYE_FRAME_DONE);
    free(e);
    return NULL;
  }
  return e;
}

void eye_sync_destroy(eye_sync_t *e) {
  if (!e) return;
  autodrive_eye_frame_done_t_unsubscribe(e->lcm, e->sub);
  free(e);
}

void eye_sync_before_frame(eye_sync_t *e) {
  if (e->first_sent) return;
  e->first_sent = 1;
  const double limit_s = e->wait_s > EYE_SYNC_FIRST_S ? e->wait_s : EYE_SYNC_FIRST_S;
  const double t_give_up = app_wall_s() + limit_s;
  while (!e->heard && !app_stop_requested()) {
    eye_sync_handle(e, 50);
    if (!e->heard && app_wall_s() > t_give_up) {
      e->given_up++;
      fprintf(stderr,
              "[autodrive-sim] " EYE_SYNC_GIVE_UP_MARK
              " (%ld): no Eye announced itself on " AUTODRIVE_CH_EYE_FRAME_DONE
              " in %.1f s (wall): running on, the run now depends on wall time; it is waited "
              "for once it answers\n",
              e->given_up, limit_s);
      return;
    }
  }
}

void eye_sync_frame_sent(eye_sync_t *e, int64_t capture_us) {
  if (e->n == EYE_SYNC_MAX_PENDING) { /* the oldest is not waited for any more */
    e->head = (e->head + 1) % EYE_SYNC_MAX_PENDING;
    e->n--;
  }
  e->pending[(e->head + e->n) % EYE_SYNC_MAX_PENDING] = capture_us;
  e->n++;
}

/* Handles what waits on LCM's socket, waiting up to timeout_ms for it. */
static void eye_sync_handle(eye_sync_t *e, int timeout_ms) {
  struct pollfd p = {lcm_get_fileno(e->lcm), POLLIN, 0};
  while (poll(&p, 1, timeout_ms) > 0 && (p.revents & POLLIN)) {
    if (lcm_handle(e->lcm) != 0) break;
    timeout_ms = 0;
  }
}

void eye_sync_poll(eye_sync_t *e) {
  eye_sync_handle(e, 0);
}

int eye_sync_due(const eye_sync_t *e, int64_t now_us) {
  return e->heard && e->n > 0 && e->pending[e->head] + e->latency_us <= now_us;
}

void eye_sync_wait(eye_sync_t *e, int64_t now_us) {
  const double t0 = app_wall_s();
  const double t_give_up = t0 + e->wait_s;
  e->waits++;
  while (eye_sync_due(e, now_us) && !app_stop_requested()) {
    eye_sync_handle(e, 50);
    if (eye_sync_due(e, now_us) && app_wall_s() > t_give_up) {
      e->given_up++;
      fprintf(stderr,
              "[autodrive-sim] " EYE_SYNC_GIVE_UP_MARK
              " (%ld): it has not finished the frame of t = %.3f s for %.1f s (wall; "
              "no " AUTODRIVE_CH_EYE_FRAME_DONE
              "): running on without it, the run now depends on wall time (--eye-sync-wait-s "
              "sets the limit)\n",
              e->given_up, e->pending[e->head] * 1e-6, e->wait_s);
      e->heard = 0;
      e->lost_at_us = e->done_us;
      e->n = 0;
      break;
    }
  }
  e->waited_s += app_wall_s() - t0;
}

long eye_sync_stats(const eye_sync_t *e, double *waited_s, long *given_up) {
  if (waited_s) *waited_s = e ? e->waited_s : 0.0;
  if (given_up) *given_up = e ? e->given_up : 0;
  return e ? e->waits : 0;
}
