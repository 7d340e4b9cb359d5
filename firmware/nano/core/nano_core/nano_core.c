/* The firmware core; see nano_core.h and PROTOCOL.md. */
#include "nano_core.h"

#include <string.h>

/* ---- transmit ------------------------------------------------------------------------- */
static void send_frame(nano_core_t *n, uint8_t id, const uint8_t *payload, uint8_t len) {
  uint8_t frame[PROTOCOL_MAX_FRAME];
  size_t size = protocol_frame_encode(id, n->tx_seq, payload, len, frame, sizeof frame);
  if (size == 0u) return; /* cannot happen for our fixed lengths */
  ++n->tx_seq;
  n->hal->serial_write(n->hal->ctx, frame, (uint8_t)size);
}

static void send_hello(nano_core_t *n) {
  protocol_hello_t h;
  uint8_t p[PROTOCOL_LEN_HELLO];
  h.fw_major = NIGEL_FW_MAJOR;
  h.fw_minor = NIGEL_FW_MINOR;
  h.fw_patch = NIGEL_FW_PATCH;
  h.proto_version = PROTOCOL_VERSION;
  h.schema_hash = n->schema_hash;
  h.build_id = n->build_id;
  protocol_hello_pack(&h, p);
  send_frame(n, PROTOCOL_ID_HELLO, p, PROTOCOL_LEN_HELLO);
}

static void send_nack(nano_core_t *n, uint8_t id, uint8_t reason, uint16_t seq) {
  protocol_nack_t k;
  uint8_t p[PROTOCOL_LEN_NACK];
  k.rejected_id = id;
  k.reason = reason;
  k.seq = seq;
  protocol_nack_pack(&k, p);
  send_frame(n, PROTOCOL_ID_NACK, p, PROTOCOL_LEN_NACK);
}

/* ---- receive -------------------------------------------------------------------------- */
static void on_command(nano_core_t *n, const protocol_frame_t *f) {
  protocol_command_t c;
  if (protocol_command_unpack(f->payload, f->len, &c) != 0) {
    send_nack(n, f->id, PROTOCOL_NACK_BAD_LENGTH, 0);
    return;
  }
  if (!protocol_command_valid(&c)) {
    /* never applied, and it does not feed the failsafe timer */
    n->faults_latched |= PROTOCOL_FAULT_CMD_INVALID;
    send_nack(n, f->id, PROTOCOL_NACK_OUT_OF_RANGE, c.seq);
    return;
  }
  if (failsafe_on_command(&n->failsafe, (uint8_t)(c.flags & PROTOCOL_CMD_ENGAGED), n->rx_now_us))
    n->faults_latched = 0; /* (re-)armed: the operator has acknowledged the faults */
  n->cmd = c;
}

static void on_config(nano_core_t *n, const protocol_frame_t *f) {
  protocol_config_t c;
  if (protocol_config_unpack(f->payload, f->len, &c) != 0) {
    send_nack(n, f->id, PROTOCOL_NACK_BAD_LENGTH, 0);
    return;
  }
  if (!protocol_config_valid(&c)) {
    send_nack(n, f->id, PROTOCOL_NACK_OUT_OF_RANGE, 0);
    return;
  }
  n->cfg = c;
  n->actuation.trim_us = c.servo_trim_us;
  failsafe_set_timeout_ms(&n->failsafe, c.failsafe_timeout_ms);
}

static void on_frame(const protocol_frame_t *f, void *ctx) {
  nano_core_t *n = (nano_core_t *)ctx;
  switch (f->id) {
    case PROTOCOL_ID_COMMAND: on_command(n, f); break;
    case PROTOCOL_ID_CONFIG: on_config(n, f); break;
    case PROTOCOL_ID_HELLO_REQUEST:
      if (f->len != PROTOCOL_LEN_HELLO_REQUEST)
        send_nack(n, f->id, PROTOCOL_NACK_BAD_LENGTH, 0);
      else
        send_hello(n);
      break;
    default: send_nack(n, f->id, PROTOCOL_NACK_UNKNOWN_ID, 0); break;
  }
}

