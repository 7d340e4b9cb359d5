/* The Nano firmware core: everything the car's firmware does, in portable C99 behind the HAL
 * (nigel_hal.h). The AVR firmware (firmware/nano/src), the host tests and the simulator's
 * emulated Nano all run this same code. Time is passed in [us] (uint32, wraps every ~71.6
 * min; all comparisons are wrap-safe differences).
 *
 *   nigel_init  once at boot (sends HELLO);
 *   nigel_rx    with the UART bytes received (any chunking, from the main loop, not an ISR);
 *   nigel_step  at >= 1 kHz: failsafe, actuators, lights, IMU + AHRS (every 10 ms), battery
 *               (every 10 ms), wheel speeds, STATE telemetry when due.
 *
 * Behaviour and wire format: firmware/nano/lib/proto/PROTOCOL.md. No malloc, no globals:
 * nigel_t is a complete struct the caller allocates (statically on the AVR: 270 bytes). */
#ifndef AUTODRIVE_NIGEL_CORE_H
#define AUTODRIVE_NIGEL_CORE_H

#include <stdint.h>

#include "act.h"
#include "ahrs.h"
#include "batt.h"
#include "fs.h"
#include "lights.h"
#include "nigel_hal.h"
#include "proto.h"
#include "wspd.h"

#ifdef __cplusplus
extern "C" {
#endif

#define NIGEL_FW_MAJOR 1u
#define NIGEL_FW_MINOR 0u
#define NIGEL_FW_PATCH 0u

#define NIGEL_IMU_PERIOD_US 10000ul /* [us] IMU read + AHRS update: 100 Hz */
#define NIGEL_IMU_OFFSET_US                                                             \
  5000ul                            /* [us] IMU reads sit between telemetry frames; the \
                                       AHRS runs in the three loop                      \
                                       passes after the read, a step each */
#define NIGEL_BATT_OFFSET_US 2500ul /* [us] battery reads too */
#define NIGEL_LOOP_OVERRUN_US                                                            \
  20000ul                              /* [us] a gap between nigel_step calls above this \
                                          raises PROTO_FAULT_LOOP_OVERRUN */
#define NIGEL_DEFAULT_TELEMETRY_MS 10u /* [ms] STATE period: 100 Hz */

typedef struct nigel {
  const nigel_hal_t *hal;
  proto_parser_t parser; /* bytes from the Jetson */
  fs_t fs;               /* failsafe state machine */
  act_t act;             /* motor and servo */
  lights_t lights;
  batt_t batt;
  wspd_t wspd;
  ahrs_t ahrs;
  proto_command_t cmd; /* last valid COMMAND (targets); zero until one arrives */
  proto_config_t cfg;  /* applied CONFIG */
  nigel_imu_raw_t imu; /* last good IMU sample (zeros until one is read) */
  int32_t enc[2];      /* [counts] left, right, as passed to the last nigel_step */
  uint32_t build_id;
  uint32_t schema_hash;    /* proto_schema_hash(), computed once at init */
  uint32_t rx_now_us;      /* [us] time of the bytes being parsed */
  uint32_t last_step_us;   /* [us] */
  uint32_t imu_next_us;    /* [us] next IMU read */
  uint32_t batt_next_us;   /* [us] next battery read */
  uint32_t telem_next_us;  /* [us] next STATE frame */
  uint32_t imu_read_us;    /* [us] time of the last good IMU sample */
  uint16_t faults_latched; /* PROTO_FAULT_CMD_INVALID / WATCHDOG_RESET / LOOP_OVERRUN;
                              cleared when the car is (re-)armed */
  uint8_t imu_lost;        /* the last IMU read failed (live, not latched) */
  uint8_t ahrs_stage;      /* next AHRS step for the last sample: 0 none, 1 gravity,
                              2 magnetic field, 3 integrate (one per loop pass) */
  uint8_t tx_seq;          /* frame seq of the next frame we send */
} nigel_t;

void nigel_init(nigel_t *n, const nigel_hal_t *hal, uint32_t now_us, uint8_t reset_was_watchdog,
                uint32_t build_id);
void nigel_rx(nigel_t *n, const uint8_t *data, uint8_t len, uint32_t now_us); /* UART bytes in */
void nigel_step(nigel_t *n, uint32_t now_us, int32_t enc_left_counts, int32_t enc_right_counts);

/* The fault word as sent in STATE (latched and live bits). */
uint16_t nigel_faults(const nigel_t *n);
/* Fills a STATE message from the current state (what the next telemetry frame would carry). */
void nigel_state(const nigel_t *n, proto_state_t *out, uint32_t now_us);

#ifdef __cplusplus
}
#endif
#endif
