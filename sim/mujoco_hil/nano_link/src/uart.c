/* Wire-rate byte queue (see uart.h). */
#include "uart.h"

void uart_init(uart_queue_t *q, uint32_t baud) {
  q->head = q->count = 0;
  q->credit_bytes = 0.0;
  q->bytes_per_us = baud / 10.0 / 1e6;
  q->dropped_bytes = 0;
}

size_t uart_space(const uart_queue_t *q) {
  return UART_QUEUE_BYTES - q->count;
}

void uart_push(uart_queue_t *q, const uint8_t *data, size_t n) {
  for (size_t i = 0; i < n; i++) {
    if (q->count == UART_QUEUE_BYTES) {
      q->dropped_bytes += n - i;
      return;
    }
    q->buf[(q->head + q->count) % UART_QUEUE_BYTES] = data[i];
    q->count++;
  }
}

size_t uart_pop(uart_queue_t *q, uint32_t dt_us, uint8_t *out, size_t cap) {
  q->credit_bytes += q->bytes_per_us * dt_us;
  size_t n = 0;
  while (n < cap && q->count > 0 && q->credit_bytes >= 1.0) {
    out[n++] = q->buf[q->head];
    q->head = (q->head + 1) % UART_QUEUE_BYTES;
    q->count--;
    q->credit_bytes -= 1.0;
  }
  /* an idle line cannot bank wire time: at most one byte of credit carries over */
  if (q->count == 0 && q->credit_bytes > 1.0) q->credit_bytes = 1.0;
  return n;
}
