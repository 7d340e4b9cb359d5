/* Battery monitor; see batt.h. */
#include "batt.h"

void batt_init(batt_t *b) {
  b->mv_x256 = 0;
  b->have = 0;
  b->low = 0;
  b->cutoff = 0;
}

uint16_t batt_mv(const batt_t *b) {
  return (uint16_t)((b->mv_x256 + 128u) >> 8);
}

void batt_update(batt_t *b, uint16_t raw_mv) {
  uint32_t raw_x256 = (uint32_t)raw_mv << 8;
  uint16_t mv;
  if (!b->have) {
    b->mv_x256 = raw_x256; /* the first sample decides at once: no drive on a flat pack */
    b->have = 1;
  } else if (raw_x256 >= b->mv_x256) {
    b->mv_x256 += (raw_x256 - b->mv_x256) >> BATT_FILTER_SHIFT;
  } else {
    b->mv_x256 -= (b->mv_x256 - raw_x256) >> BATT_FILTER_SHIFT;
  }
  mv = batt_mv(b);
  if (mv < BATT_WARN_MV)
    b->low = 1;
  else if (mv > BATT_WARN_CLEAR_MV)
    b->low = 0;
  if (mv < BATT_CUTOFF_MV)
    b->cutoff = 1;
  else if (mv > BATT_CUTOFF_CLEAR_MV)
    b->cutoff = 0;
}
