/* Traffic lights (see traffic_lights.h). */
#include "traffic_lights.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

static const char *tl_colour[3] = {"red", "yellow", "green"};
/* Lit lamp looks [rgba], emission 1: bright and saturated in any light level. */
static const float tl_lit_rgba[3][4] = {
    {1.0f, 0.05f, 0.02f, 1}, {1.0f, 0.75f, 0.0f, 1}, {0.1f, 1.0f, 0.25f, 1}};

const char *tl_state_name(int state) {
  switch (state) {
    case TL_OFF: return "OFF";
    case TL_RED: return "RED";
    case TL_YELLOW: return "YELLOW";
    case TL_GREEN: return "GREEN";
    default: return "?";
  }
}

static const char *tl_name(const mjModel *m, int adr) {
  return m->names + adr;
}

int tl_find(const traffic_lights_t *t, int id) {
  for (int i = 0; i < t->n; i++)
    if (t->light[i].id == id) return i;
  return -1;
}

static int tl_bind_lamps(tl_light_t *l, const mjModel *m, char *err, size_t err_sz) {
  for (int k = 0; k < 3; k++) {
    char name[64];
    snprintf(name, sizeof name, "tl%d_lamp_%s_mat", l->id, tl_colour[k]);
    l->lamp_mat[k] = mj_name2id(m, mjOBJ_MATERIAL, name);
    if (l->lamp_mat[k] < 0) {
      snprintf(err, err_sz, "traffic light %d: the map has no material '%s'", l->id, name);
      return -1;
    }
    memcpy(l->off_rgba[k], m->mat_rgba + 4 * l->lamp_mat[k], sizeof l->off_rgba[k]);
    l->off_emission[k] = m->mat_emission[l->lamp_mat[k]];
    snprintf(name, sizeof name, "tl%d_lamp_%s", l->id, tl_colour[k]);
    l->lamp_geom[k] = mj_name2id(m, mjOBJ_GEOM, name); /* optional: the material suffices */
  }
  return 0;
}

int tl_load(traffic_lights_t *t, const mjModel *m, char *err, size_t err_sz) {
  memset(t, 0, sizeof *t);
  for (int i = 0; i < m->nnumeric; i++) {
    const char *name = tl_name(m, m->name_numericadr[i]);
    int id = 0, end = 0;
    if (sscanf(name, "tl%d_program%n", &id, &end) != 1 || name[end] != '\0') continue;
    const mjtNum *v = m->numeric_data + m->numeric_adr[i];
    if (m->numeric_size[i] != 4 || id < 1 || !(v[0] > 0) || v[2] < 0 || v[3] < 0 ||
        v[2] + v[3] > v[0]) {
      snprintf(err, err_sz,
               "numeric '%s': expected 'cycle_s offset_s green_s yellow_s' with cycle > 0, id >= "
               "1 and green + yellow <= cycle (%d values)",
               name, m->numeric_size[i]);
      return -1;
    }
    if (tl_find(t, id) >= 0 || t->n == TL_MAX_LIGHTS) {
      snprintf(err, err_sz, "numeric '%s': light id %d repeated, or more than %d lights", name, id,
               TL_MAX_LIGHTS);
      return -1;
    }
    tl_light_t *l = &t->light[t->n++];
    l->id = id;
    l->cycle_s = v[0];
    l->offset_s = v[1];
    l->green_s = v[2];
    l->yellow_s = v[3];
    l->state = l->drawn_state = -1; /* the first tl_update reports every light as changed */
    if (tl_bind_lamps(l, m, err, err_sz) != 0) return -1;
  }
  const int c = mj_name2id(m, mjOBJ_NUMERIC, "tl_conflicts");
  if (c >= 0) {
    const int sz = m->numeric_size[c];
    const mjtNum *v = m->numeric_data + m->numeric_adr[c];
    if (sz % 2 != 0 || sz / 2 > TL_MAX_CONFLICTS) {
      snprintf(err, err_sz, "numeric 'tl_conflicts': expected pairs of light ids (%d values)", sz);
      return -1;
    }
    for (int k = 0; k < sz / 2; k++) {
      const int a = (int)lround(v[2 * k]), b = (int)lround(v[2 * k + 1]);
      if (tl_find(t, a) < 0 || tl_find(t, b) < 0 || a == b) {
        snprintf(err, err_sz, "numeric 'tl_conflicts': pair %d (%d, %d) names no two lights", k + 1,
                 a, b);
        return -1;
      }
      t->conflict[k][0] = a;
      t->conflict[k][1] = b;
    }
    t->nconflicts = sz / 2;
  }
  return 0;
}

