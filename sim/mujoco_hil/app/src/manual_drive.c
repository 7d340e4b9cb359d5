/* Manual driving from the window (manual_drive.h). */
#define _GNU_SOURCE /* pipe2 */
#include "manual_drive.h"

#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <signal.h>
#include <spawn.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include <autodrive_channels.h>

#include "sim_viewer.h"

#define MANUAL_DRIVE_STOP_WAIT_S 3.0 /* [s] wall for teleop's last command before SIGTERM */

extern char **environ;

/* The pad's name in the HUD: the last part of its path (js0), which keeps the HUD narrow. */
static const char *manual_drive_pad(const manual_drive_t *m) {
  const char *slash = m->gamepad ? strrchr(m->gamepad, '/') : NULL;
  return slash ? slash + 1 : m->gamepad ? m->gamepad : "";
}

/* The HUD's line while no one drives by hand. */
static void manual_drive_idle(manual_drive_t *m) {
  if (m->gamepad)
    snprintf(m->status, sizeof m->status, "autonomous (gamepad %.60s for manual)",
             manual_drive_pad(m));
  else
    snprintf(m->status, sizeof m->status, "autonomous");
}

void manual_drive_init(manual_drive_t *m, const char *gamepad) {
  memset(m, 0, sizeof *m);
  m->fd = m->out = -1;
  m->gamepad = gamepad;
  manual_drive_idle(m);
}

static void manual_drive_close_pipes(manual_drive_t *m) {
  if (m->fd >= 0) close(m->fd);
  if (m->out >= 0) close(m->out);
  m->fd = m->out = -1;
}

/* autodrive-teleop beside this program (build/<preset>/bin, where every program lands). */
static int manual_drive_teleop_path(char *out, size_t n) {
  char self[PATH_MAX];
  const ssize_t k = readlink("/proc/self/exe", self, sizeof self - 1);
  if (k <= 0) return -1;
  self[k] = 0;
  char *slash = strrchr(self, '/');
  if (!slash) return -1;
  *slash = 0;
  return snprintf(out, n, "%s/autodrive-teleop", self) < (int)n ? 0 : -1;
}

static int manual_drive_fail(manual_drive_t *m, const char *why) {
  snprintf(m->status, sizeof m->status, "manual off: %.140s", why);
  fprintf(stderr, "autodrive-sim: manual driving: %s\n", why);
  m->failed = 1;
  return -1;
}

static int manual_drive_start(manual_drive_t *m, int car, const char *url) {
  char path[PATH_MAX + 32], veh[32], hold[16], why[PATH_MAX + 96];
  if (manual_drive_teleop_path(path, sizeof path) != 0 || access(path, X_OK) != 0) {
    snprintf(why, sizeof why, "no autodrive-teleop at %s (tools/build --target autodrive-teleop)",
             path);
    return manual_drive_fail(m, why);
  }
  snprintf(veh, sizeof veh, AUTODRIVE_VEHICLE_PREFIX "%d", car);
  snprintf(hold, sizeof hold, "%d", MANUAL_DRIVE_HOLD_MS);
  int p[2], q[2]; /* its stdin (the keys), its stdout (what it reports) */
  if (pipe2(p, O_CLOEXEC) != 0) return manual_drive_fail(m, "cannot make a pipe");
  if (pipe2(q, O_CLOEXEC) != 0) {
    close(p[0]);
    close(p[1]);
    return manual_drive_fail(m, "cannot make a pipe");
  }
  posix_spawn_file_actions_t fa;
  posix_spawn_file_actions_init(&fa);
  posix_spawn_file_actions_adddup2(&fa, p[0], STDIN_FILENO);
  posix_spawn_file_actions_adddup2(&fa, q[1], STDOUT_FILENO);
  /* a fresh press counts as held for this delay + 150 ms before its first repeat */
  char *argv[] = {path,
                  "--keys-stdin",
                  "--vehicle",
                  veh,
                  "--lcm-url",
                  (char *)url,
                  "--key-hold-ms",
                  hold,
                  "--key-repeat-delay-ms",
                  hold,
                  m->gamepad ? "--joystick" : NULL,
                  (char *)m->gamepad,
                  NULL};
  const int rc = posix_spawn(&m->pid, path, &fa, NULL, argv, environ);
  posix_spawn_file_actions_destroy(&fa);
  close(p[0]);
  close(q[1]);
  m->fd = p[1];
  m->out = q[0];
  if (rc != 0) {
    manual_drive_close_pipes(m);
    m->pid = 0;
    snprintf(why, sizeof why, "cannot start %s: %s", path, strerror(rc));
    return manual_drive_fail(m, why);
  }
  fcntl(m->fd, F_SETFL, O_NONBLOCK); /* a full pipe drops a repeat, never stalls the sim */
  fcntl(m->out, F_SETFL, O_NONBLOCK);
  m->car = car;
  m->keys = 0;
  m->next_write_s = 0;
  m->gamepad_lost = 0;
  m->line_n = 0;
  if (m->gamepad)
    snprintf(m->status, sizeof m->status, "manual: keys + gamepad %.60s -> autodrive-teleop",
             manual_drive_pad(m));
  else
    snprintf(m->status, sizeof m->status, "manual: keys -> autodrive-teleop");
  printf("manual driving: %s by keys%s%s through autodrive-teleop (pid %d)\n", veh,
         m->gamepad ? " and gamepad " : "", m->gamepad ? m->gamepad : "", (int)m->pid);
  fflush(stdout);
  return 1;
}

