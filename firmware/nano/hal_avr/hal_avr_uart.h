/* UART0 at 500000 baud 8N1 with interrupt-driven RX and TX rings.
 * Bandwidth budget at 500000 baud (50000 bytes/s): STATE frames 67 B at 100 Hz = 6700 B/s
 * (13%), HELLO/NACK are rare; Jetson -> Nano COMMAND frames 16 B at 100 Hz = 1600 B/s (3%). */
#ifndef AUTODRIVE_HAL_AVR_UART_H
#define AUTODRIVE_HAL_AVR_UART_H
#include <stdint.h>
#ifdef __cplusplus
extern "C" {
#endif
#define HAL_AVR_UART_RX_SIZE 128u /* [bytes], power of two; 2.5 ms of line time at 500 kbaud */
#define HAL_AVR_UART_TX_SIZE 128u /* [bytes], power of two; holds one STATE frame plus a NACK */

void hal_avr_uart_init(void);
/* Moves up to max received bytes into out; returns the count. */
uint8_t hal_avr_uart_read(uint8_t *out, uint8_t max);
/* Received bytes wait in the ring (call with interrupts off to decide on sleeping). */
uint8_t hal_avr_uart_rx_pending(void);
/* Queues n bytes; drops what does not fit (counted) rather than blocking the loop. */
void hal_avr_uart_write(const uint8_t *data, uint8_t n);
/* Bytes lost to a full RX ring or a hardware overrun, and TX bytes dropped [bytes]. */
uint16_t hal_avr_uart_rx_lost(void);
uint16_t hal_avr_uart_tx_dropped(void);
#ifdef __cplusplus
}
#endif
#endif
