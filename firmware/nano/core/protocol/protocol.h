/* Nano <-> Jetson serial protocol: framing, CRC, messages and a byte-wise parser.
 *
 * Portable C99, no Arduino headers: the firmware, the simulator's emulated Nano and the Jetson
 * runtime link this same code. The wire format is documented byte by byte in PROTOCOL.md.
 * Every multi-byte field is little-endian on the wire, whatever the host.
 */
#ifndef AUTODRIVE_PROTOCOL_H
#define AUTODRIVE_PROTOCOL_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/* ---- framing ------------------------------------------------------------------------- */
#define PROTOCOL_SYNC0 0xA5u
#define PROTOCOL_SYNC1 0x5Au
#define PROTOCOL_MAX_PAYLOAD 64u /* [bytes] */
#define PROTOCOL_OVERHEAD 7u     /* sync0 sync1 len id seq .. crc_lo crc_hi [bytes] */
#define PROTOCOL_MAX_FRAME (PROTOCOL_MAX_PAYLOAD + PROTOCOL_OVERHEAD)
#define PROTOCOL_BAUD 500000ul /* [bit/s], exact at 16 MHz (U2X, UBRR=3) */
#define PROTOCOL_VERSION 1u

/* ---- message ids: 0x0_ Jetson -> Nano, 0x8_ Nano -> Jetson --------------------------- */
enum {
  PROTOCOL_ID_COMMAND = 0x01,
  PROTOCOL_ID_CONFIG = 0x02,
  PROTOCOL_ID_HELLO_REQUEST = 0x03,
  PROTOCOL_ID_HELLO = 0x81,
  PROTOCOL_ID_STATE = 0x82,
  PROTOCOL_ID_NACK = 0x84
};

/* Payload lengths [bytes]; a frame whose length differs for its id is rejected. */
#define PROTOCOL_LEN_COMMAND 9u
#define PROTOCOL_LEN_CONFIG 6u
#define PROTOCOL_LEN_HELLO_REQUEST 0u
#define PROTOCOL_LEN_HELLO 12u
#define PROTOCOL_LEN_STATE 60u
#define PROTOCOL_LEN_NACK 4u

/* The schema: every message's fields in wire order. The schema hash (FNV-1a 32 of this
 * string) is sent in HELLO; a host whose hash differs refuses the link. Change the string
 * whenever a layout changes (tests check it against the PROTOCOL_LEN_* above). */
#define PROTOCOL_SCHEMA                                                                    \
  "v1;"                                                                                    \
  "01 command:u16 seq,i16 throttle_milli,i16 steering_milli,u8 headlights,u8 indicators,"  \
  "u8 flags;"                                                                              \
  "02 config:i16 servo_trim_us,u16 telemetry_period_ms,u16 failsafe_timeout_ms;"           \
  "03 hello_request:;"                                                                     \
  "81 hello:u8 fw_major,u8 fw_minor,u8 fw_patch,u8 proto_version,u32 schema_hash,"         \
  "u32 build_id;"                                                                          \
  "82 state:u32 nano_time_us,i32 enc_left,i32 enc_right,i16 speed_left_mrad_s,"            \
  "i16 speed_right_mrad_s,i16 throttle_milli,i16 steering_milli,i16 accel_x,i16 accel_y,"  \
  "i16 accel_z,i16 gyro_x,i16 gyro_y,i16 gyro_z,i16 mag_x,i16 mag_y,i16 mag_z,i16 quat_w," \
  "i16 quat_x,i16 quat_y,i16 quat_z,u16 battery_mv,u8 lights,u8 mode,u16 faults,"          \
  "u16 last_cmd_seq,u16 frames_ok,u16 frames_bad_crc,u16 frames_dropped;"                  \
  "84 nack:u8 rejected_id,u8 reason,u16 seq;"

/* ---- scales of the fixed-point fields ------------------------------------------------ */
#define PROTOCOL_MILLI 1000            /* throttle/steering: 1000 = 1.0 (normalised) */
#define PROTOCOL_ACCEL_LSB_PER_G 8192  /* MPU-9250 at +-4 g */
#define PROTOCOL_GYRO_LSB_PER_DPS 65.5 /* MPU-9250 at +-500 deg/s */
#define PROTOCOL_MAG_UT_PER_LSB 0.15   /* AK8963 16-bit mode [uT/LSB] */
#define PROTOCOL_QUAT_ONE 16384        /* quaternion component 1.0 */

