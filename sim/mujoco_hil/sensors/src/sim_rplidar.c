/* sim_rplidar: see sim_rplidar.h for the wire format. */
#include "sim_rplidar.h"

#include "sim_lidar.h"

#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <termios.h>
#include <unistd.h>

#define RPL_SYNC 0xA5
#define RPL_SYNC2 0x5A
#define RPL_CMD_STOP 0x25
#define RPL_CMD_RESET 0x40
#define RPL_CMD_SCAN 0x20
#define RPL_CMD_FORCE_SCAN 0x21
#define RPL_CMD_GET_INFO 0x50
#define RPL_CMD_GET_HEALTH 0x52
#define RPL_CMD_GET_SAMPLERATE 0x59
#define RPL_NODE_BYTES 5
#define RPL_OUT_CAP 8192   /* bytes of responses waiting for the wire */
#define RPL_QUALITY_HIT 47 /* 6-bit quality of a return */

/* Request parser states. */
enum { RX_SYNC, RX_CMD, RX_SIZE, RX_PAYLOAD, RX_CHECKSUM };

struct sim_rplidar {
  int master_fd;
  char link_path[4096];
  char slave_path[128];
  uint32_t baud;
  /* request parser */
  int rx_state;
  uint8_t rx_cmd, rx_size, rx_len, rx_xor;
  /* response bytes (descriptors and data) go first; then nodes */
  uint8_t out[RPL_OUT_CAP];
  size_t out_len;
  uint8_t *nodes;                        /* queued measurement nodes, RPL_NODE_BYTES each */
  size_t nodes_len, nodes_cap, node_off; /* bytes queued, capacity, bytes of the head sent */
  int scanning;
  int connected;       /* a client has the slave open (reads did not return EIO) */
  int64_t wire_us;     /* wire time up to which bytes were allowed [us] */
  double credit_bytes; /* bytes the wire may still carry now */
  int clock_started;
  int64_t last_push_us; /* wire clock at the previous revolution's start, -1 before the first */
  int rev_send;         /* nodes sent in the current streamed revolution (0: not started) */
  sim_rplidar_stats_t stats;
};

static void err_set(char *err, size_t n, const char *what, const char *arg) {
  if (err && n)
    snprintf(err, n, "sim_rplidar: %s%s%s%s%s", what, arg ? " '" : "", arg ? arg : "",
             arg ? "'" : "", errno ? ": " : "");
  if (err && n && errno) {
    size_t l = strlen(err);
    if (l < n) snprintf(err + l, n - l, "%s", strerror(errno));
  }
}

sim_rplidar_t *sim_rplidar_create(const char *link_path, uint32_t baud, char *err, size_t err_len) {
  errno = 0;
  if (!link_path || !*link_path || strlen(link_path) >= sizeof(((sim_rplidar_t *)0)->link_path) ||
      baud < 1200 || baud > 4000000) {
    err_set(err, err_len, "bad symlink path or baud (1200..4000000)", link_path);
    return NULL;
  }
  struct stat st;
  if (lstat(link_path, &st) == 0) {
    if (!S_ISLNK(st.st_mode)) {
      errno = 0;
      err_set(err, err_len, "refusing to replace a file that is not a symlink", link_path);
      return NULL;
    }
    if (unlink(link_path) != 0) {
      err_set(err, err_len, "cannot remove old symlink", link_path);
      return NULL;
    }
  }
  int fd = posix_openpt(O_RDWR | O_NOCTTY | O_NONBLOCK);
  if (fd < 0 || grantpt(fd) != 0 || unlockpt(fd) != 0) {
    err_set(err, err_len, "cannot open a pseudo-terminal", NULL);
    if (fd >= 0) close(fd);
    return NULL;
  }
  sim_rplidar_t *r = calloc(1, sizeof *r);
  if (!r) {
    close(fd);
    return NULL;
  }
  r->master_fd = fd;
  r->baud = baud;
  r->last_push_us = -1;
  r->rev_send = 0;
  if (ptsname_r(fd, r->slave_path, sizeof r->slave_path) != 0) {
    err_set(err, err_len, "ptsname failed", NULL);
    close(fd);
    free(r);
    return NULL;
  }
  /* raw 8N1 at the nominal baud, so a client that does not set termios still sees raw bytes */
  int sfd = open(r->slave_path, O_RDWR | O_NOCTTY);
  if (sfd >= 0) {
    struct termios t;
    if (tcgetattr(sfd, &t) == 0) {
      cfmakeraw(&t);
      cfsetispeed(&t, B115200);
      cfsetospeed(&t, B115200);
      tcsetattr(sfd, TCSANOW, &t);
    }
    close(sfd);
  }
  snprintf(r->link_path, sizeof r->link_path, "%s", link_path);
  if (symlink(r->slave_path, r->link_path) != 0) {
    err_set(err, err_len, "cannot create symlink", link_path);
    close(fd);
    free(r);
    return NULL;
  }
  return r;
}

