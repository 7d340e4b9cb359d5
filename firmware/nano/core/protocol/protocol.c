/* Serial protocol codec; see protocol.h and PROTOCOL.md. */
#include "protocol.h"

#include <string.h>

/* ---- little-endian field writers/readers -------------------------------------------- */
static uint8_t *put_u8(uint8_t *o, uint8_t v) {
  *o = v;
  return o + 1;
}
static uint8_t *put_u16(uint8_t *o, uint16_t v) {
  o[0] = (uint8_t)(v & 0xFFu);
  o[1] = (uint8_t)(v >> 8);
  return o + 2;
}
static uint8_t *put_i16(uint8_t *o, int16_t v) {
  return put_u16(o, (uint16_t)v);
}
static uint8_t *put_u32(uint8_t *o, uint32_t v) {
  o = put_u16(o, (uint16_t)(v & 0xFFFFu));
  return put_u16(o, (uint16_t)(v >> 16));
}
static uint8_t *put_i32(uint8_t *o, int32_t v) {
  return put_u32(o, (uint32_t)v);
}

static const uint8_t *get_u8(const uint8_t *p, uint8_t *v) {
  *v = p[0];
  return p + 1;
}
static const uint8_t *get_u16(const uint8_t *p, uint16_t *v) {
  *v = (uint16_t)((uint16_t)p[0] | (uint16_t)((uint16_t)p[1] << 8));
  return p + 2;
}
static const uint8_t *get_i16(const uint8_t *p, int16_t *v) {
  uint16_t u;
  p = get_u16(p, &u);
  *v = (int16_t)u;
  return p;
}
static const uint8_t *get_u32(const uint8_t *p, uint32_t *v) {
  uint16_t lo, hi;
  p = get_u16(p, &lo);
  p = get_u16(p, &hi);
  *v = (uint32_t)lo | ((uint32_t)hi << 16);
  return p;
}
static const uint8_t *get_i32(const uint8_t *p, int32_t *v) {
  uint32_t u;
  p = get_u32(p, &u);
  *v = (int32_t)u;
  return p;
}

/* ---- messages -------------------------------------------------------------------------- */
void protocol_command_pack(const protocol_command_t *m, uint8_t *o) {
  o = put_u16(o, m->seq);
  o = put_i16(o, m->throttle_milli);
  o = put_i16(o, m->steering_milli);
  o = put_u8(o, m->headlights);
  o = put_u8(o, m->indicators);
  put_u8(o, m->flags);
}
int protocol_command_unpack(const uint8_t *p, uint8_t len, protocol_command_t *m) {
  if (len != PROTOCOL_LEN_COMMAND) return -1;
  p = get_u16(p, &m->seq);
  p = get_i16(p, &m->throttle_milli);
  p = get_i16(p, &m->steering_milli);
  p = get_u8(p, &m->headlights);
  p = get_u8(p, &m->indicators);
  get_u8(p, &m->flags);
  return 0;
}

void protocol_config_pack(const protocol_config_t *m, uint8_t *o) {
  o = put_i16(o, m->servo_trim_us);
  o = put_u16(o, m->telemetry_period_ms);
  put_u16(o, m->failsafe_timeout_ms);
}
int protocol_config_unpack(const uint8_t *p, uint8_t len, protocol_config_t *m) {
  if (len != PROTOCOL_LEN_CONFIG) return -1;
  p = get_i16(p, &m->servo_trim_us);
  p = get_u16(p, &m->telemetry_period_ms);
  get_u16(p, &m->failsafe_timeout_ms);
  return 0;
}

void protocol_hello_pack(const protocol_hello_t *m, uint8_t *o) {
  o = put_u8(o, m->fw_major);
  o = put_u8(o, m->fw_minor);
  o = put_u8(o, m->fw_patch);
  o = put_u8(o, m->proto_version);
  o = put_u32(o, m->schema_hash);
  put_u32(o, m->build_id);
}
int protocol_hello_unpack(const uint8_t *p, uint8_t len, protocol_hello_t *m) {
  if (len != PROTOCOL_LEN_HELLO) return -1;
  p = get_u8(p, &m->fw_major);
  p = get_u8(p, &m->fw_minor);
  p = get_u8(p, &m->fw_patch);
  p = get_u8(p, &m->proto_version);
  p = get_u32(p, &m->schema_hash);
  get_u32(p, &m->build_id);
  return 0;
}