/* ---- command flags, lights bits, modes, faults, nack reasons ------------------------- */
#define PROTOCOL_CMD_ENGAGED 0x01u /* host wants the car to move */
#define PROTOCOL_CMD_KNOWN_FLAGS 0x01u

#define PROTOCOL_LIGHTS_HEAD_MASK 0x03u /* bits 0-1: 0 off, 1 low, 2 high */
#define PROTOCOL_LIGHTS_IND_SHIFT 2u    /* bits 2-3: 0 off, 1 left, 2 right, 3 hazard */
#define PROTOCOL_LIGHTS_IND_MASK 0x0Cu
#define PROTOCOL_LIGHTS_TAIL 0x10u        /* brake/tail lamps lit */
#define PROTOCOL_LIGHTS_REVERSE 0x20u     /* reverse lamps lit */
#define PROTOCOL_LIGHTS_BLINK_LEFT 0x40u  /* left indicator lamp lit right now */
#define PROTOCOL_LIGHTS_BLINK_RIGHT 0x80u /* right indicator lamp lit right now */

enum { PROTOCOL_MODE_DISARMED = 0, PROTOCOL_MODE_ENGAGED = 1, PROTOCOL_MODE_FAILSAFE = 2 };

/* Fault flags: a set bit is a fault, zero means healthy. */
#define PROTOCOL_FAULT_LINK_LOST 0x0001u      /* command stream stopped while engaged (latched) */
#define PROTOCOL_FAULT_CMD_INVALID 0x0002u    /* an out-of-range command arrived (latched) */
#define PROTOCOL_FAULT_IMU_LOST 0x0004u       /* IMU absent or not answering */
#define PROTOCOL_FAULT_BATTERY_LOW 0x0008u    /* below the warning voltage */
#define PROTOCOL_FAULT_BATTERY_CUTOFF 0x0010u /* below cut-off: drive refused */
#define PROTOCOL_FAULT_WATCHDOG_RESET 0x0020u /* last reset came from the watchdog */
#define PROTOCOL_FAULT_LOOP_OVERRUN 0x0040u   /* a main loop pass took too long */

enum {
  PROTOCOL_NACK_BAD_LENGTH = 1,   /* payload length wrong for the id */
  PROTOCOL_NACK_OUT_OF_RANGE = 2, /* a field outside its range: not applied */
  PROTOCOL_NACK_UNKNOWN_ID = 3
};

/* ---- messages ------------------------------------------------------------------------ */
typedef struct protocol_command {
  uint16_t seq;
  int16_t throttle_milli; /* [-1000, 1000], + forward */
  int16_t steering_milli; /* [-1000, 1000], + left; 1000 = 30 deg */
  uint8_t headlights;     /* 0..2 */
  uint8_t indicators;     /* 0..3 */
  uint8_t flags;          /* PROTOCOL_CMD_* */
} protocol_command_t;

typedef struct protocol_config {
  int16_t servo_trim_us;        /* [-200, 200] us added to the servo pulse */
  uint16_t telemetry_period_ms; /* [5, 1000] ms */
  uint16_t failsafe_timeout_ms; /* [20, 150] ms */
} protocol_config_t;

typedef struct protocol_hello {
  uint8_t fw_major, fw_minor, fw_patch;
  uint8_t proto_version;
  uint32_t schema_hash;
  uint32_t build_id;
} protocol_hello_t;

typedef struct protocol_state {
  uint32_t nano_time_us;         /* Nano clock [us], wraps every ~71.6 min */
  int32_t enc_counts[2];         /* left, right [counts], 1920 per wheel revolution */
  int16_t wheel_speed_mrad_s[2]; /* filtered, left, right [mrad/s] */
  int16_t throttle_milli;        /* applied [-1000, 1000] */
  int16_t steering_milli;        /* applied [-1000, 1000] */
  int16_t accel_raw[3];          /* [LSB], PROTOCOL_ACCEL_LSB_PER_G */
  int16_t gyro_raw[3];           /* [LSB], PROTOCOL_GYRO_LSB_PER_DPS */
  int16_t mag_raw[3];            /* [LSB], PROTOCOL_MAG_UT_PER_LSB */
  int16_t quat_q14[4];           /* AHRS w x y z, PROTOCOL_QUAT_ONE = 1.0 */
  uint16_t battery_mv;           /* [mV] */
  uint8_t lights;                /* PROTOCOL_LIGHTS_* */
  uint8_t mode;                  /* PROTOCOL_MODE_* */
  uint16_t faults;               /* PROTOCOL_FAULT_* */
  uint16_t last_cmd_seq;
  uint16_t frames_ok, frames_bad_crc, frames_dropped; /* Nano's parser counts, wrap at 65536 */
} protocol_state_t;