void sim_rplidar_destroy(sim_rplidar_t *r) {
  if (!r) return;
  unlink(r->link_path);
  close(r->master_fd);
  free(r->nodes);
  free(r);
}

const char *sim_rplidar_slave_path(const sim_rplidar_t *r) {
  return r->slave_path;
}
int sim_rplidar_scanning(const sim_rplidar_t *r) {
  return r->scanning;
}
void sim_rplidar_get_stats(const sim_rplidar_t *r, sim_rplidar_stats_t *out) {
  *out = r->stats;
}

void sim_rplidar_encode_node(uint8_t out[5], int start, uint8_t quality, double angle_deg,
                             double distance_mm) {
  angle_deg = fmod(angle_deg, 360.0);
  if (angle_deg < 0) angle_deg += 360.0;
  long a = lround(angle_deg * 64.0);
  if (a >= 360 * 64) a -= 360 * 64;
  long dq2 = (isfinite(distance_mm) && distance_mm > 0) ? lround(distance_mm * 4.0) : 0;
  if (dq2 > 0xFFFF) dq2 = 0; /* beyond what the field holds: no return */
  uint8_t s = start ? 1 : 0;
  out[0] = (uint8_t)(((quality & 0x3F) << 2) | ((!s) << 1) | s);
  out[1] = (uint8_t)(((a & 0x7F) << 1) | 1);
  out[2] = (uint8_t)((a >> 7) & 0xFF);
  out[3] = (uint8_t)(dq2 & 0xFF);
  out[4] = (uint8_t)((dq2 >> 8) & 0xFF);
}

static void out_put(sim_rplidar_t *r, const uint8_t *b, size_t n) {
  if (r->out_len + n > RPL_OUT_CAP) return; /* a client flooding requests loses answers */
  memcpy(r->out + r->out_len, b, n);
  r->out_len += n;
}

/* Response descriptor: A5 5A, 30-bit length | 2-bit send mode << 30 (LE), data type. */
static void out_descriptor(sim_rplidar_t *r, uint32_t len, uint8_t mode, uint8_t type) {
  uint32_t v = (len & 0x3FFFFFFFu) | ((uint32_t)mode << 30);
  uint8_t b[7] = {RPL_SYNC,           RPL_SYNC2,          (uint8_t)v, (uint8_t)(v >> 8),
                  (uint8_t)(v >> 16), (uint8_t)(v >> 24), type};
  out_put(r, b, sizeof b);
}

static void rpl_stop(sim_rplidar_t *r) {
  r->scanning = 0;
  r->last_push_us = -1;
  r->rev_send = 0;
  r->nodes_len = 0;
  r->node_off = 0;
}

static void rpl_request(sim_rplidar_t *r, uint8_t cmd) {
  r->stats.requests_rx++;
  switch (cmd) {
    case RPL_CMD_STOP:
    case RPL_CMD_RESET:
      rpl_stop(r);
      r->out_len = 0;
      break;
    case RPL_CMD_SCAN:
    case RPL_CMD_FORCE_SCAN:
      rpl_stop(r);
      out_descriptor(r, 5, 1, 0x81); /* multiple response mode */
      r->scanning = 1;
      break;
    case RPL_CMD_GET_INFO: {
      out_descriptor(r, 20, 0, 0x04);
      /* model 0x18 (A1M8), firmware 1.29, hardware 7, 16-byte serial "NIGEL-SIM-LIDAR\0" */
      uint8_t b[20] = {0x18, 29, 1, 7};
      memcpy(b + 4, "NIGEL-SIM-LIDAR", 16);
      out_put(r, b, sizeof b);
      break;
    }
    case RPL_CMD_GET_HEALTH: {
      out_descriptor(r, 3, 0, 0x06);
      uint8_t b[3] = {0, 0, 0}; /* status 0 = good, error code 0 */
      out_put(r, b, sizeof b);
      break;
    }
    case RPL_CMD_GET_SAMPLERATE: {
      out_descriptor(r, 4, 0, 0x15);
      uint8_t b[4] = {0xFA, 0x01, 0xFA, 0x01}; /* 506 us standard, 506 us express (~A1) */
      out_put(r, b, sizeof b);
      break;
    }
    default:
      r->stats.requests_rx--;
      r->stats.bad_requests++; /* unknown commands get no answer, like the device */
      break;
  }
}

