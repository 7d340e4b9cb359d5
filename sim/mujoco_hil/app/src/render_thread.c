/* The cameras on a thread of their own (render_thread.h). */
#include "render_thread.h"

#include <stdio.h>

static void *render_thread_run(void *arg) {
  render_thread_t *t = arg;
  char err[256] = "";
  int rc = cameras_open(&t->cams, t->s, t->cameras, t->eye, t->eye_render, err, sizeof err);
  if (rc == 0) {
    cameras_set_effects(&t->cams, t->noise, t->blur_px, t->exposure_ev, t->seed);
    cameras_set_render_scale(&t->cams, t->scale);
  }
  pthread_mutex_lock(&t->mu);
  t->opened = rc == 0 ? 1 : -1;
  snprintf(t->err, sizeof t->err, "%s", err);
  pthread_cond_broadcast(&t->cv);
  while (rc == 0) {
    while (!t->queued && !t->stop) pthread_cond_wait(&t->cv, &t->mu);
    if (t->stop) break;
    mjData *snap = t->snap[t->head];
    const int64_t frame_us = t->frame_us[t->head];
    const double scale = t->frame_scale[t->head];
    pthread_mutex_unlock(&t->mu);
    if (scale != t->scale) cameras_set_render_scale(&t->cams, t->scale = scale);
    const int r =
        cameras_publish(&t->cams, sim_render_model(t->s), snap, t->lcm, frame_us, err, sizeof err);
    pthread_mutex_lock(&t->mu);
    if (r != 0) {
      t->failed = 1;
      snprintf(t->err, sizeof t->err, "%s", err);
    }
    t->rendered++;
    t->head = (t->head + 1) % RENDER_THREAD_QUEUE;
    t->queued--;
  }
  pthread_mutex_unlock(&t->mu);
  cameras_close(&t->cams);
  return NULL;
}

int render_thread_start(render_thread_t *t, sim_t *s, lcm_t *lcm, char *err, size_t err_sz) {
  t->s = s;
  t->lcm = lcm;
  for (int i = 0; i < RENDER_THREAD_QUEUE; i++)
    if (!(t->snap[i] = mj_makeData(sim_render_model(s)))) {
      snprintf(err, err_sz, "cannot allocate the render thread's snapshots");
      return -1;
    }
  if (pthread_mutex_init(&t->mu, NULL) != 0 || pthread_cond_init(&t->cv, NULL) != 0 ||
      pthread_create(&t->th, NULL, render_thread_run, t) != 0) {
    snprintf(err, err_sz, "cannot start the render thread");
    return -1;
  }
  pthread_mutex_lock(&t->mu);
  while (!t->opened) pthread_cond_wait(&t->cv, &t->mu);
  pthread_mutex_unlock(&t->mu);
  if (t->opened > 0) return 0;
  pthread_join(t->th, NULL);
  snprintf(err, err_sz, "%s", t->err);
  return -1;
}

int render_thread_submit(render_thread_t *t, const sim_t *s, int64_t now_us, double scale,
                         char *err, size_t err_sz) {
  pthread_mutex_lock(&t->mu);
  const int failed = t->failed;
  int queued = 0;
  if (failed) {
    snprintf(err, err_sz, "%s", t->err);
  } else if (t->queued == RENDER_THREAD_QUEUE) {
    t->skipped++;
  } else {
    queued = 1;
    const int tail = (t->head + t->queued) % RENDER_THREAD_QUEUE;
    sim_render_snapshot(s, t->snap[tail]);
    t->frame_us[tail] = now_us;
    t->frame_scale[tail] = scale;
    t->queued++;
    pthread_cond_signal(&t->cv);
  }
  pthread_mutex_unlock(&t->mu);
  return failed ? -1 : queued;
}

long render_thread_backlog_us(render_thread_t *t) {
  pthread_mutex_lock(&t->mu);
  const int waiting = t->queued > 1 ? t->queued - 1 : 0;
  pthread_mutex_unlock(&t->mu);
  return (long)waiting * RENDER_THREAD_YIELD_US;
}

void render_thread_stop(render_thread_t *t) {
  pthread_mutex_lock(&t->mu);
  t->stop = 1;
  pthread_cond_signal(&t->cv);
  pthread_mutex_unlock(&t->mu);
  pthread_join(t->th, NULL);
  for (int i = 0; i < RENDER_THREAD_QUEUE; i++) mj_deleteData(t->snap[i]);
  fprintf(stderr,
          "autodrive-sim: cameras (render thread): %ld frame times rendered, %ld skipped (its "
          "queue was full)\n",
          t->rendered, t->skipped);
}
