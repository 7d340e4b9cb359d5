/* Battery monitor for the 3S LiPo: a low-pass filtered voltage, a warning and a cut-off
 * threshold, each with hysteresis. Below cut-off the core refuses to drive. */
#ifndef AUTODRIVE_BATTERY_H
#define AUTODRIVE_BATTERY_H

#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

#define BATTERY_WARN_MV 10500u         /* [mV] 3.50 V/cell: warning on below this */
#define BATTERY_WARN_CLEAR_MV 10800u   /* [mV] warning off again above this */
#define BATTERY_CUTOFF_MV 9900u        /* [mV] 3.30 V/cell: drive refused below this */
#define BATTERY_CUTOFF_CLEAR_MV 10500u /* [mV] drive allowed again above this */
#define BATTERY_PERIOD_US 10000ul      /* [us] sampling period */
#define BATTERY_FILTER_SHIFT 3u        /* IIR weight 1/8 per sample: ~80 ms time constant */

typedef struct battery {
  uint32_t mv_x256; /* filtered voltage [mV / 256] */
  uint8_t have;     /* a first sample was taken */
  uint8_t low;      /* PROTOCOL_FAULT_BATTERY_LOW */
  uint8_t cutoff;   /* PROTOCOL_FAULT_BATTERY_CUTOFF */
} battery_t;

void battery_init(battery_t *b);
void battery_update(battery_t *b, uint16_t raw_mv);
uint16_t battery_mv(const battery_t *b); /* filtered [mV] */

#ifdef __cplusplus
}
#endif
#endif
