/* libFuzzer target: the protocol parser and the firmware core's receive path.
 *
 * The input is a script, so the fuzzer reaches deep states instead of dying at the CRC:
 *   op 0: n raw bytes (garbage, partial frames)             [0, n, bytes...]
 *   op 1: a frame with a valid CRC: id, len, payload         [1, id, len, payload...]
 *         (len is taken mod 65; with bit 7 of the id byte set the id comes from the list of
 *         real ids and the length is the right one for it)
 *   op 2: advance time by b * 97 us and run nano_core_step       [2, b]
 *   op 3: a valid frame split at a fuzzer-chosen point       [3, cut, id, len, payload...]
 * Invariants checked (abort on violation): the standalone parser and the core see the same
 * good frames, the parser never holds a complete frame, every byte the core sends parses back
 * with a good CRC, the motor only drives when ENGAGED, the servo stays in 1000..2000 us. */
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "nano_core.h"
#include "protocol.h"

typedef struct world {
  uint8_t duty, reverse, brake;
  uint16_t servo_us;
  uint32_t imu_reads;
  protocol_parser_t tx_check; /* parses what the core sends */
} world_t;

static void motor_set(void *c, uint8_t duty, uint8_t rev, uint8_t brake) {
  world_t *w = (world_t *)c;
  w->duty = duty;
  w->reverse = rev;
  w->brake = brake;
}
static void servo_set_us(void *c, uint16_t us) {
  ((world_t *)c)->servo_us = us;
}
static void lamps_set(void *c, uint8_t l) {
  (void)c;
  (void)l;
}
static int imu_read(void *c, nano_core_imu_raw_t *out) {
  world_t *w = (world_t *)c;
  memset(out, 0, sizeof *out);
  out->accel[2] = 8192;
  out->gyro[0] = (int16_t)(w->imu_reads * 37u);
  return (++w->imu_reads % 7u) == 0u ? -1 : 0; /* sometimes absent */
}
static uint16_t battery_read_mv(void *c) {
  return (uint16_t)(9000u + (((world_t *)c)->imu_reads * 131u) % 3000u);
}
static void serial_write(void *c, const uint8_t *d, uint8_t n) {
  protocol_parser_feed(&((world_t *)c)->tx_check, d, n, NULL, NULL);
}

static unsigned cb_count;
static void count_cb(const protocol_frame_t *f, void *ctx) {
  (void)f;
  (void)ctx;
  ++cb_count;
}

static const uint8_t real_ids[] = {
    PROTOCOL_ID_COMMAND, PROTOCOL_ID_CONFIG, PROTOCOL_ID_HELLO_REQUEST, PROTOCOL_ID_COMMAND,
    PROTOCOL_ID_COMMAND, PROTOCOL_ID_STATE,  PROTOCOL_ID_HELLO,         PROTOCOL_ID_NACK};
static uint8_t real_len(uint8_t id) {
  switch (id) {
    case PROTOCOL_ID_COMMAND: return PROTOCOL_LEN_COMMAND;
    case PROTOCOL_ID_CONFIG: return PROTOCOL_LEN_CONFIG;
    case PROTOCOL_ID_HELLO_REQUEST: return PROTOCOL_LEN_HELLO_REQUEST;
    case PROTOCOL_ID_HELLO: return PROTOCOL_LEN_HELLO;
    case PROTOCOL_ID_STATE: return PROTOCOL_LEN_STATE;
    default: return PROTOCOL_LEN_NACK;
  }
}

static nano_core_t core;
static protocol_parser_t parser;
static world_t world;
static nano_core_hal_t hal;
static uint32_t now_us;
static uint8_t tx_seq;

static void feed(const uint8_t *d, size_t n) {
  while (n > 0u) {
    uint8_t k = (uint8_t)(n > 255u ? 255u : n);
    protocol_parser_feed(&parser, d, k, count_cb, NULL);
    nano_core_rx(&core, d, k, now_us);
    d += k;
    n -= k;
  }
  if (parser.n >= PROTOCOL_MAX_FRAME) abort();
  if (parser.stats.frames_ok != core.parser.stats.frames_ok) abort();
  if (parser.stats.frames_ok != cb_count) abort();
}

static uint16_t servo_before;
static int32_t steer_before_u;
static void check_outputs(void) {
  /* the servo only moves while engaged (trim changes aside, which CONFIG makes) */
  if (core.failsafe.mode != PROTOCOL_MODE_ENGAGED && world.servo_us != servo_before &&
      core.actuation.steering_u != steer_before_u)
    abort();
  if (world.servo_us < 1000u || world.servo_us > 2000u) abort();
  if (world.duty > 0u && (core.failsafe.mode != PROTOCOL_MODE_ENGAGED || world.brake)) abort();
  if (world.tx_check.stats.bad_crc != 0u || world.tx_check.stats.bad_length != 0u) abort();
  if (world.tx_check.stats.frames_dropped != 0u) abort();
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  size_t i = 0;
  memset(&world, 0, sizeof world);
  protocol_parser_init(&world.tx_check);
  hal.ctx = &world;
  hal.motor_set = motor_set;
  hal.servo_set_us = servo_set_us;
  hal.lamps_set = lamps_set;
  hal.imu_read = imu_read;
  hal.battery_read_mv = battery_read_mv;
  hal.serial_write = serial_write;
  now_us = 0xFFFF0000u; /* close to the wrap on purpose */
  tx_seq = 0;
  cb_count = 0;
  protocol_parser_init(&parser);
  nano_core_init(&core, &hal, now_us, 0, 1u);
  while (i < size) {
    uint8_t op = (uint8_t)(data[i++] & 3u);
    if (op == 0u) {
      size_t n;
      if (i >= size) break;
      n = data[i++];
      if (n > size - i) n = size - i;
      feed(data + i, n);
      i += n;
    } else if (op == 1u || op == 3u) {
      uint8_t frame[PROTOCOL_MAX_FRAME], payload[PROTOCOL_MAX_PAYLOAD], id, len, cut = 0;
      size_t sz, avail;
      if (op == 3u) {
        if (i >= size) break;
        cut = data[i++];
      }
      if (i + 2u > size) break;
      id = data[i++];
      len = (uint8_t)(data[i++] % (PROTOCOL_MAX_PAYLOAD + 1u));
      if (id & 0x80u) {
        id = real_ids[id % sizeof real_ids];
        len = real_len(id);
      }
      memset(payload, 0, sizeof payload);
      avail = size - i < len ? size - i : len;
      memcpy(payload, data + i, avail);
      i += avail;
      sz = protocol_frame_encode(id, tx_seq++, payload, len, frame, sizeof frame);
      if (sz == 0u) abort();
      cut = (uint8_t)(cut % (sz + 1u));
      feed(frame, cut);
      feed(frame + cut, sz - cut);
    } else {
      uint32_t dt = 1u;
      if (i < size) dt = (uint32_t)data[i++] * 97u + 1u;
      now_us += dt;
      servo_before = world.servo_us;
      steer_before_u = core.actuation.steering_u;
      nano_core_step(&core, now_us, (int32_t)(now_us >> 7), -(int32_t)(now_us >> 8));
      check_outputs();
    }
  }
  /* let the failsafe run out: the car must end stopped */
  now_us += 200000u;
  servo_before = world.servo_us;
  steer_before_u = core.actuation.steering_u;
  nano_core_step(&core, now_us, 0, 0);
  check_outputs();
  if (world.duty != 0u) abort();
  return 0;
}
