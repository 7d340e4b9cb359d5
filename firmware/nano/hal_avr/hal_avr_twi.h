/* Interrupt-driven TWI (I2C) master, 400 kHz, one transaction at a time, never blocking:
 * the loop starts a transaction and polls its status; a watchdog on the loop side aborts a
 * transaction that has not finished in time (an IMU that holds the bus or never answers).
 * Written instead of Arduino's Wire, whose endTransmission()/requestFrom() busy-wait. */
#ifndef AUTODRIVE_HAL_AVR_TWI_H
#define AUTODRIVE_HAL_AVR_TWI_H
#include <stdint.h>
#ifdef __cplusplus
extern "C" {
#endif
enum { HAL_AVR_TWI_IDLE = 0, HAL_AVR_TWI_BUSY = 1, HAL_AVR_TWI_DONE = 2, HAL_AVR_TWI_ERROR = 3 };

void hal_avr_twi_init(void);
/* Writes nw bytes, then (if nr > 0) a repeated START and reads nr bytes into rd. The
 * buffers must stay valid until the status leaves HAL_AVR_TWI_BUSY. Returns 0, or -1 if busy. */
int hal_avr_twi_start(uint8_t addr7, const uint8_t *wr, uint8_t nw, uint8_t *rd, uint8_t nr);
uint8_t hal_avr_twi_status(void);
/* Stops whatever is going on and resets the peripheral (status -> HAL_AVR_TWI_ERROR). */
void hal_avr_twi_abort(void);
#ifdef __cplusplus
}
#endif
#endif