void nano_core_rx(nano_core_t *n, const uint8_t *data, uint8_t len, uint32_t now_us) {
  n->rx_now_us = now_us;
  protocol_parser_feed(&n->parser, data, len, on_frame, n);
}

/* ---- state ---------------------------------------------------------------------------- */
uint16_t nano_core_faults(const nano_core_t *n) {
  uint16_t f = n->faults_latched;
  if (n->failsafe.link_lost) f |= PROTOCOL_FAULT_LINK_LOST;
  if (n->imu_lost) f |= PROTOCOL_FAULT_IMU_LOST;
  if (n->battery.low) f |= PROTOCOL_FAULT_BATTERY_LOW;
  if (n->battery.cutoff) f |= PROTOCOL_FAULT_BATTERY_CUTOFF;
  return f;
}

void nano_core_state(const nano_core_t *n, protocol_state_t *s, uint32_t now_us) {
  uint8_t i;
  s->nano_time_us = now_us;
  s->enc_counts[0] = n->enc[0];
  s->enc_counts[1] = n->enc[1];
  s->wheel_speed_mrad_s[0] = wheel_speed_mrad_s(&n->wheel_speed, 0);
  s->wheel_speed_mrad_s[1] = wheel_speed_mrad_s(&n->wheel_speed, 1);
  s->throttle_milli = actuation_throttle_milli(&n->actuation);
  s->steering_milli = actuation_steering_milli(&n->actuation);
  for (i = 0; i < 3u; ++i) {
    s->accel_raw[i] = n->imu.accel[i];
    s->gyro_raw[i] = n->imu.gyro[i];
    s->mag_raw[i] = n->imu.mag[i];
  }
  ahrs_quat_q14(&n->ahrs, s->quat_q14);
  s->battery_mv = battery_mv(&n->battery);
  s->lights = n->lights.state;
  s->mode = n->failsafe.mode;
  s->faults = nano_core_faults(n);
  s->last_cmd_seq = n->cmd.seq;
  s->frames_ok = (uint16_t)n->parser.stats.frames_ok;
  s->frames_bad_crc = (uint16_t)n->parser.stats.bad_crc;
  s->frames_dropped = (uint16_t)n->parser.stats.frames_dropped;
}

/* ---- init / step ---------------------------------------------------------------------- */
void nano_core_init(nano_core_t *n, const nano_core_hal_t *hal, uint32_t now_us,
                    uint8_t reset_was_watchdog, uint32_t build_id) {
  memset(n, 0, sizeof *n);
  n->hal = hal;
  n->build_id = build_id;
  n->schema_hash = protocol_schema_hash(); /* once: ~2 ms on the AVR (schema string in flash) */
  protocol_parser_init(&n->parser);
  failsafe_init(&n->failsafe, FAILSAFE_DEFAULT_TIMEOUT_MS);
  actuation_init(&n->actuation, now_us);
  lights_init(&n->lights, now_us);
  battery_init(&n->battery);
  wheel_speed_init(&n->wheel_speed);
  ahrs_init(&n->ahrs);
  n->cfg.servo_trim_us = 0;
  n->cfg.telemetry_period_ms = NANO_CORE_DEFAULT_TELEMETRY_MS;
  n->cfg.failsafe_timeout_ms = FAILSAFE_DEFAULT_TIMEOUT_MS;
  if (reset_was_watchdog) n->faults_latched |= PROTOCOL_FAULT_WATCHDOG_RESET;
  /* know the pack before the first command can arm: a flat pack refuses drive from boot */
  battery_update(&n->battery, hal->battery_read_mv(hal->ctx));
  n->last_step_us = now_us;
  n->imu_next_us = now_us + NANO_CORE_IMU_OFFSET_US;
  n->battery_next_us = now_us + NANO_CORE_BATTERY_OFFSET_US;
  n->telem_next_us = now_us + (uint32_t)n->cfg.telemetry_period_ms * 1000ul;
  /* boot silent: brake on, servo centred, lamps off */
  hal->motor_set(hal->ctx, 0, 0, 1);
  hal->servo_set_us(hal->ctx, ACTUATION_SERVO_CENTER_US);
  hal->lamps_set(hal->ctx, 0);
  send_hello(n);
}

