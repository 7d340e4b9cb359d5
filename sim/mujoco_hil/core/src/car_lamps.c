/* A car's lamps (sim_internal.h): the lamp geoms of the render model, coloured from the
 * firmware's lamp outputs (headlights, indicators, tail and reverse lights). */
#include <stdio.h>

#include "sim_internal.h"

static const struct {
  const char *name;
  uint8_t bits;
  float on[3], off[3];
} sim_lamp[SIM_LAMPS] = {
    /* each lamp geom, the NANO_CORE_LAMP_* bits and colours that drive it */
    {"lamp_head_l",
     NANO_CORE_LAMP_HEAD_LOW | NANO_CORE_LAMP_HEAD_HIGH,
     {1, 1, 0.85f},
     {0.25f, 0.25f, 0.22f}},
    {"lamp_head_r",
     NANO_CORE_LAMP_HEAD_LOW | NANO_CORE_LAMP_HEAD_HIGH,
     {1, 1, 0.85f},
     {0.25f, 0.25f, 0.22f}},
    {"lamp_ind_fl", NANO_CORE_LAMP_IND_LEFT, {1, 0.55f, 0}, {0.3f, 0.18f, 0.05f}},
    {"lamp_ind_fr", NANO_CORE_LAMP_IND_RIGHT, {1, 0.55f, 0}, {0.3f, 0.18f, 0.05f}},
    {"lamp_tail_l", NANO_CORE_LAMP_TAIL, {1, 0, 0}, {0.3f, 0.02f, 0.02f}},
    {"lamp_tail_r", NANO_CORE_LAMP_TAIL, {1, 0, 0}, {0.3f, 0.02f, 0.02f}},
    {"lamp_ind_rl", NANO_CORE_LAMP_IND_LEFT, {1, 0.55f, 0}, {0.3f, 0.18f, 0.05f}},
    {"lamp_ind_rr", NANO_CORE_LAMP_IND_RIGHT, {1, 0.55f, 0}, {0.3f, 0.18f, 0.05f}},
    {"lamp_reverse", NANO_CORE_LAMP_REVERSE, {1, 1, 1}, {0.25f, 0.25f, 0.25f}},
};
/* Colours the lamp geoms when the firmware's lamp outputs change. */
void sim_draw_lamps(sim_t *s, sim_car_t *c) {
  if (c->lamps == c->lamps_shown) return;
  c->lamps_shown = c->lamps;
  for (int k = 0; k < SIM_LAMPS; k++) {
    if (c->lamp_geom[k] < 0) continue;
    const float *rgb = (c->lamps & sim_lamp[k].bits) ? sim_lamp[k].on : sim_lamp[k].off;
    float *dst = (s->mv ? s->mv : s->m)->geom_rgba + 4 * c->lamp_geom[k];
    dst[0] = rgb[0];
    dst[1] = rgb[1];
    dst[2] = rgb[2];
  }
}

/* The lamp geoms are optional: older scenes may lack them. They are drawn in the render model. */
void sim_bind_lamps(sim_t *s, sim_car_t *c) {
  for (int k = 0; k < SIM_LAMPS; k++) {
    char name[64];
    snprintf(name, sizeof name, "nigel%d/%s", c->index, sim_lamp[k].name);
    c->lamp_geom[k] = mj_name2id(s->mv ? s->mv : s->m, mjOBJ_GEOM, name);
  }
  c->lamps_shown = 0xFF; /* draw on the first step */
}