void protocol_state_pack(const protocol_state_t *m, uint8_t *o) {
  int i;
  o = put_u32(o, m->nano_time_us);
  o = put_i32(o, m->enc_counts[0]);
  o = put_i32(o, m->enc_counts[1]);
  o = put_i16(o, m->wheel_speed_mrad_s[0]);
  o = put_i16(o, m->wheel_speed_mrad_s[1]);
  o = put_i16(o, m->throttle_milli);
  o = put_i16(o, m->steering_milli);
  for (i = 0; i < 3; ++i) o = put_i16(o, m->accel_raw[i]);
  for (i = 0; i < 3; ++i) o = put_i16(o, m->gyro_raw[i]);
  for (i = 0; i < 3; ++i) o = put_i16(o, m->mag_raw[i]);
  for (i = 0; i < 4; ++i) o = put_i16(o, m->quat_q14[i]);
  o = put_u16(o, m->battery_mv);
  o = put_u8(o, m->lights);
  o = put_u8(o, m->mode);
  o = put_u16(o, m->faults);
  o = put_u16(o, m->last_cmd_seq);
  o = put_u16(o, m->frames_ok);
  o = put_u16(o, m->frames_bad_crc);
  put_u16(o, m->frames_dropped);
}
int protocol_state_unpack(const uint8_t *p, uint8_t len, protocol_state_t *m) {
  int i;
  if (len != PROTOCOL_LEN_STATE) return -1;
  p = get_u32(p, &m->nano_time_us);
  p = get_i32(p, &m->enc_counts[0]);
  p = get_i32(p, &m->enc_counts[1]);
  p = get_i16(p, &m->wheel_speed_mrad_s[0]);
  p = get_i16(p, &m->wheel_speed_mrad_s[1]);
  p = get_i16(p, &m->throttle_milli);
  p = get_i16(p, &m->steering_milli);
  for (i = 0; i < 3; ++i) p = get_i16(p, &m->accel_raw[i]);
  for (i = 0; i < 3; ++i) p = get_i16(p, &m->gyro_raw[i]);
  for (i = 0; i < 3; ++i) p = get_i16(p, &m->mag_raw[i]);
  for (i = 0; i < 4; ++i) p = get_i16(p, &m->quat_q14[i]);
  p = get_u16(p, &m->battery_mv);
  p = get_u8(p, &m->lights);
  p = get_u8(p, &m->mode);
  p = get_u16(p, &m->faults);
  p = get_u16(p, &m->last_cmd_seq);
  p = get_u16(p, &m->frames_ok);
  p = get_u16(p, &m->frames_bad_crc);
  get_u16(p, &m->frames_dropped);
  return 0;
}

void protocol_nack_pack(const protocol_nack_t *m, uint8_t *o) {
  o = put_u8(o, m->rejected_id);
  o = put_u8(o, m->reason);
  put_u16(o, m->seq);
}
int protocol_nack_unpack(const uint8_t *p, uint8_t len, protocol_nack_t *m) {
  if (len != PROTOCOL_LEN_NACK) return -1;
  p = get_u8(p, &m->rejected_id);
  p = get_u8(p, &m->reason);
  get_u16(p, &m->seq);
  return 0;
}

int protocol_command_valid(const protocol_command_t *m) {
  return m->throttle_milli >= -PROTOCOL_MILLI && m->throttle_milli <= PROTOCOL_MILLI &&
         m->steering_milli >= -PROTOCOL_MILLI && m->steering_milli <= PROTOCOL_MILLI &&
         m->headlights <= 2u && m->indicators <= 3u &&
         (m->flags & (uint8_t)~PROTOCOL_CMD_KNOWN_FLAGS) == 0u;
}

int protocol_config_valid(const protocol_config_t *m) {
  return m->servo_trim_us >= -200 && m->servo_trim_us <= 200 && m->telemetry_period_ms >= 5u &&
         m->telemetry_period_ms <= 1000u && m->failsafe_timeout_ms >= 20u &&
         m->failsafe_timeout_ms <= 150u;
}

/* ---- frames ---------------------------------------------------------------------------- */
uint16_t protocol_crc16(uint16_t crc, const uint8_t *data, size_t n) {
  size_t i;
  for (i = 0; i < n; ++i) {
    /* Byte-at-a-time form of the bitwise MSB-first division by 0x1021 (same result as
     * 8 shift/xor steps, ~6x fewer cycles on the AVR, no table in RAM or flash):
     * with x = top byte ^ data and x ^= x >> 4, the remainder is x*(x^12 + x^5 + 1). */
    uint8_t x = (uint8_t)((crc >> 8) ^ data[i]);
    x ^= (uint8_t)(x >> 4);
    crc = (uint16_t)((uint16_t)(crc << 8) ^ (uint16_t)((uint16_t)x << 12) ^
                     (uint16_t)((uint16_t)x << 5) ^ (uint16_t)x);
  }
  return crc;
}

