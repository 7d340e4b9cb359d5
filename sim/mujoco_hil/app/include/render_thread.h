/* The cameras on a thread of their own (autodrive-sim in real time, --rtf, --lockstep-client). */
#ifndef SIM_APP_RENDER_THREAD_H
#define SIM_APP_RENDER_THREAD_H

#include <pthread.h>
#include <stdint.h>

#include <lcm/lcm.h>

#include "cameras.h"
#include "sim.h"

/* The cameras on their own thread (real time, --rtf, --lockstep-client). Software OpenGL
 * takes ~40 ms of CPU per 1280x960 frame, so rendering Tiny Town's four overhead cameras on
 * the stepping thread stalled it for over 500 ms under load, and the runtimes, which want a
 * Nano frame every 500 ms of wall time, dropped their links. The stepping thread queues a
 * snapshot of the state at each frame time and steps on; the render thread renders them in
 * order. While snapshots wait, the stepping thread sleeps RENDER_THREAD_YIELD_US per step and
 * waiting frame, so the sim slows to what the renderer follows (frames stay in sim time, the
 * ptys never go quiet for long); a frame time that finds the queue full is skipped and
 * counted. Free --lockstep and --lockstep-frames render on the stepping thread, every frame
 * time (repeatable runs). The GL context lives on the render thread. */
#define RENDER_THREAD_QUEUE 4
#define RENDER_THREAD_YIELD_US 3000
typedef struct render_thread {
  pthread_t th;
  pthread_mutex_t mu;
  pthread_cond_t cv;
  cameras_t cams;
  sim_t *s;
  lcm_t *lcm;
  mjData *snap[RENDER_THREAD_QUEUE]; /* a ring of states at frame times */
  int64_t frame_us[RENDER_THREAD_QUEUE];
  double frame_scale[RENDER_THREAD_QUEUE]; /* the cars' cameras' render scale for each */
  int head, queued;                        /* next to render; queued (the one in hand included) */
  int stop, opened, failed;                /* opened: 1 ok, -1 failed */
  int cameras, eye, eye_render;            /* cameras_open's arguments */
  double noise, blur_px, exposure_ev;
  double scale; /* the cars' cameras' render scale: --camera-scale, then the thread's own copy
                   of the last snapshot's (frame_scale) */
  uint64_t seed;
  long rendered, skipped;
  char err[256];
} render_thread_t;

/* Starts the thread, which opens the cameras (t->cameras, t->eye, effects from t->noise,
 * t->blur_px, t->exposure_ev, t->seed) and waits for snapshots. */
int render_thread_start(render_thread_t *t, sim_t *s, lcm_t *lcm, char *err, size_t err_sz);
/* The state at frame time now_us to the render thread's queue, unless it is full, to be
 * rendered with the cars' cameras at render scale scale (the View section's Cam scale can change
 * it between frames). Returns 1 when queued, 0 when skipped (the queue was full), -1 when the
 * thread failed (err). */
int render_thread_submit(render_thread_t *t, const sim_t *s, int64_t now_us, double scale,
                         char *err, size_t err_sz);
/* Frames waiting behind the one being rendered: the stepping thread's pause this step [us]. */
long render_thread_backlog_us(render_thread_t *t);
/* Stops and joins it; prints how many frame times it rendered and skipped. */
void render_thread_stop(render_thread_t *t);

#endif