/* 1 when the periodic deadline *next_us has come; advances it by period_us (and resyncs
 * after a stall instead of bursting). */
static uint8_t due(uint32_t *next_us, uint32_t period_us, uint32_t now_us) {
  if ((int32_t)(now_us - *next_us) < 0) return 0;
  *next_us += period_us;
  if ((int32_t)(now_us - *next_us) >= 0) *next_us = now_us + period_us;
  return 1;
}

void nano_core_step(nano_core_t *n, uint32_t now_us, int32_t enc_left_counts,
                    int32_t enc_right_counts) {
  const nano_core_hal_t *hal = n->hal;
  uint8_t actuation_flags = 0, indicators;

  if ((uint32_t)(now_us - n->last_step_us) > NANO_CORE_LOOP_OVERRUN_US)
    n->faults_latched |= PROTOCOL_FAULT_LOOP_OVERRUN;
  n->last_step_us = now_us;
  n->enc[0] = enc_left_counts;
  n->enc[1] = enc_right_counts;

  failsafe_update(&n->failsafe, now_us);

  if (due(&n->battery_next_us, BATTERY_PERIOD_US, now_us))
    battery_update(&n->battery, hal->battery_read_mv(hal->ctx));

  if (due(&n->imu_next_us, NANO_CORE_IMU_PERIOD_US, now_us)) {
    nano_core_imu_raw_t raw;
    if (hal->imu_read(hal->ctx, &raw) == 0) {
      n->imu = raw;
      n->imu_lost = 0;
      n->imu_read_us = now_us;
      n->ahrs_stage = 1;
    } else {
      n->imu_lost = 1;
    }
  } else if (n->ahrs_stage != 0u) {
    /* the AHRS runs in the three passes after the (blocking) IMU read, a third each, so no
     * loop pass carries more than one of these software-float costs */
    if (n->ahrs_stage == 1u) {
      ahrs_correct(&n->ahrs, n->imu.accel, n->imu.gyro, n->imu_read_us);
      n->ahrs_stage = 2;
    } else if (n->ahrs_stage == 2u) {
      ahrs_correct_mag(&n->ahrs, n->imu.mag);
      n->ahrs_stage = 3;
    } else {
      ahrs_integrate(&n->ahrs);
      n->ahrs_stage = 0;
    }
  }

  wheel_speed_update(&n->wheel_speed, enc_left_counts, enc_right_counts, now_us);

  /* Not engaged: no drive and the servo holds where it is (nothing moves unless the host
   * engaged). A flat battery only refuses drive; steering still follows. */
  if (!failsafe_may_drive(&n->failsafe)) actuation_flags = ACTUATION_STOP | ACTUATION_HOLD_STEERING;
  if (n->battery.cutoff) actuation_flags |= ACTUATION_STOP;
  actuation_update(&n->actuation, n->cmd.throttle_milli, n->cmd.steering_milli, actuation_flags,
                   now_us);
  hal->motor_set(hal->ctx, n->actuation.duty, n->actuation.reverse, n->actuation.brake);
  hal->servo_set_us(hal->ctx, n->actuation.servo_us);

  indicators = n->failsafe.mode == PROTOCOL_MODE_FAILSAFE ? 3u : n->cmd.indicators;
  hal->lamps_set(hal->ctx, lights_update(&n->lights, n->cmd.headlights, indicators,
                                         (uint8_t)(n->actuation.brake || n->actuation.decelerating),
                                         n->actuation.reverse, now_us));

  if (due(&n->telem_next_us, (uint32_t)n->cfg.telemetry_period_ms * 1000ul, now_us)) {
    protocol_state_t s;
    uint8_t p[PROTOCOL_LEN_STATE];
    nano_core_state(n, &s, now_us);
    protocol_state_pack(&s, p);
    send_frame(n, PROTOCOL_ID_STATE, p, PROTOCOL_LEN_STATE);
  }
}