int tl_program_state(const tl_light_t *l, double t_s, double *remaining_s) {
  const double u = fmod(fmod(t_s - l->offset_s, l->cycle_s) + l->cycle_s, l->cycle_s);
  int st;
  double left;
  if (u < l->green_s) {
    st = TL_GREEN;
    left = l->green_s - u;
  } else if (u < l->green_s + l->yellow_s) {
    st = TL_YELLOW;
    left = l->green_s + l->yellow_s - u;
  } else {
    st = TL_RED;
    left = l->cycle_s - u;
  }
  if (remaining_s) *remaining_s = left;
  return st;
}

static int tl_non_red(int state) {
  return state == TL_GREEN || state == TL_YELLOW;
}

/* 1 if lights a and b (ids) conflict. */
static int tl_conflict(const traffic_lights_t *t, int a, int b) {
  for (int k = 0; k < t->nconflicts; k++)
    if ((t->conflict[k][0] == a && t->conflict[k][1] == b) ||
        (t->conflict[k][0] == b && t->conflict[k][1] == a))
      return 1;
  return 0;
}

int tl_update(traffic_lights_t *t, int64_t now_us) {
  const double now_s = now_us * 1e-6;
  int want[TL_MAX_LIGHTS];
  double left[TL_MAX_LIGHTS];
  for (int i = 0; i < t->n; i++) {
    tl_light_t *l = &t->light[i];
    if (l->held && now_us >= l->hold_until_us) l->held = 0; /* back to its program */
    if (l->held) {
      want[i] = l->held_state;
      left[i] = l->hold_until_us == TL_HOLD_FOREVER ? -1.0 : (l->hold_until_us - now_us) * 1e-6;
    } else {
      want[i] = tl_program_state(l, now_s, &left[i]);
    }
  }
  /* a light on its program yields to a conflicting light held non-red by a command */
  for (int i = 0; i < t->n; i++) {
    if (t->light[i].held || !tl_non_red(want[i])) continue;
    for (int j = 0; j < t->n; j++)
      if (t->light[j].held && tl_non_red(want[j]) &&
          tl_conflict(t, t->light[i].id, t->light[j].id)) {
        want[i] = TL_RED;
        left[i] = -1.0;
        break;
      }
  }
  int changed = 0;
  for (int i = 0; i < t->n; i++) {
    tl_light_t *l = &t->light[i];
    l->changed = want[i] != l->state;
    changed += l->changed;
    l->state = want[i];
    l->remaining_s = left[i];
  }
  return changed;
}

int tl_command(traffic_lights_t *t, int id, int state, double duration_s, int64_t now_us, char *why,
               size_t why_sz) {
  const int i = tl_find(t, id);
  if (i < 0) {
    snprintf(why, why_sz, "no traffic light %d on this map (%d lights)", id, t->n);
    return -1;
  }
  if (state < TL_OFF || state > TL_GREEN || !isfinite(duration_s)) {
    snprintf(why, why_sz,
             "light %d: state %d is not OFF/RED/YELLOW/GREEN (0..3) or duration %g s "
             "is not finite",
             id, state, duration_s);
    return -1;
  }
  if (tl_non_red(state)) {
    for (int j = 0; j < t->n; j++) {
      const tl_light_t *o = &t->light[j];
      if (j != i && tl_non_red(o->state) && tl_conflict(t, id, o->id)) {
        snprintf(why, why_sz,
                 "light %d -> %s refused: conflicting light %d is %s (tl_conflicts %d %d)", id,
                 tl_state_name(state), o->id, tl_state_name(o->state), id, o->id);
        return -1;
      }
    }
  }
  tl_light_t *l = &t->light[i];
  l->held = 1;
  l->held_state = state;
  l->hold_until_us = duration_s > 0 ? now_us + (int64_t)llround(duration_s * 1e6) : TL_HOLD_FOREVER;
  return 0;
}

void tl_draw(traffic_lights_t *t, mjModel *m) {
  for (int i = 0; i < t->n; i++) {
    tl_light_t *l = &t->light[i];
    if (l->drawn_state == l->state) continue;
    l->drawn_state = l->state;
    for (int k = 0; k < 3; k++) {
      const int lit = l->state == TL_RED + k; /* red 1, yellow 2, green 3 */
      const float *rgba = lit ? tl_lit_rgba[k] : l->off_rgba[k];
      const int mat = l->lamp_mat[k];
      memcpy(m->mat_rgba + 4 * mat, rgba, 4 * sizeof(float));
      m->mat_emission[mat] = lit ? 1.0f : l->off_emission[k];
      /* a geom with its own rgba ignores the material's colour: keep both the same */
      if (l->lamp_geom[k] >= 0) memcpy(m->geom_rgba + 4 * l->lamp_geom[k], rgba, 4 * sizeof(float));
    }
  }
}
