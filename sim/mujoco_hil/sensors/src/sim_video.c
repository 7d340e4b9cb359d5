/* sim_video: see sim_video.h. */
#include "sim_video.h"

#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

struct sim_video {
  pid_t pid;
  int fd; /* our end of the socket pair: ffmpeg's stdin */
  int w, h;
  long frames;
  char path[512];
};

/* A socket pair rather than a pipe: send(MSG_NOSIGNAL) to an ffmpeg that died is an error
 * return, not a SIGPIPE that would end the simulator. */
sim_video_t *sim_video_open(const char *path, int width_px, int height_px, double fps, char *err,
                            size_t err_sz) {
  if (!path || !*path || width_px < 16 || height_px < 16 || (width_px | height_px) & 1 ||
      !(fps > 0.0 && fps <= 240.0)) {
    snprintf(err, err_sz,
             "video '%s': bad size %dx%d px or rate %.3g fps (need even sizes >= 16 px, 0 < fps "
             "<= 240)",
             path ? path : "", width_px, height_px, fps);
    return NULL;
  }
  const char *ffmpeg = getenv("AUTODRIVE_FFMPEG");
  if (!ffmpeg || !*ffmpeg) ffmpeg = "ffmpeg";
  int sv[2];
  if (socketpair(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0, sv) != 0) {
    snprintf(err, err_sz, "video '%s': socketpair: %s", path, strerror(errno));
    return NULL;
  }
  int ready[2]; /* closed on exec; a byte on it carries exec's errno */
  if (pipe2(ready, O_CLOEXEC) != 0) {
    snprintf(err, err_sz, "video '%s': pipe: %s", path, strerror(errno));
    close(sv[0]);
    close(sv[1]);
    return NULL;
  }
  char size[32], rate[32];
  snprintf(size, sizeof size, "%dx%d", width_px, height_px);
  snprintf(rate, sizeof rate, "%.6g", fps);
  /* ffmpeg's environment: ours without LD_PRELOAD (a sanitizer runtime a test preloaded is not
   * for a foreign program), built before fork: the child only dups and execs */
  extern char **environ;
  size_t nenv = 0;
  while (environ[nenv]) nenv++;
  char **envp = calloc(nenv + 1, sizeof *envp);
  if (!envp) {
    snprintf(err, err_sz, "video '%s': out of memory", path);
    close(sv[0]);
    close(sv[1]);
    close(ready[0]);
    close(ready[1]);
    return NULL;
  }
  for (size_t i = 0, k = 0; i < nenv; i++)
    if (strncmp(environ[i], "LD_PRELOAD=", 11) != 0) envp[k++] = environ[i];
  const pid_t pid = fork();
  if (pid == 0) {
    dup2(sv[1], STDIN_FILENO);
    const int null = open("/dev/null", O_WRONLY);
    if (null >= 0) dup2(null, STDOUT_FILENO);
    char *const argv[] = {(char *)ffmpeg, "-nostdin",   "-loglevel",  "error",      "-y",
                          "-f",           "rawvideo",   "-pix_fmt",   "rgb24",      "-video_size",
                          size,           "-framerate", rate,         "-i",         "pipe:0",
                          "-c:v",         "libx264",    "-preset",    "veryfast",   "-pix_fmt",
                          "yuv420p",      "-movflags",  "+faststart", (char *)path, NULL};
    execvpe(ffmpeg, argv, envp);
    const int e = errno;
    if (write(ready[1], &e, sizeof e) < 0) _exit(127);
    _exit(127);
  }
  free(envp);
  close(sv[1]);
  close(ready[1]);
  int exec_errno = 0;
  const ssize_t got = pid > 0 ? read(ready[0], &exec_errno, sizeof exec_errno) : -1;
  close(ready[0]);
  if (pid < 0 || got != 0) {
    snprintf(err, err_sz, "video '%s': cannot run '%s': %s (install Debian's ffmpeg)", path, ffmpeg,
             pid < 0 ? strerror(errno) : strerror(exec_errno));
    close(sv[0]);
    if (pid > 0) waitpid(pid, NULL, 0);
    return NULL;
  }
  sim_video_t *v = calloc(1, sizeof *v);
  if (!v) {
    close(sv[0]);
    kill(pid, SIGTERM);
    waitpid(pid, NULL, 0);
    snprintf(err, err_sz, "video '%s': out of memory", path);
    return NULL;
  }
  v->pid = pid;
  v->fd = sv[0];
  v->w = width_px;
  v->h = height_px;
  snprintf(v->path, sizeof v->path, "%s", path);
  return v;
}

