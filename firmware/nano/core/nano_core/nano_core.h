/* The Nano firmware core: everything the car's firmware does, in portable C99 behind the HAL
 * (nano_core_hal.h). The AVR firmware (firmware/nano/hal_avr), the host tests and the simulator's
 * emulated Nano all run this same code. Time is passed in [us] (uint32, wraps every ~71.6
 * min; all comparisons are wrap-safe differences).
 *
 *   nano_core_init  once at boot (sends HELLO);
 *   nano_core_rx    with the UART bytes received (any chunking, from the main loop, not an ISR);
 *   nano_core_step  at >= 1 kHz: failsafe, actuators, lights, IMU + AHRS (every 10 ms), battery
 *               (every 10 ms), wheel speeds, STATE telemetry when due.
 *
 * Behaviour and wire format: firmware/nano/core/protocol/PROTOCOL.md. No malloc, no globals:
 * nano_core_t is a complete struct the caller allocates (statically on the AVR: 270 bytes). */
#ifndef AUTODRIVE_NANO_CORE_H
#define AUTODRIVE_NANO_CORE_H

#include <stdint.h>

#include "actuation.h"
#include "ahrs.h"
#include "battery.h"
#include "failsafe.h"
#include "lights.h"
#include "nano_core_hal.h"
#include "protocol.h"
#include "wheel_speed.h"

#ifdef __cplusplus
extern "C" {
#endif

#define NIGEL_FW_MAJOR 1u
#define NIGEL_FW_MINOR 0u
#define NIGEL_FW_PATCH 0u

#define NANO_CORE_IMU_PERIOD_US 10000ul /* [us] IMU read + AHRS update: 100 Hz */
/* [us] IMU reads sit between telemetry frames; the AHRS runs in the three loop passes after the
 * read, a step each. Battery reads are offset too. */
#define NANO_CORE_IMU_OFFSET_US 5000ul
#define NANO_CORE_BATTERY_OFFSET_US 2500ul
/* [us] a gap between nano_core_step calls above this raises PROTOCOL_FAULT_LOOP_OVERRUN */
#define NANO_CORE_LOOP_OVERRUN_US 20000ul
#define NANO_CORE_DEFAULT_TELEMETRY_MS 10u /* [ms] STATE period: 100 Hz */

typedef struct nano_core {
  const nano_core_hal_t *hal;
  protocol_parser_t parser; /* bytes from the Jetson */
  failsafe_t failsafe;      /* failsafe state machine */
  actuation_t actuation;    /* motor and servo */
  lights_t lights;
  battery_t battery;
  wheel_speed_t wheel_speed;
  ahrs_t ahrs;
  protocol_command_t cmd;  /* last valid COMMAND (targets); zero until one arrives */
  protocol_config_t cfg;   /* applied CONFIG */
  nano_core_imu_raw_t imu; /* last good IMU sample (zeros until one is read) */
  int32_t enc[2];          /* [counts] left, right, as passed to the last nano_core_step */
  uint32_t build_id;
  uint32_t schema_hash;     /* protocol_schema_hash(), computed once at init */
  uint32_t rx_now_us;       /* [us] time of the bytes being parsed */
  uint32_t last_step_us;    /* [us] */
  uint32_t imu_next_us;     /* [us] next IMU read */
  uint32_t battery_next_us; /* [us] next battery read */
  uint32_t telem_next_us;   /* [us] next STATE frame */
  uint32_t imu_read_us;     /* [us] time of the last good IMU sample */
  uint16_t faults_latched;  /* PROTOCOL_FAULT_CMD_INVALID / WATCHDOG_RESET / LOOP_OVERRUN;
                               cleared when the car is (re-)armed */
  uint8_t imu_lost;         /* the last IMU read failed (live, not latched) */
  uint8_t ahrs_stage;       /* next AHRS step for the last sample: 0 none, 1 gravity,
                               2 magnetic field, 3 integrate (one per loop pass) */
  uint8_t tx_seq;           /* frame seq of the next frame we send */
} nano_core_t;

void nano_core_init(nano_core_t *n, const nano_core_hal_t *hal, uint32_t now_us,
                    uint8_t reset_was_watchdog, uint32_t build_id);
void nano_core_rx(nano_core_t *n, const uint8_t *data, uint8_t len,
                  uint32_t now_us); /* UART bytes in */
void nano_core_step(nano_core_t *n, uint32_t now_us, int32_t enc_left_counts,
                    int32_t enc_right_counts);

/* The fault word as sent in STATE (latched and live bits). */
uint16_t nano_core_faults(const nano_core_t *n);
/* Fills a STATE message from the current state (what the next telemetry frame would carry). */
void nano_core_state(const nano_core_t *n, protocol_state_t *out, uint32_t now_us);

#ifdef __cplusplus
}
#endif
#endif
