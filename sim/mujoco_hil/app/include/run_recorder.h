/* The run's recording (--video FILE, --record DIR, the window's Record button): an MP4 of one
 * camera rendered headless (its own EGL/OSMesa renderer) once per 1/fps of sim time, each
 * frame stamped with its sim time and listed in a CSV beside it (frame, sim_time_us), and, for
 * --record, the LCM log of every channel (lcm-logger, a child process) in the same folder:
 *   DIR/run.lcmlog   every channel; ground truth and SIM_CLOCK carry sim time
 *   DIR/view.mp4     the camera, frame k at sim time frames.csv[k]
 *   DIR/view_frames.csv
 * Video and log meet on sim time: a frame's sim_time_us is the utime of the ground truth
 * published at that step. */
#ifndef SIM_APP_RUN_RECORDER_H
#define SIM_APP_RUN_RECORDER_H

#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <sys/types.h>

#include "sim.h"
#include "sim_render.h"
#include "sim_video.h"

#define RUN_RECORDER_FPS 30.0 /* frames per second of sim time */
#define RUN_RECORDER_WIDTH_PX 640
#define RUN_RECORDER_HEIGHT_PX 480

typedef struct run_recorder {
  sim_render_t *render; /* NULL: not recording */
  sim_video_t *video;
  FILE *frames_csv;
  pid_t logger; /* lcm-logger, or 0 */
  int cam_id;
  uint8_t *rgb;
  int64_t start_us, period_us;
  long next_frame; /* frame index due next: at start_us + next_frame * period_us */
  char dir[1024], video_path[1100];
} run_recorder_t;

/* Starts recording camera cam_name (e.g. "nigel1/cam_front", "eye") of s from now:
 * video_path alone (--video; its CSV is video_path + ".frames.csv"), or dir (--record: made
 * if missing; lcm-logger on lcm_url writes DIR/run.lcmlog). Returns 0, or -1 with a message
 * naming the option's input and the cause in err. */
int run_recorder_start(run_recorder_t *r, sim_t *s, const char *cam_name, const char *video_path,
                       const char *dir, const char *lcm_url, char *err, size_t err_sz);
/* At every step: renders, stamps and writes a frame when one is due at sim time now_us.
 * Returns 0, or -1 (message in err). Nothing when not recording. */
int run_recorder_step(run_recorder_t *r, sim_t *s, char *err, size_t err_sz);
int run_recorder_active(const run_recorder_t *r);
/* Stops: closes the video (waiting for ffmpeg) and the CSV, ends lcm-logger (SIGINT, by its
 * pid). Returns 0, or -1 (message in err). Fine when not recording. */
int run_recorder_stop(run_recorder_t *r, char *err, size_t err_sz);

#endif