int sim_video_frame(sim_video_t *v, const uint8_t *rgb, char *err, size_t err_sz) {
  size_t left = (size_t)v->w * (size_t)v->h * 3;
  while (left > 0) {
    const ssize_t n = send(v->fd, rgb, left, MSG_NOSIGNAL);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      snprintf(err, err_sz, "video '%s': ffmpeg stopped reading at frame %ld: %s", v->path,
               v->frames, strerror(errno));
      return -1;
    }
    rgb += n;
    left -= (size_t)n;
  }
  v->frames++;
  return 0;
}

long sim_video_frames(const sim_video_t *v) {
  return v->frames;
}

int sim_video_close(sim_video_t *v, char *err, size_t err_sz) {
  if (!v) return 0;
  close(v->fd); /* end of input: ffmpeg writes the index and exits */
  int status = 0;
  pid_t r;
  while ((r = waitpid(v->pid, &status, 0)) < 0 && errno == EINTR) {
  }
  int rc = 0;
  if (r < 0 || !WIFEXITED(status) || WEXITSTATUS(status) != 0) {
    snprintf(err, err_sz, "video '%s': ffmpeg failed (status %d) after %ld frame(s)", v->path,
             r < 0 ? -1 : status, v->frames);
    rc = -1;
  }
  free(v);
  return rc;
}

/* 3x5 glyphs, one row per 3 bits (MSB left): 0-9, '.', 'S', ' ', '-'. */
static const uint8_t glyph_rows[14][5] = {
    {7, 5, 5, 5, 7}, {2, 6, 2, 2, 7}, {7, 1, 7, 4, 7}, {7, 1, 7, 1, 7}, {5, 5, 7, 1, 1},
    {7, 4, 7, 1, 7}, {7, 4, 7, 5, 7}, {7, 1, 1, 1, 1}, {7, 5, 7, 5, 7}, {7, 5, 7, 1, 7},
    {0, 0, 0, 0, 2}, {3, 4, 2, 1, 6}, {0, 0, 0, 0, 0}, {0, 0, 7, 0, 0},
};

static int glyph_index(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c == '.') return 10;
  if (c == 's' || c == 'S') return 11;
  if (c == '-') return 13;
  return 12;
}

void sim_video_stamp(uint8_t *rgb, int width_px, int height_px, double t_s, int scale_px) {
  char text[32];
  snprintf(text, sizeof text, "%.3f s", isfinite(t_s) ? t_s : 0.0);
  if (scale_px < 1) scale_px = 1;
  const int n = (int)strlen(text), cell = 4 * scale_px, pad = scale_px;
  const int box_w = n * cell + pad, box_h = 5 * scale_px + 2 * pad;
  for (int y = 0; y < box_h && y < height_px; y++)
    for (int x = 0; x < box_w && x < width_px; x++) {
      int on = 0;
      const int gx = x - pad, gy = y - pad;
      if (gx >= 0 && gy >= 0 && gy < 5 * scale_px && gx % cell < 3 * scale_px) {
        const int k = gx / cell;
        if (k < n)
          on = glyph_rows[glyph_index(text[k])][gy / scale_px] >> (2 - (gx % cell) / scale_px) & 1;
      }
      memset(rgb + 3 * ((size_t)y * (size_t)width_px + (size_t)x), on ? 255 : 0, 3);
    }
}
