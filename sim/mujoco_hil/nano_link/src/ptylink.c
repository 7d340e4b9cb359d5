/* Pseudo-terminal with a symlink (see ptylink.h). */
#define _XOPEN_SOURCE 700 /* posix_openpt, grantpt, ptsname */
#include "ptylink.h"

#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/ioctl.h>
#include <sys/stat.h>
#include <termios.h>
#include <unistd.h>

int ptylink_open(ptylink_t *p, const char *link_path, char *err, size_t err_sz) {
  memset(p, 0, sizeof *p);
  p->master_fd = p->slave_fd = -1;
  p->master_fd = posix_openpt(O_RDWR | O_NOCTTY | O_NONBLOCK);
  if (p->master_fd < 0 || grantpt(p->master_fd) != 0 || unlockpt(p->master_fd) != 0) {
    snprintf(err, err_sz, "pty for '%s': posix_openpt failed: %s", link_path, strerror(errno));
    ptylink_close(p);
    return -1;
  }
  const char *name = ptsname(p->master_fd);
  if (!name || strlen(name) >= sizeof p->slave_path) {
    snprintf(err, err_sz, "pty for '%s': ptsname failed", link_path);
    ptylink_close(p);
    return -1;
  }
  strcpy(p->slave_path, name);
  p->slave_fd = open(p->slave_path, O_RDWR | O_NOCTTY | O_NONBLOCK);
  if (p->slave_fd < 0) {
    snprintf(err, err_sz, "pty slave '%s': %s", p->slave_path, strerror(errno));
    ptylink_close(p);
    return -1;
  }
  /* raw 8N1 like a serial port: no echo, no line editing, no CR/LF mangling */
  struct termios t;
  if (tcgetattr(p->slave_fd, &t) == 0) {
    cfmakeraw(&t);
    tcsetattr(p->slave_fd, TCSANOW, &t);
  }
  struct stat st;
  if (lstat(link_path, &st) == 0) {
    if (!S_ISLNK(st.st_mode)) {
      snprintf(err, err_sz, "'%s' exists and is not a symlink: refusing to replace it", link_path);
      ptylink_close(p);
      return -1;
    }
    unlink(link_path);
  }
  if (symlink(p->slave_path, link_path) != 0) {
    snprintf(err, err_sz, "symlink '%s' -> '%s': %s", link_path, p->slave_path, strerror(errno));
    ptylink_close(p);
    return -1;
  }
  snprintf(p->link_path, sizeof p->link_path, "%s", link_path);
  return 0;
}

size_t ptylink_read(ptylink_t *p, unsigned char *buf, size_t cap) {
  if (p->master_fd < 0 || cap == 0) return 0;
  ssize_t n = read(p->master_fd, buf, cap);
  return n > 0 ? (size_t)n : 0; /* EAGAIN: nothing yet; EIO: no client, same thing here */
}

size_t ptylink_write(ptylink_t *p, const unsigned char *buf, size_t n) {
  if (p->master_fd < 0 || n == 0) return 0;
  ssize_t w = write(p->master_fd, buf, n);
  return w > 0 ? (size_t)w : 0;
}

size_t ptylink_unread(const ptylink_t *p) {
  int n = 0;
  if (p->slave_fd < 0 || ioctl(p->slave_fd, FIONREAD, &n) != 0 || n < 0) return 0;
  return (size_t)n;
}

void ptylink_close(ptylink_t *p) {
  if (p->link_path[0]) {
    /* remove the link only if it still points at our slave (another sim may own it now) */
    char target[64];
    ssize_t n = readlink(p->link_path, target, sizeof target - 1);
    if (n > 0) {
      target[n] = '\0';
      if (strcmp(target, p->slave_path) == 0) unlink(p->link_path);
    }
    p->link_path[0] = '\0';
  }
  if (p->slave_fd >= 0) close(p->slave_fd);
  if (p->master_fd >= 0) close(p->master_fd);
  p->slave_fd = p->master_fd = -1;
}