/* Byte-wise request parser: A5 cmd, plus size payload checksum when cmd has bit 7 set. */
static void rpl_rx_byte(sim_rplidar_t *r, uint8_t b) {
  switch (r->rx_state) {
    case RX_SYNC:
      if (b == RPL_SYNC) r->rx_state = RX_CMD;
      break;
    case RX_CMD:
      r->rx_cmd = b;
      if (b & 0x80) {
        r->rx_xor = (uint8_t)(RPL_SYNC ^ b);
        r->rx_state = RX_SIZE;
      } else {
        rpl_request(r, b);
        r->rx_state = RX_SYNC;
      }
      break;
    case RX_SIZE:
      r->rx_size = b;
      r->rx_len = 0;
      r->rx_xor ^= b;
      r->rx_state = b ? RX_PAYLOAD : RX_CHECKSUM;
      break;
    case RX_PAYLOAD:
      r->rx_xor ^= b;
      if (++r->rx_len >= r->rx_size) r->rx_state = RX_CHECKSUM;
      break;
    case RX_CHECKSUM:
      /* payload commands (express scan, motor PWM, conf queries) are acknowledged silently */
      if (b == r->rx_xor)
        r->stats.requests_rx++;
      else
        r->stats.bad_requests++;
      r->rx_state = RX_SYNC;
      break;
    default: r->rx_state = RX_SYNC;
  }
}

/* Makes room for need more node bytes: drops the oldest whole nodes beyond two revolutions
 * (keep_bytes) and compacts the sent prefix. Returns 0, or -1 when memory ran out. */
static int rpl_queue_reserve(sim_rplidar_t *r, size_t need, size_t keep_bytes) {
  size_t queued = r->nodes_len - r->node_off;
  if (queued + need > keep_bytes) {
    size_t drop = queued + need - keep_bytes;
    drop -= drop % RPL_NODE_BYTES;
    /* never cut the node that is half on the wire: drop from after it */
    size_t keep_head =
        (r->node_off % RPL_NODE_BYTES) ? RPL_NODE_BYTES - r->node_off % RPL_NODE_BYTES : 0;
    size_t from = r->node_off + keep_head;
    if (drop > r->nodes_len - from) drop = r->nodes_len - from;
    memmove(r->nodes + from, r->nodes + from + drop, r->nodes_len - from - drop);
    r->nodes_len -= drop;
    r->stats.nodes_dropped += drop / RPL_NODE_BYTES;
  }
  if (r->node_off > 0) {
    memmove(r->nodes, r->nodes + r->node_off, r->nodes_len - r->node_off);
    r->nodes_len -= r->node_off;
    r->node_off = 0;
  }
  if (r->nodes_len + need > r->nodes_cap) {
    size_t cap = (r->nodes_len + need) * 2;
    uint8_t *p = realloc(r->nodes, cap);
    if (!p) return -1;
    r->nodes = p;
    r->nodes_cap = cap;
  }
  return 0;
}

/* A real A1 samples at a fixed rate: a faster spin gives fewer nodes per revolution. Nodes
 * the wire carries in one revolution (the wire time since the previous revolution's start,
 * 3 % margin), at most num_rays. Called at each revolution's start. */
static int rpl_nodes_per_rev(sim_rplidar_t *r, int num_rays) {
  int send = num_rays;
  if (r->last_push_us >= 0 && r->wire_us > r->last_push_us) {
    double per_rev =
        (double)(r->wire_us - r->last_push_us) * 1e-6 * r->baud / 10.0 / RPL_NODE_BYTES * 0.97;
    if (per_rev < send) send = per_rev < 1 ? 1 : (int)per_rev;
  }
  r->last_push_us = r->wire_us;
  return send;
}

static void rpl_queue_node(sim_rplidar_t *r, const float *ranges_m, const float *quality, int i,
                           int num_rays, int start) {
  double ccw_deg = 360.0 * i / num_rays;
  double r_m = ranges_m[i];
  int hit = isfinite(r_m) && r_m > 0;
  uint8_t q = hit ? (quality ? (uint8_t)quality[i] : RPL_QUALITY_HIT) : 0;
  sim_rplidar_encode_node(r->nodes + r->nodes_len, start, q, 360.0 - ccw_deg,
                          hit ? r_m * 1000.0 : 0.0);
  r->nodes_len += RPL_NODE_BYTES;
}

