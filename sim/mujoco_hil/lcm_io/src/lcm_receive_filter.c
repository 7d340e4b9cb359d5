/* Kernel-side channel filter for LCM's receive socket (see lcm_receive_filter.h). */
#include "lcm_receive_filter.h"

#include <dirent.h>
#include <linux/filter.h>
#include <netinet/in.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>

#define RECEIVE_FILTER_DEFAULT_PORT 7667       /* LCM's default udpm port */
#define RECEIVE_FILTER_MAGIC_SHORT 0x4C433032u /* "LC02": a message in one datagram */
/* Offsets in the datagram as a UDP socket filter sees it (from the UDP header, 8 bytes): the
 * LCM magic, then its sequence number, then the NUL-terminated channel name. */
#define RECEIVE_FILTER_OFF_MAGIC 8u
#define RECEIVE_FILTER_OFF_CHANNEL 16u
#define RECEIVE_FILTER_MAX_CHANNEL 63
#define RECEIVE_FILTER_MAX_CHANNELS 2 /* a jump over every test stays under 256 */

/* The port of a udpm:// URL ("udpm://239.255.76.67:7667?ttl=0"); 0 for other providers. */
static int receive_filter_port(const char *url) {
  if (!url || strncmp(url, "udpm://", 7) != 0) return 0;
  const char *host = url + 7, *end = host + strcspn(host, "?");
  const char *colon = memchr(host, ':', (size_t)(end - host));
  if (!colon) return RECEIVE_FILTER_DEFAULT_PORT;
  const long p = strtol(colon + 1, NULL, 10);
  return p > 0 && p < 65536 ? (int)p : 0;
}

/* The process's UDP socket bound to port (LCM's receive socket: its send socket is unbound). */
static int receive_filter_find_socket(int port) {
  DIR *dir = opendir("/proc/self/fd");
  if (!dir) return -1;
  int found = -1;
  struct dirent *e;
  while (found < 0 && (e = readdir(dir)) != NULL) {
    const int fd = atoi(e->d_name);
    if (e->d_name[0] == '.' || fd == dirfd(dir)) continue;
    int type = 0;
    socklen_t tl = sizeof type;
    struct sockaddr_in a;
    socklen_t al = sizeof a;
    if (getsockopt(fd, SOL_SOCKET, SO_TYPE, &type, &tl) != 0 || type != SOCK_DGRAM) continue;
    if (getsockname(fd, (struct sockaddr *)&a, &al) != 0 || a.sin_family != AF_INET) continue;
    if (ntohs(a.sin_port) == port) found = fd;
  }
  closedir(dir);
  return found;
}

/* Appends to prog at *k the test of one channel (with its NUL) at the datagram's channel
 * offset: its bytes 4 at a time, the rest 1 at a time, any mismatch jumping to instruction
 * miss; all matching, keep the datagram whole. */
static void receive_filter_channel(struct sock_filter *prog, unsigned *k, const char *channel,
                                   size_t n, unsigned miss) {
  const unsigned bytes = (unsigned)(n % 4);
  for (unsigned i = 0; i < n; i += (i + 4 <= n - bytes) ? 4 : 1) {
    const int word = i + 4 <= n - bytes;
    uint32_t v = 0;
    for (unsigned b = 0; b < (word ? 4u : 1u); b++) v = (v << 8) | (uint8_t)channel[i + b];
    prog[*k] = (struct sock_filter)BPF_STMT(BPF_LD | (word ? BPF_W : BPF_B) | BPF_ABS,
                                            RECEIVE_FILTER_OFF_CHANNEL + i);
    (*k)++;
    prog[*k] =
        (struct sock_filter)BPF_JUMP(BPF_JMP | BPF_JEQ | BPF_K, v, 0, (uint8_t)(miss - *k - 1));
    (*k)++;
  }
  prog[(*k)++] = (struct sock_filter)BPF_STMT(BPF_RET | BPF_K, 0xFFFFFFFFu); /* keep it whole */
}

/* The instructions of one channel's test (receive_filter_channel). */
static unsigned receive_filter_channel_len(size_t n) {
  return 2 * (unsigned)(n / 4 + n % 4) + 1;
}

int lcm_receive_filter_keep(lcm_t *lcm, const char *url, const char *const *channels, int count,
                            char *err, size_t err_sz) {
  const int port = receive_filter_port(url);
  if (port == 0) return 0;
  if (count < 1 || count > RECEIVE_FILTER_MAX_CHANNELS) {
    snprintf(err, err_sz, "LCM filter: %d channels, want 1..%d", count,
             RECEIVE_FILTER_MAX_CHANNELS);
    return -1;
  }
  unsigned total = 2 + 1; /* the magic's load and test, ..., the drop */
  for (int c = 0; c < count; c++) {
    const size_t n = strlen(channels[c]) + 1; /* with its NUL */
    if (n - 1 > RECEIVE_FILTER_MAX_CHANNEL) {
      snprintf(err, err_sz, "LCM filter: channel '%s' longer than %d", channels[c],
               RECEIVE_FILTER_MAX_CHANNEL);
      return -1;
    }
    total += receive_filter_channel_len(n);
  }
  if (total > 256) { /* the magic test's jump to the drop must fit its 8 bits */
    snprintf(err, err_sz, "LCM filter: the channels' names are too long for one filter");
    return -1;
  }
  (void)lcm_get_fileno(lcm); /* the receive socket exists once this returns */
  const int fd = receive_filter_find_socket(port);
  if (fd < 0) {
    snprintf(err, err_sz, "LCM filter: no receive socket on port %d (%s)", port, url);
    return -1;
  }
  /* magic, then each channel in turn (a mismatch tries the next one); none matching drops */
  struct sock_filter
      prog[3 + RECEIVE_FILTER_MAX_CHANNELS * (2 * (RECEIVE_FILTER_MAX_CHANNEL + 1) + 1)];
  const unsigned drop = total - 1;
  unsigned k = 0;
  prog[k] = (struct sock_filter)BPF_STMT(BPF_LD | BPF_W | BPF_ABS, RECEIVE_FILTER_OFF_MAGIC);
  k++;
  prog[k] = (struct sock_filter)BPF_JUMP(BPF_JMP | BPF_JEQ | BPF_K, RECEIVE_FILTER_MAGIC_SHORT, 0,
                                         (uint8_t)(drop - k - 1));
  k++;
  for (int c = 0; c < count; c++) {
    const size_t n = strlen(channels[c]) + 1;
    receive_filter_channel(prog, &k, channels[c], n, k + receive_filter_channel_len(n));
  }
  prog[k++] = (struct sock_filter)BPF_STMT(BPF_RET | BPF_K, 0); /* drop */
  if (k != total) {
    snprintf(err, err_sz, "LCM filter: program of %u instructions, expected %u", k, total);
    return -1;
  }
  struct sock_fprog fp = {(unsigned short)k, prog};
  if (setsockopt(fd, SOL_SOCKET, SO_ATTACH_FILTER, &fp, sizeof fp) != 0) {
    snprintf(err, err_sz, "LCM filter: SO_ATTACH_FILTER on port %d refused", port);
    return -1;
  }
  return 1;
}