typedef struct protocol_nack {
  uint8_t rejected_id;
  uint8_t reason; /* PROTOCOL_NACK_* */
  uint16_t seq;   /* the rejected command's seq, or 0 */
} protocol_nack_t;

/* Pack writes exactly PROTOCOL_LEN_<msg> bytes. Unpack returns 0, or -1 if len is wrong. */
void protocol_command_pack(const protocol_command_t *m, uint8_t *out);
int protocol_command_unpack(const uint8_t *p, uint8_t len, protocol_command_t *m);
void protocol_config_pack(const protocol_config_t *m, uint8_t *out);
int protocol_config_unpack(const uint8_t *p, uint8_t len, protocol_config_t *m);
void protocol_hello_pack(const protocol_hello_t *m, uint8_t *out);
int protocol_hello_unpack(const uint8_t *p, uint8_t len, protocol_hello_t *m);
void protocol_state_pack(const protocol_state_t *m, uint8_t *out);
int protocol_state_unpack(const uint8_t *p, uint8_t len, protocol_state_t *m);
void protocol_nack_pack(const protocol_nack_t *m, uint8_t *out);
int protocol_nack_unpack(const uint8_t *p, uint8_t len, protocol_nack_t *m);

/* Range checks: 1 when every field is inside its documented range. */
int protocol_command_valid(const protocol_command_t *m);
int protocol_config_valid(const protocol_config_t *m);

/* ---- frames ---------------------------------------------------------------------------- */
/* CRC-16/CCITT-FALSE (poly 0x1021, init 0xFFFF), over len, id, seq and the payload. */
uint16_t protocol_crc16(uint16_t crc, const uint8_t *data, size_t n);

/* Writes one frame to out (capacity cap bytes); returns its size [bytes] or 0 if it does not
 * fit or len > PROTOCOL_MAX_PAYLOAD. */
size_t protocol_frame_encode(uint8_t id, uint8_t seq, const uint8_t *payload, uint8_t len,
                             uint8_t *out, size_t cap);

/* FNV-1a 32 of PROTOCOL_SCHEMA. */
uint32_t protocol_schema_hash(void);

typedef struct protocol_frame {
  uint8_t id;
  uint8_t seq;
  uint8_t len;
  uint8_t payload[PROTOCOL_MAX_PAYLOAD];
} protocol_frame_t;

/* Cumulative parser counters [frames or bytes]. */
typedef struct protocol_stats {
  uint32_t frames_ok;      /* frames with a good CRC */
  uint32_t bad_crc;        /* frames whose CRC failed */
  uint32_t bad_length;     /* length byte above PROTOCOL_MAX_PAYLOAD */
  uint32_t frames_dropped; /* gaps in the sender's seq counter */
  uint32_t skipped_bytes;  /* bytes discarded while hunting for sync */
} protocol_stats_t;

/* Called for each good frame. The frame is only valid during the call. */
typedef void (*protocol_frame_cb)(const protocol_frame_t *frame, void *ctx);

/* Byte-wise parser. After a bad frame it rescans the bytes it had buffered, so a real
 * frame hidden inside a corrupted one is still found. */
typedef struct protocol_parser {
  uint8_t buf[PROTOCOL_MAX_FRAME]; /* bytes of the frame being assembled, from sync0 */
  uint8_t n;                       /* bytes in buf */
  uint8_t have_seq;                /* a previous seq is known */
  uint8_t last_seq;
  protocol_stats_t stats;
} protocol_parser_t;

void protocol_parser_init(protocol_parser_t *p);
/* Feeds n bytes; calls cb for each complete good frame. Returns the number of good frames. */
unsigned protocol_parser_feed(protocol_parser_t *p, const uint8_t *data, size_t n,
                              protocol_frame_cb cb, void *ctx);

#ifdef __cplusplus
}
#endif
#endif /* AUTODRIVE_PROTOCOL_H */
