/* Actuators and slow inputs of the Nigel board: servo (Timer1 OC1A), motor driver (Timer0
 * OC0A + DIR/BRK), lamps, battery ADC, watchdog and reset cause. Pin map: hal_avr_pins.h. */
#ifndef AUTODRIVE_HAL_AVR_IO_H
#define AUTODRIVE_HAL_AVR_IO_H
#include <stdint.h>
#ifdef __cplusplus
extern "C" {
#endif
/* Everything to the safe state: servo centred, motor duty 0 with brake on, lamps off. */
void hal_avr_io_init(void);
void hal_avr_servo_set_us(uint16_t pulse_us); /* clamped to 1000..2000 us */
void hal_avr_motor_set(uint8_t duty, uint8_t reverse, uint8_t brake);
void hal_avr_lamps_set(uint8_t lamps); /* NANO_CORE_LAMP_* bits */
/* Battery: non-blocking, returns the last completed conversion [mV] and starts the next. */
uint16_t hal_avr_battery_read_mv(void);

/* MCUSR as it was at reset (captured in .init3 before anything clears it). */
uint8_t hal_avr_reset_cause(void);
void hal_avr_wdt_start(void); /* ~250 ms timeout, reset mode */
void hal_avr_wdt_kick(void);
#ifdef __cplusplus
}
#endif
#endif