void sim_rplidar_push_scan(sim_rplidar_t *r, const float *ranges_m, const float *quality,
                           int num_rays) {
  if (!r->scanning || num_rays <= 0 || !ranges_m) return;
  size_t need = (size_t)num_rays * RPL_NODE_BYTES;
  if (rpl_queue_reserve(r, need, 2 * need) != 0) {
    r->stats.nodes_dropped += (uint64_t)num_rays;
    return;
  }
  /* Send what the wire carries in one revolution, spread evenly over the circle, instead of
   * a backlog that must later be cut. */
  int send = rpl_nodes_per_rev(r, num_rays);
  for (int k = 0; k < send; k++) {
    const int step = (int)((int64_t)k * num_rays / send);
    rpl_queue_node(r, ranges_m, quality, sim_lidar_sweep_ray(step, num_rays), num_rays, k == 0);
  }
}

void sim_rplidar_push_rays(sim_rplidar_t *r, const float *ranges_m, const float *quality, int from,
                           int to, int num_rays) {
  if (!r->scanning || num_rays <= 0 || !ranges_m || from >= to) return;
  if (from == 0 || r->rev_send <= 0) r->rev_send = rpl_nodes_per_rev(r, num_rays);
  const int64_t send = r->rev_send;
  size_t need = (size_t)(to - from) * RPL_NODE_BYTES;
  if (rpl_queue_reserve(r, need, 2 * (size_t)num_rays * RPL_NODE_BYTES) != 0) {
    r->stats.nodes_dropped += (uint64_t)(to - from);
    return;
  }
  for (int step = from; step < to; step++) {
    /* sweep step `step` is sent when it is one of floor(k * num_rays / send), k = 0..send-1:
     * the same evenly spread subset as a whole-revolution push */
    int64_t k = ((int64_t)step * send + num_rays - 1) / num_rays;
    if (k < send && k * num_rays / send == step)
      rpl_queue_node(r, ranges_m, quality, sim_lidar_sweep_ray(step, num_rays), num_rays,
                     step == 0);
  }
}

/* Writes up to max bytes from buf; returns bytes written, or -1 on a hang-up. */
static long rpl_write(sim_rplidar_t *r, const uint8_t *buf, size_t max) {
  if (max == 0) return 0;
  ssize_t w = write(r->master_fd, buf, max);
  if (w < 0) return (errno == EAGAIN || errno == EINTR) ? 0 : -1;
  r->stats.bytes_tx += (uint64_t)w;
  return (long)w;
}

int sim_rplidar_poll(sim_rplidar_t *r, int64_t now_us, char *err, size_t err_len) {
  uint8_t buf[256];
  for (;;) {
    ssize_t n = read(r->master_fd, buf, sizeof buf);
    if (n > 0) {
      r->connected = 1;
      for (ssize_t i = 0; i < n; i++) rpl_rx_byte(r, buf[i]);
      continue;
    }
    if (n < 0 && errno == EIO) {
      /* no client has the slave open: the device idles, as if unplugged and replugged */
      if (r->connected) {
        rpl_stop(r);
        r->out_len = 0;
        r->rx_state = RX_SYNC;
      }
      r->connected = 0;
      break;
    }
    if (n < 0 && errno != EAGAIN && errno != EINTR) {
      err_set(err, err_len, "read from pty failed", r->slave_path);
      return -1;
    }
    break;
  }
  /* wire pacing: 10 bits per byte (8N1); credit is capped at 20 ms of wire (>= 64 bytes) so an
   * idle wire does not burst, while a caller polling every 1..20 ms still reaches full rate */
  if (!r->clock_started || now_us < r->wire_us) {
    r->clock_started = 1;
    r->wire_us = now_us;
  }
  r->credit_bytes += (double)(now_us - r->wire_us) * r->baud / 10.0 / 1e6;
  r->wire_us = now_us;
  double cap = r->baud / 10.0 * 0.020;
  if (cap < 64) cap = 64;
  if (r->credit_bytes > cap) r->credit_bytes = cap;
  size_t allow = (size_t)r->credit_bytes;
  size_t sent = 0;
  if (allow && r->out_len) {
    long w = rpl_write(r, r->out, r->out_len < allow ? r->out_len : allow);
    if (w > 0) {
      memmove(r->out, r->out + w, r->out_len - (size_t)w);
      r->out_len -= (size_t)w;
      sent += (size_t)w;
    }
  }
  if (sent < allow && r->out_len == 0 && r->nodes_len > r->node_off) {
    size_t avail = r->nodes_len - r->node_off;
    size_t want = allow - sent;
    long w = rpl_write(r, r->nodes + r->node_off, avail < want ? avail : want);
    if (w > 0) {
      size_t before = r->node_off / RPL_NODE_BYTES;
      r->node_off += (size_t)w;
      sent += (size_t)w;
      r->stats.nodes_tx += r->node_off / RPL_NODE_BYTES - before;
      if (r->node_off == r->nodes_len) r->nodes_len = r->node_off = 0;
    }
  }
  r->credit_bytes -= (double)sent;
  return 0;
}
