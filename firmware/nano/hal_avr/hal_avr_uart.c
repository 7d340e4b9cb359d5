#include "hal_avr_uart.h"

#include <avr/interrupt.h>
#include <avr/io.h>

static volatile uint8_t s_rx[HAL_AVR_UART_RX_SIZE];
static volatile uint8_t s_rx_head, s_rx_tail; /* head: ISR writes, tail: loop reads */
static volatile uint8_t s_tx[HAL_AVR_UART_TX_SIZE];
static volatile uint8_t s_tx_head, s_tx_tail; /* head: loop writes, tail: ISR reads */
static volatile uint16_t s_rx_lost;
static uint16_t s_tx_dropped;

void hal_avr_uart_init(void) {
  UCSR0A = _BV(U2X0);
  UBRR0 = 3; /* 16 MHz / (8 * (3 + 1)) = 500000 baud exactly */
  UCSR0C = _BV(UCSZ01) | _BV(UCSZ00);
  UCSR0B = _BV(RXEN0) | _BV(TXEN0) | _BV(RXCIE0);
}

ISR(USART_RX_vect) {
  uint8_t status = UCSR0A;
  uint8_t byte = UDR0;
  uint8_t next = (uint8_t)((s_rx_head + 1u) & (HAL_AVR_UART_RX_SIZE - 1u));
  if ((status & _BV(DOR0)) || next == s_rx_tail) {
    s_rx_lost++;
  }
  if (next != s_rx_tail) {
    s_rx[s_rx_head] = byte;
    s_rx_head = next;
  }
}

ISR(USART_UDRE_vect) {
  if (s_tx_tail == s_tx_head) {
    UCSR0B &= (uint8_t)~_BV(UDRIE0);
    return;
  }
  UDR0 = s_tx[s_tx_tail];
  s_tx_tail = (uint8_t)((s_tx_tail + 1u) & (HAL_AVR_UART_TX_SIZE - 1u));
}

uint8_t hal_avr_uart_read(uint8_t *out, uint8_t max) {
  uint8_t n = 0;
  uint8_t head = s_rx_head; /* one byte: atomic */
  while (n < max && s_rx_tail != head) {
    out[n++] = s_rx[s_rx_tail];
    s_rx_tail = (uint8_t)((s_rx_tail + 1u) & (HAL_AVR_UART_RX_SIZE - 1u));
  }
  return n;
}

void hal_avr_uart_write(const uint8_t *data, uint8_t n) {
  for (uint8_t i = 0; i < n; i++) {
    uint8_t next = (uint8_t)((s_tx_head + 1u) & (HAL_AVR_UART_TX_SIZE - 1u));
    if (next == s_tx_tail) {
      s_tx_dropped = (uint16_t)(s_tx_dropped + (uint8_t)(n - i));
      break;
    }
    s_tx[s_tx_head] = data[i];
    s_tx_head = next;
  }
  UCSR0B |= _BV(UDRIE0); /* RMW is safe: the ISR clears UDRIE0 only when the ring is empty */
}

uint8_t hal_avr_uart_rx_pending(void) {
  return (uint8_t)(s_rx_head != s_rx_tail);
}

uint16_t hal_avr_uart_rx_lost(void) {
  uint8_t sreg = SREG;
  cli();
  uint16_t v = s_rx_lost;
  SREG = sreg;
  return v;
}

uint16_t hal_avr_uart_tx_dropped(void) {
  return s_tx_dropped;
}
