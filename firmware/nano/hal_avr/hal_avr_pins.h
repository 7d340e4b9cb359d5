/* Nano pin map and timer use of the Nigel board (ATmega328P at 16 MHz).
 *
 *   D2  PD2 INT0   left encoder A   (any edge -> one count, B read in the ISR)
 *   D3  PD3 INT1   right encoder A
 *   D4  PD4        left encoder B
 *   D5  PD5        right encoder B
 *   D6  PD6 OC0A   motor PWM, Timer0 fast PWM ~976 Hz (Timer0 also runs micros())
 *   D7  PD7        motor DIR (1 = reverse)
 *   D8  PB0        motor BRK (1 = brake)
 *   D9  PB1 OC1A   steering servo, Timer1 mode 14, 50 Hz, 0.5 us steps
 *   D10 PB2        headlight low   } plain GPIO: Timer1 drives OC1A only (COM1B = 0), so
 *   D11 PB3        headlight high  } D10 is free; never analogWrite() D10 (it would steal
 *   D12 PB4        tail/brake lamp } Timer1's period from the servo)
 *   D13 PB5        reverse lamp (also the on-board LED)
 *   D14 PC0 (A0)   left indicator
 *   D15 PC1 (A1)   right indicator
 *   A4/A5 PC4/PC5  TWI SDA/SCL: MPU-9250 at 0x68, its AK8963 magnetometer at 0x0C (bypass)
 *   A7  ADC7       battery through a 10k:3.3k divider (11.1 V 3S pack -> ~2.8 V)
 *   D0/D1          UART0 at 500000 baud (U2X, UBRR0 = 3, exact at 16 MHz)
 */
#ifndef AUTODRIVE_HAL_AVR_PINS_H
#define AUTODRIVE_HAL_AVR_PINS_H

#define HAL_AVR_F_CPU_HZ 16000000ul

/* Battery divider: V_pack = V_adc * (R_top + R_bottom) / R_bottom, AVcc = 5.0 V reference. */
#define HAL_AVR_BATTERY_R_TOP_OHM 10000ul
#define HAL_AVR_BATTERY_R_BOTTOM_OHM 3300ul
#define HAL_AVR_ADC_REF_MV 5000ul
#define HAL_AVR_BATTERY_ADC_CHANNEL 7u

#endif
