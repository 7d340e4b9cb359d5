#include "hal_avr_io.h"

#include <avr/interrupt.h>
#include <avr/io.h>
#include <avr/wdt.h>

#include "hal_avr_pins.h"
#include "nano_core_hal.h"

/* Timer1 mode 14 (fast PWM, TOP = ICR1), prescaler 8: 0.5 us per tick, 20 ms period. */
#define SERVO_TICKS_PER_US 2u
#define SERVO_PERIOD_TICKS 40000u

void hal_avr_io_init(void) {
  /* motor: DIR D7 low, BRK D8 high (braked), PWM D6 duty 0 on Timer0 (set up by init()) */
  PORTD &= (uint8_t) ~(_BV(PD6) | _BV(PD7));
  DDRD |= _BV(PD6) | _BV(PD7);
  PORTB |= _BV(PB0);
  DDRB |= _BV(PB0);
  OCR0A = 0;
  TCCR0A &= (uint8_t) ~(_BV(COM0A1) | _BV(COM0A0)); /* pin held low by PORTD while duty 0 */

  /* servo on OC1A (D9), centred */
  DDRB |= _BV(PB1);
  TCCR1A = _BV(COM1A1) | _BV(WGM11);
  TCCR1B = _BV(WGM13) | _BV(WGM12) | _BV(CS11);
  ICR1 = SERVO_PERIOD_TICKS - 1u;
  OCR1A = 1500u * SERVO_TICKS_PER_US;

  /* lamps: D10-D13 (PB2-PB5), D14-D15 (PC0-PC1), all off */
  PORTB &= (uint8_t) ~(_BV(PB2) | _BV(PB3) | _BV(PB4) | _BV(PB5));
  DDRB |= _BV(PB2) | _BV(PB3) | _BV(PB4) | _BV(PB5);
  PORTC &= (uint8_t) ~(_BV(PC0) | _BV(PC1));
  DDRC |= _BV(PC0) | _BV(PC1);

  /* battery ADC: AVcc reference, ADC7, prescaler 128 (125 kHz), first conversion started */
  ADMUX = _BV(REFS0) | HAL_AVR_BATTERY_ADC_CHANNEL;
  ADCSRA = _BV(ADEN) | _BV(ADSC) | _BV(ADPS2) | _BV(ADPS1) | _BV(ADPS0);
}

void hal_avr_servo_set_us(uint16_t pulse_us) {
  if (pulse_us < 1000u) pulse_us = 1000u;
  if (pulse_us > 2000u) pulse_us = 2000u;
  OCR1A = (uint16_t)(pulse_us * SERVO_TICKS_PER_US); /* double-buffered: applied at BOTTOM */
}

void hal_avr_motor_set(uint8_t duty, uint8_t reverse, uint8_t brake) {
  if (brake) {
    duty = 0;
    PORTB |= _BV(PB0);
  } else {
    PORTB &= (uint8_t)~_BV(PB0);
  }
  if (reverse) {
    PORTD |= _BV(PD7);
  } else {
    PORTD &= (uint8_t)~_BV(PD7);
  }
  OCR0A = duty;
  /* fast PWM still emits a 1-tick spike at OCR0A = 0: disconnect the pin instead */
  if (duty == 0) {
    TCCR0A &= (uint8_t)~_BV(COM0A1);
  } else {
    TCCR0A |= _BV(COM0A1);
  }
}

void hal_avr_lamps_set(uint8_t lamps) {
  uint8_t b = PORTB & (uint8_t) ~(_BV(PB2) | _BV(PB3) | _BV(PB4) | _BV(PB5));
  if (lamps & NANO_CORE_LAMP_HEAD_LOW) b |= _BV(PB2);
  if (lamps & NANO_CORE_LAMP_HEAD_HIGH) b |= _BV(PB3);
  if (lamps & NANO_CORE_LAMP_TAIL) b |= _BV(PB4);
  if (lamps & NANO_CORE_LAMP_REVERSE) b |= _BV(PB5);
  uint8_t c = PORTC & (uint8_t) ~(_BV(PC0) | _BV(PC1));
  if (lamps & NANO_CORE_LAMP_IND_LEFT) c |= _BV(PC0);
  if (lamps & NANO_CORE_LAMP_IND_RIGHT) c |= _BV(PC1);
  uint8_t sreg = SREG; /* PORTB/PORTC are shared with no ISR, but keep the write atomic */
  cli();
  PORTB = b;
  PORTC = c;
  SREG = sreg;
}

static uint16_t s_battery_mv;

uint16_t hal_avr_battery_read_mv(void) {
  if (!(ADCSRA & _BV(ADSC))) {
    uint32_t adc = ADC; /* 0..1023 */
    uint32_t mv_at_pin = adc * HAL_AVR_ADC_REF_MV / 1023u;
    s_battery_mv =
        (uint16_t)(mv_at_pin * (HAL_AVR_BATTERY_R_TOP_OHM + HAL_AVR_BATTERY_R_BOTTOM_OHM) /
                   HAL_AVR_BATTERY_R_BOTTOM_OHM);
    ADCSRA |= _BV(ADSC);
  }
  return s_battery_mv;
}

/* MCUSR must be read and cleared before the watchdog can be turned off after a WDT reset
 * (WDRF forces WDE on): done in .init3, before main() and the C++ constructors. */
static uint8_t s_mcusr __attribute__((section(".noinit")));
void hal_avr_io_capture_mcusr(void) __attribute__((naked, used, section(".init3")));
void hal_avr_io_capture_mcusr(void) {
  s_mcusr = MCUSR;
  MCUSR = 0;
  wdt_disable();
}

uint8_t hal_avr_reset_cause(void) {
  return s_mcusr;
}

void hal_avr_wdt_start(void) {
  wdt_enable(WDTO_250MS);
}

void hal_avr_wdt_kick(void) {
  wdt_reset();
}
