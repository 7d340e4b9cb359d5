/* Battery monitor; see battery.h. */
#include "battery.h"

void battery_init(battery_t *b) {
  b->mv_x256 = 0;
  b->have = 0;
  b->low = 0;
  b->cutoff = 0;
}

uint16_t battery_mv(const battery_t *b) {
  return (uint16_t)((b->mv_x256 + 128u) >> 8);
}

void battery_update(battery_t *b, uint16_t raw_mv) {
  uint32_t raw_x256 = (uint32_t)raw_mv << 8;
  uint16_t mv;
  if (!b->have) {
    b->mv_x256 = raw_x256; /* the first sample decides at once: no drive on a flat pack */
    b->have = 1;
  } else if (raw_x256 >= b->mv_x256) {
    b->mv_x256 += (raw_x256 - b->mv_x256) >> BATTERY_FILTER_SHIFT;
  } else {
    b->mv_x256 -= (b->mv_x256 - raw_x256) >> BATTERY_FILTER_SHIFT;
  }
  mv = battery_mv(b);
  if (mv < BATTERY_WARN_MV)
    b->low = 1;
  else if (mv > BATTERY_WARN_CLEAR_MV)
    b->low = 0;
  if (mv < BATTERY_CUTOFF_MV)
    b->cutoff = 1;
  else if (mv > BATTERY_CUTOFF_CLEAR_MV)
    b->cutoff = 0;
}
