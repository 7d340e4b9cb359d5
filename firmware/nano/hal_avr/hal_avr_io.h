/* Actuators and slow inputs of the Nigel board: servo (Timer1 OC1A), motor driver (Timer0
 * OC0A + DIR/BRK), lamps, battery ADC, watchdog and reset cause. Pin map: fw_pins.h. */
#ifndef NIGEL_FW_IO_H
#define NIGEL_FW_IO_H
#include <stdint.h>
#ifdef __cplusplus
extern "C" {
#endif
/* Everything to the safe state: servo centred, motor duty 0 with brake on, lamps off. */
void fw_io_init(void);
void fw_servo_set_us(uint16_t pulse_us); /* clamped to 1000..2000 us */
void fw_motor_set(uint8_t duty, uint8_t reverse, uint8_t brake);
void fw_lamps_set(uint8_t lamps); /* NIGEL_LAMP_* bits */
/* Battery: non-blocking, returns the last completed conversion [mV] and starts the next. */
uint16_t fw_battery_read_mv(void);

/* MCUSR as it was at reset (captured in .init3 before anything clears it). */
uint8_t fw_reset_cause(void);
void fw_wdt_start(void); /* ~250 ms timeout, reset mode */
void fw_wdt_kick(void);
#ifdef __cplusplus
}
#endif
#endif
