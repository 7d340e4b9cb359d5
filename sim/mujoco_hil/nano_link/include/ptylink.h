/* A pseudo-terminal that stands in for a USB serial port, with a stable symlink to its slave.
 * The master is non-blocking. The sim keeps a slave descriptor open itself so the master never
 * sees a hang-up while no client is connected; clients may come and go. */
#ifndef SIM_PTYLINK_H
#define SIM_PTYLINK_H

#include <stddef.h>
#include <sys/types.h>

typedef struct ptylink {
  int master_fd, slave_fd;
  char slave_path[64];
  char link_path[512];
} ptylink_t;

/* Opens the pty in raw mode and points link_path at the slave (replacing an old symlink, never
 * a regular file). Returns 0, or -1 with a message in err. */
int ptylink_open(ptylink_t *p, const char *link_path, char *err, size_t err_sz);
/* Reads what the client wrote (up to cap). Returns bytes read, 0 if none. */
size_t ptylink_read(ptylink_t *p, unsigned char *buf, size_t cap);
/* Writes n bytes; returns bytes accepted (fewer when the pty buffer is full). */
size_t ptylink_write(ptylink_t *p, const unsigned char *buf, size_t n);
/* Bytes written to the client that it has not read yet [bytes] (FIONREAD on our own slave
 * descriptor); 0 when unknown. A queue that only grows means nobody reads the pty. */
size_t ptylink_unread(const ptylink_t *p);
/* Closes both ends and removes the symlink. Safe on a zeroed or already closed link. */
void ptylink_close(ptylink_t *p);

#endif
