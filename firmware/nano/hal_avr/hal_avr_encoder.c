#include "hal_avr_encoder.h"

#include <avr/interrupt.h>
#include <avr/io.h>

#include "encoder.h"

static encoder_t s_left, s_right;

void hal_avr_encoder_init(void) {
  encoder_init(&s_left, HAL_AVR_ENCODER_LEFT_INVERT);
  encoder_init(&s_right, HAL_AVR_ENCODER_RIGHT_INVERT);
  DDRD &= (uint8_t) ~(_BV(PD2) | _BV(PD3) | _BV(PD4) | _BV(PD5));
  PORTD |= _BV(PD2) | _BV(PD3) | _BV(PD4) | _BV(PD5); /* pull-ups for open-collector encoders */
  EICRA = _BV(ISC00) | _BV(ISC10);                    /* any logical change on INT0 and INT1 */
  EIFR = _BV(INTF0) | _BV(INTF1);
  EIMSK = _BV(INT0) | _BV(INT1);
}

/* Kept tiny (budget <= 150 cycles including entry and exit): one port read, the decoder of
 * core/encoder, one 32-bit add. flatten: -Os would otherwise call encoder_edge_a out of line, and
 * the call makes the ISR save every call-clobbered register (~2x the cycles). */
ISR(INT0_vect, __attribute__((flatten))) {
  uint8_t pins = PIND;
  encoder_edge_a(&s_left, pins & _BV(PD2), pins & _BV(PD4));
}

ISR(INT1_vect, __attribute__((flatten))) {
  uint8_t pins = PIND;
  encoder_edge_a(&s_right, pins & _BV(PD3), pins & _BV(PD5));
}

void hal_avr_encoder_read(int32_t *left_counts, int32_t *right_counts) {
  uint8_t sreg = SREG;
  cli();
  *left_counts = s_left.counts;
  *right_counts = s_right.counts;
  SREG = sreg;
}