/* The bytes a terminal would send for the held keys (autodrive-teleop's w/s/a/d); a release
 * first sends ' ' (teleop's stop), then the keys still held. */
static void manual_drive_write(manual_drive_t *m, int keys) {
  char b[8];
  int n = 0;
  if (m->keys & ~keys) b[n++] = ' ';
  if (keys & SIM_VIEWER_KEY_FORWARD) b[n++] = 'w';
  if (keys & SIM_VIEWER_KEY_BACK) b[n++] = 's';
  if (keys & SIM_VIEWER_KEY_LEFT) b[n++] = 'a';
  if (keys & SIM_VIEWER_KEY_RIGHT) b[n++] = 'd';
  if (n > 0 && write(m->fd, b, (size_t)n) < 0 && errno != EAGAIN) {
    /* teleop is gone: the next update reaps it */
  }
  m->keys = keys;
}

/* teleop's stdout, line by line: "gamepad lost" when the pad went away. */
static void manual_drive_read(manual_drive_t *m) {
  char b[256];
  ssize_t k;
  while (m->out >= 0 && (k = read(m->out, b, sizeof b)) > 0)
    for (ssize_t i = 0; i < k; i++) {
      if (b[i] != '\n') {
        if (m->line_n < (int)sizeof m->line - 1) m->line[m->line_n++] = b[i];
        continue;
      }
      m->line[m->line_n] = 0;
      m->line_n = 0;
      if (strcmp(m->line, "gamepad lost") != 0 || m->gamepad_lost) continue;
      m->gamepad_lost = 1;
      snprintf(m->status, sizeof m->status, "manual: keys; gamepad %.60s lost, car stopped",
               manual_drive_pad(m));
      printf("manual driving: gamepad %s lost; autodrive-teleop stopped the car\n",
             m->gamepad ? m->gamepad : "");
      fflush(stdout);
    }
}

void manual_drive_stop(manual_drive_t *m) {
  if (m->fd >= 0) close(m->fd); /* end of input: teleop stops the car and quits */
  m->fd = -1;
  if (m->pid > 0) {
    int st = 0;
    const struct timespec tick = {0, 10000000L};
    for (int i = 0; i < (int)(MANUAL_DRIVE_STOP_WAIT_S / 0.01); i++) {
      if (waitpid(m->pid, &st, WNOHANG) == m->pid) {
        m->pid = 0;
        break;
      }
      nanosleep(&tick, NULL);
    }
    if (m->pid > 0) {
      kill(m->pid, SIGTERM);
      waitpid(m->pid, &st, 0);
      m->pid = 0;
    }
    printf("manual driving off: " AUTODRIVE_VEHICLE_PREFIX "%d back to its autonomy\n", m->car);
    fflush(stdout);
  }
  manual_drive_close_pipes(m); /* after teleop quit: its last line never meets a closed pipe */
  manual_drive_idle(m);
}

int manual_drive_update(manual_drive_t *m, int manual, int car, int keys, const char *url,
                        double now_s) {
  if (m->pid > 0) { /* teleop exited on its own (no key, LCM refused ...) */
    int st = 0;
    manual_drive_read(m);
    if (waitpid(m->pid, &st, WNOHANG) == m->pid) {
      m->pid = 0;
      manual_drive_close_pipes(m);
      char why[96];
      snprintf(why, sizeof why, "autodrive-teleop exited with status %d (its message above)",
               WIFEXITED(st) ? WEXITSTATUS(st) : 128 + WTERMSIG(st));
      return manual_drive_fail(m, why);
    }
  }
  if (!manual) {
    m->failed = 0;
    if (m->pid > 0) manual_drive_stop(m);
    return 0;
  }
  if (m->failed) return -1;
  if (m->pid > 0 && m->car != car) manual_drive_stop(m); /* another ego car: its own teleop */
  if (m->pid == 0 && manual_drive_start(m, car, url) < 0) return -1;
  if (keys != m->keys || (keys && now_s >= m->next_write_s)) {
    manual_drive_write(m, keys);
    m->next_write_s = now_s + MANUAL_DRIVE_REPEAT_S;
  }
  return 1;
}