size_t protocol_frame_encode(uint8_t id, uint8_t seq, const uint8_t *payload, uint8_t len,
                             uint8_t *out, size_t cap) {
  size_t total = (size_t)len + PROTOCOL_OVERHEAD;
  uint16_t crc;
  if (len > PROTOCOL_MAX_PAYLOAD || cap < total) return 0;
  out[0] = PROTOCOL_SYNC0;
  out[1] = PROTOCOL_SYNC1;
  out[2] = len;
  out[3] = id;
  out[4] = seq;
  if (len) memcpy(out + 5, payload, len);
  crc = protocol_crc16(0xFFFFu, out + 2, (size_t)len + 3u);
  put_u16(out + 5 + len, crc);
  return total;
}

#ifdef __AVR__
/* On the AVR the ~900-byte schema string stays in flash, not in the 2 KiB of RAM. */
#include <avr/pgmspace.h>
static const char schema_text[] PROGMEM = PROTOCOL_SCHEMA;
#define SCHEMA_BYTE(i) ((uint8_t)pgm_read_byte(&schema_text[i]))
#else
static const char schema_text[] = PROTOCOL_SCHEMA;
#define SCHEMA_BYTE(i) ((uint8_t)schema_text[i])
#endif

static uint32_t schema_fnv1a(void) {
  uint32_t h = 2166136261ul;
  size_t i;
  for (i = 0; i + 1u < sizeof schema_text; ++i) {
    h ^= SCHEMA_BYTE(i);
    h *= 16777619ul;
  }
  return h;
}

#ifdef __AVR__
/* Cached on the AVR: hashing ~900 flash bytes costs ~4.5 ms, too long for every HELLO. The
 * firmware is single-threaded, so a plain static is safe there (not on a threaded host). */
uint32_t protocol_schema_hash(void) {
  static uint32_t cached;
  static uint8_t have;
  if (!have) {
    cached = schema_fnv1a();
    have = 1;
  }
  return cached;
}
#else
uint32_t protocol_schema_hash(void) {
  return schema_fnv1a();
}
#endif

/* ---- parser ---------------------------------------------------------------------------- */
void protocol_parser_init(protocol_parser_t *p) {
  memset(p, 0, sizeof *p);
}

static void drop_front(protocol_parser_t *p, uint8_t k) {
  memmove(p->buf, p->buf + k, (size_t)(p->n - k));
  p->n = (uint8_t)(p->n - k);
}

/* Consumes what it can of buf; returns the number of good frames dispatched. */
static unsigned scan(protocol_parser_t *p, protocol_frame_cb cb, void *ctx) {
  unsigned good = 0;
  for (;;) {
    uint8_t i = 0, len, total;
    uint16_t crc_rx, crc;
    while (i < p->n && p->buf[i] != PROTOCOL_SYNC0) ++i;
    p->stats.skipped_bytes += i;
    if (i) drop_front(p, i);
    if (p->n < 2u) return good;
    if (p->buf[1] != PROTOCOL_SYNC1) {
      ++p->stats.skipped_bytes;
      drop_front(p, 1);
      continue;
    }
    if (p->n < 3u) return good;
    len = p->buf[2];
    if (len > PROTOCOL_MAX_PAYLOAD) {
      ++p->stats.bad_length;
      ++p->stats.skipped_bytes;
      drop_front(p, 1);
      continue;
    }
    total = (uint8_t)(len + PROTOCOL_OVERHEAD);
    if (p->n < total) return good;
    crc = protocol_crc16(0xFFFFu, p->buf + 2, (size_t)len + 3u);
    crc_rx = (uint16_t)((uint16_t)p->buf[5 + len] | (uint16_t)((uint16_t)p->buf[6 + len] << 8));
    if (crc != crc_rx) {
      /* Drop only the sync byte: a real frame may start inside the bad one. */
      ++p->stats.bad_crc;
      ++p->stats.skipped_bytes;
      drop_front(p, 1);
      continue;
    }
    {
      protocol_frame_t f;
      f.id = p->buf[3];
      f.seq = p->buf[4];
      f.len = len;
      memcpy(f.payload, p->buf + 5, len);
      if (p->have_seq) p->stats.frames_dropped += (uint8_t)(f.seq - p->last_seq - 1u);
      p->have_seq = 1;
      p->last_seq = f.seq;
      ++p->stats.frames_ok;
      ++good;
      drop_front(p, total);
      if (cb) cb(&f, ctx);
    }
  }
}

unsigned protocol_parser_feed(protocol_parser_t *p, const uint8_t *data, size_t n,
                              protocol_frame_cb cb, void *ctx) {
  unsigned good = 0;
  size_t k;
  for (k = 0; k < n; ++k) {
    /* buf never holds a complete frame after scan(), so one more byte always fits. */
    p->buf[p->n++] = data[k];
    if (p->buf[0] == PROTOCOL_SYNC0 && p->n < 3u) continue; /* fast path while in a header */
    good += scan(p, cb, ctx);
  }
  return good;
}
