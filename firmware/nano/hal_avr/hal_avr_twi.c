#include "hal_avr_twi.h"

#include <avr/interrupt.h>
#include <avr/io.h>
#include <util/twi.h>

static volatile uint8_t s_status;
static uint8_t s_addr7;
static const uint8_t *s_wr;
static uint8_t *s_rd;
static uint8_t s_nw, s_nr, s_iw, s_ir;

#define TWCR_RUN (_BV(TWEN) | _BV(TWIE) | _BV(TWINT))

void hal_avr_twi_init(void) {
  PORTC |= _BV(PC4) | _BV(PC5); /* weak internal pull-ups; the IMU board has its own */
  TWSR = 0;                     /* prescaler 1 */
  TWBR = 12;                    /* 16 MHz / (16 + 2 * 12) = 400 kHz */
  TWCR = _BV(TWEN);
  s_status = HAL_AVR_TWI_IDLE;
}

int hal_avr_twi_start(uint8_t addr7, const uint8_t *wr, uint8_t nw, uint8_t *rd, uint8_t nr) {
  if (s_status == HAL_AVR_TWI_BUSY) return -1;
  s_addr7 = addr7;
  s_wr = wr;
  s_nw = nw;
  s_rd = rd;
  s_nr = nr;
  s_iw = 0;
  s_ir = 0;
  s_status = HAL_AVR_TWI_BUSY;
  TWCR = TWCR_RUN | _BV(TWSTA);
  return 0;
}

uint8_t hal_avr_twi_status(void) {
  return s_status;
}

static void finish(uint8_t status) {
  TWCR = _BV(TWEN) | _BV(TWINT) | _BV(TWSTO);
  s_status = status;
}

void hal_avr_twi_abort(void) {
  uint8_t sreg = SREG;
  cli();
  TWCR = 0; /* disabling the TWI releases SDA/SCL and clears its state */
  TWCR = _BV(TWEN);
  s_status = HAL_AVR_TWI_ERROR;
  SREG = sreg;
}

ISR(TWI_vect) {
  switch (TW_STATUS) {
    case TW_START:
    case TW_REP_START:
      TWDR = (s_iw < s_nw || s_nr == 0) ? (uint8_t)(s_addr7 << 1) : (uint8_t)((s_addr7 << 1) | 1u);
      TWCR = TWCR_RUN;
      break;
    case TW_MT_SLA_ACK:
    case TW_MT_DATA_ACK:
      if (s_iw < s_nw) {
        TWDR = s_wr[s_iw++];
        TWCR = TWCR_RUN;
      } else if (s_nr > 0) {
        TWCR = TWCR_RUN | _BV(TWSTA); /* repeated START for the read */
      } else {
        finish(HAL_AVR_TWI_DONE);
      }
      break;
    case TW_MR_SLA_ACK: TWCR = s_nr > 1 ? (TWCR_RUN | _BV(TWEA)) : TWCR_RUN; break;
    case TW_MR_DATA_ACK:
      s_rd[s_ir++] = TWDR;
      TWCR = (uint8_t)(s_ir + 1u < s_nr ? (TWCR_RUN | _BV(TWEA)) : TWCR_RUN);
      break;
    case TW_MR_DATA_NACK:
      s_rd[s_ir++] = TWDR;
      finish(HAL_AVR_TWI_DONE);
      break;
    default: /* NACK on address or data, arbitration lost, bus error */
      finish(HAL_AVR_TWI_ERROR);
      break;
  }
}
