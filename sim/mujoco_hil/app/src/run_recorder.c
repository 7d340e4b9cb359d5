/* The run's recording (run_recorder.h). */
#include "run_recorder.h"

#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <signal.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

/* lcm-logger on url into path, or -1 with the cause in err. */
static pid_t recorder_spawn_logger(const char *url, const char *path, char *err, size_t err_sz) {
  char url_opt[600];
  snprintf(url_opt, sizeof url_opt, "--lcm-url=%s", url);
  const pid_t pid = fork();
  if (pid == 0) {
    const int null = open("/dev/null", O_RDWR);
    if (null >= 0) {
      dup2(null, STDIN_FILENO);
      dup2(null, STDOUT_FILENO);
    }
    execlp("lcm-logger", "lcm-logger", "-f", "-q", url_opt, path, (char *)NULL);
    _exit(127);
  }
  if (pid < 0) snprintf(err, err_sz, "--record: cannot start lcm-logger: %s", strerror(errno));
  return pid;
}

int run_recorder_start(run_recorder_t *r, sim_t *s, const char *cam_name, const char *video_path,
                       const char *dir, const char *lcm_url, char *err, size_t err_sz) {
  memset(r, 0, sizeof *r);
  const mjModel *m = sim_render_model(s);
  r->cam_id = mj_name2id(m, mjOBJ_CAMERA, cam_name);
  if (r->cam_id < 0) {
    snprintf(err, err_sz,
             "--video-camera '%s': the model has no such camera (e.g. %s1/cam_front, eye)",
             cam_name, "nigel");
    return -1;
  }
  char csv_path[1200];
  if (dir) {
    if (mkdir(dir, 0775) != 0 && errno != EEXIST) {
      snprintf(err, err_sz, "--record '%s': cannot make the folder: %s", dir, strerror(errno));
      return -1;
    }
    snprintf(r->dir, sizeof r->dir, "%s", dir);
    snprintf(r->video_path, sizeof r->video_path, "%s/view.mp4", dir);
    snprintf(csv_path, sizeof csv_path, "%s/view_frames.csv", dir);
  } else {
    snprintf(r->video_path, sizeof r->video_path, "%s", video_path);
    snprintf(csv_path, sizeof csv_path, "%s.frames.csv", video_path);
  }
  if (!(r->frames_csv = fopen(csv_path, "w"))) {
    snprintf(err, err_sz, "%s '%s': cannot write: %s", dir ? "--record" : "--video", csv_path,
             strerror(errno));
    return -1;
  }
  fprintf(r->frames_csv, "frame,sim_time_us\n");
  r->rgb = malloc((size_t)RUN_RECORDER_WIDTH_PX * RUN_RECORDER_HEIGHT_PX * 3);
  r->render = sim_render_create(m, RUN_RECORDER_WIDTH_PX, RUN_RECORDER_HEIGHT_PX, SIM_RENDER_AUTO,
                                err, err_sz);
  if (!r->rgb || !r->render ||
      !(r->video = sim_video_open(r->video_path, RUN_RECORDER_WIDTH_PX, RUN_RECORDER_HEIGHT_PX,
                                  RUN_RECORDER_FPS, err, err_sz))) {
    run_recorder_stop(r, NULL, 0);
    return -1;
  }
  if (dir) {
    char log_path[1200];
    snprintf(log_path, sizeof log_path, "%s/run.lcmlog", dir);
    if ((r->logger = recorder_spawn_logger(lcm_url, log_path, err, err_sz)) < 0) {
      r->logger = 0;
      run_recorder_stop(r, NULL, 0);
      return -1;
    }
  }
  r->start_us = sim_time_us(s);
  r->period_us = (int64_t)llround(1e6 / RUN_RECORDER_FPS);
  return 0;
}

int run_recorder_active(const run_recorder_t *r) {
  return r->render != NULL;
}

int run_recorder_step(run_recorder_t *r, sim_t *s, char *err, size_t err_sz) {
  if (!r->render) return 0;
  const int64_t now_us = sim_time_us(s);
  if (now_us < r->start_us + r->next_frame * r->period_us) return 0;
  const mjModel *m = sim_render_model(s);
  if (sim_render_camera(r->render, m, sim_render_data(s), r->cam_id, RUN_RECORDER_WIDTH_PX,
                        RUN_RECORDER_HEIGHT_PX, r->rgb) != 0) {
    snprintf(err, err_sz, "recording: rendering camera %d failed", r->cam_id);
    return -1;
  }
  sim_video_stamp(r->rgb, RUN_RECORDER_WIDTH_PX, RUN_RECORDER_HEIGHT_PX, now_us * 1e-6, 3);
  if (sim_video_frame(r->video, r->rgb, err, err_sz) != 0) return -1;
  fprintf(r->frames_csv, "%ld,%lld\n", r->next_frame, (long long)now_us);
  r->next_frame++;
  return 0;
}

int run_recorder_stop(run_recorder_t *r, char *err, size_t err_sz) {
  char buf[512] = "";
  int rc = sim_video_close(r->video, buf, sizeof buf);
  r->video = NULL;
  if (r->frames_csv && fclose(r->frames_csv) != 0 && rc == 0) {
    snprintf(buf, sizeof buf, "recording: the frame list could not be written");
    rc = -1;
  }
  r->frames_csv = NULL;
  if (r->logger > 0) {
    kill(r->logger, SIGINT); /* our own child, by pid: lcm-logger flushes and exits */
    while (waitpid(r->logger, NULL, 0) < 0 && errno == EINTR) {
    }
  }
  r->logger = 0;
  sim_render_destroy(r->render);
  r->render = NULL;
  free(r->rgb);
  r->rgb = NULL;
  if (rc != 0 && err && err_sz) snprintf(err, err_sz, "%s", buf);
  return rc;
}
