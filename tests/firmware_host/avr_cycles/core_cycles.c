/* AVR program (ATmega328P, 16 MHz) that times the firmware core's entry points with Timer1
 * (prescaler 1: one tick per CPU cycle) on a stub HAL whose calls cost next to nothing, so the
 * figures are the core's own cost. Run in simavr by run.sh; results land in core_results[]. */
#include <avr/interrupt.h>
#include <avr/io.h>
#include <avr/sleep.h>
#include <stdint.h>

#include "encoder.h"
#include "nano_core.h"

enum {
  R_INIT,
  R_STEP_IDLE,
  R_STEP_IMU,
  R_STEP_BATT,
  R_STEP_TELEM,
  R_RX_COMMAND,
  R_ENC_EDGE,
  R_STEP_IDLE_MAX,
  R_SCHEMA_HASH,
  R_STEP_AHRS,
  R_STEP_AHRS2,
  R_STEP_AHRS3,
  R_N
};
volatile uint32_t core_results[R_N];
volatile uint8_t core_done;
static volatile uint16_t ovf;
ISR(TIMER1_OVF_vect) {
  ++ovf;
}

static void t_start(void) {
  cli();
  TCNT1 = 0;
  ovf = 0;
  TIFR1 = _BV(TOV1);
  sei();
}
static uint32_t t_stop(void) {
  uint16_t t = TCNT1;
  cli();
  if (TIFR1 & _BV(TOV1)) {
    ++ovf;
    TIFR1 = _BV(TOV1);
    t = TCNT1;
  }
  sei();
  return ((uint32_t)ovf << 16) | t;
}

static void motor_set(void *c, uint8_t d, uint8_t r, uint8_t b) {
  (void)c;
  (void)d;
  (void)r;
  (void)b;
}
static void servo_set_us(void *c, uint16_t us) {
  (void)c;
  (void)us;
}
static void lamps_set(void *c, uint8_t l) {
  (void)c;
  (void)l;
}
static int imu_read(void *c, nano_core_imu_raw_t *o) {
  (void)c;
  o->accel[0] = 120;
  o->accel[1] = -340;
  o->accel[2] = 8100;
  o->gyro[0] = 12;
  o->gyro[1] = -7;
  o->gyro[2] = 300;
  o->mag[0] = 150;
  o->mag[1] = 40;
  o->mag[2] = -280;
  return 0;
}
static uint16_t battery_read_mv(void *c) {
  (void)c;
  return 11800;
}
static volatile uint8_t sink;
static void serial_write(void *c, const uint8_t *d, uint8_t n) {
  (void)c;
  sink = d[n - 1];
}

static const nano_core_hal_t hal = {0,        motor_set,       servo_set_us, lamps_set,
                                    imu_read, battery_read_mv, serial_write};
static nano_core_t core;
static encoder_t enc;

static void put_max(uint8_t i, uint32_t v) {
  if (v > core_results[i]) core_results[i] = v;
}

int main(void) {
  uint32_t now = 0, t;
  uint16_t i;
  uint8_t frame[PROTOCOL_MAX_FRAME], payload[PROTOCOL_LEN_COMMAND];
  protocol_command_t cmd = {1, 500, 300, 1, 1, PROTOCOL_CMD_ENGAGED};
  uint8_t flen;
  TCCR1A = 0;
  TCCR1B = _BV(CS10);
  TIMSK1 = _BV(TOIE1);
  sei();

  t_start();
  nano_core_init(&core, &hal, now, 0, 1);
  core_results[R_INIT] = t_stop();
  t_start();
  (void)protocol_schema_hash();
  core_results[R_SCHEMA_HASH] = t_stop();

  /* arm so the engaged paths run: engaged=0 then engaged=1 */
  cmd.flags = 0;
  protocol_command_pack(&cmd, payload);
  flen = (uint8_t)protocol_frame_encode(PROTOCOL_ID_COMMAND, 0, payload, PROTOCOL_LEN_COMMAND,
                                        frame, sizeof frame);
  nano_core_rx(&core, frame, flen, now);
  cmd.flags = PROTOCOL_CMD_ENGAGED;
  cmd.seq = 2;
  protocol_command_pack(&cmd, payload);
  flen = (uint8_t)protocol_frame_encode(PROTOCOL_ID_COMMAND, 1, payload, PROTOCOL_LEN_COMMAND,
                                        frame, sizeof frame);

  /* 300 loop passes at 1 kHz with a command every 20 ms; classify each pass by the periodic
   * work due in it (phases: battery at 2.5 ms, IMU at 5 ms, telemetry at 0 ms mod 10 ms). */
  for (i = 1; i <= 300; ++i) {
    uint16_t phase_us;
    now += 1000;
    if (i % 20 == 0) {
      t_start();
      nano_core_rx(&core, frame, flen, now);
      put_max(R_RX_COMMAND, t_stop());
    }
    t_start();
    nano_core_step(&core, now, (int32_t)i * 2, (int32_t)i * 2);
    t = t_stop();
    phase_us = (uint16_t)(now % 10000u);
    if (phase_us == 0u)
      put_max(R_STEP_TELEM, t);
    else if (phase_us == 5000u)
      put_max(R_STEP_IMU, t);
    else if (phase_us == 6000u)
      put_max(R_STEP_AHRS, t);
    else if (phase_us == 7000u)
      put_max(R_STEP_AHRS2, t);
    else if (phase_us == 8000u)
      put_max(R_STEP_AHRS3, t);
    else if (phase_us == 3000u)
      put_max(R_STEP_BATT, t);
    else {
      put_max(R_STEP_IDLE_MAX, t);
      core_results[R_STEP_IDLE] = t; /* last one: typical */
    }
  }
  encoder_init(&enc, 0);
  t_start();
  encoder_edge_a(&enc, 1, 0);
  core_results[R_ENC_EDGE] = t_stop();
  core_done = 1;
  cli();
  sleep_mode();
  for (;;) {
  }
}
