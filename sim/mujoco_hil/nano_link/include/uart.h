/* One direction of an emulated UART: a byte queue drained at the wire rate (8N1: 10 bits per
 * byte) against the sim clock, so bytes arrive as late as on the real wire. */
#ifndef SIM_UART_H
#define SIM_UART_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

#define UART_QUEUE_BYTES 4096u

typedef struct uart_queue {
  uint8_t buf[UART_QUEUE_BYTES];
  size_t head, count;
  double credit_bytes;    /* wire time earned but not yet used [bytes] */
  double bytes_per_us;    /* baud / 10 / 1e6 */
  uint64_t dropped_bytes; /* bytes refused because the queue was full */
} uart_queue_t;

void uart_init(uart_queue_t *q, uint32_t baud);
/* Queues n bytes; bytes beyond the capacity are dropped and counted. */
void uart_push(uart_queue_t *q, const uint8_t *data, size_t n);
/* Advances the wire by dt_us and copies out up to cap bytes that finished transmission.
 * Returns the number of bytes copied. */
size_t uart_pop(uart_queue_t *q, uint32_t dt_us, uint8_t *out, size_t cap);
/* Free space [bytes]. */
size_t uart_space(const uart_queue_t *q);

#ifdef __cplusplus
}
#endif
#endif
