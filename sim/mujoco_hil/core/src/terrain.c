#include "terrain.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#define TERRAIN_LIST_TEXT "terrain_patches"
#define TERRAIN_FLAT_TOL 1e-6 /* a patch may turn about z only [quaternion x, y parts] */

static int terrain_add(terrain_t *t, const mjModel *m, const char *name, const char *path,
                       char *err, size_t err_sz) {
  const int g = mj_name2id(m, mjOBJ_GEOM, name);
  if (g < 0) {
    snprintf(err, err_sz, "map file '%s': custom text '%s' names '%s', which is not a geom", path,
             TERRAIN_LIST_TEXT, name);
    return -1;
  }
  const mjtNum *q = m->geom_quat + 4 * g;
  if (m->geom_bodyid[g] != 0 || m->geom_type[g] != mjGEOM_BOX || fabs(q[1]) > TERRAIN_FLAT_TOL ||
      fabs(q[2]) > TERRAIN_FLAT_TOL) {
    snprintf(err, err_sz,
             "map file '%s': terrain patch '%s' must be a box on the world body, turned about z "
             "only",
             path, name);
    return -1;
  }
  if (t->n >= TERRAIN_MAX_PATCHES) {
    snprintf(err, err_sz, "map file '%s': more than %d terrain patches", path, TERRAIN_MAX_PATCHES);
    return -1;
  }
  const double yaw = 2.0 * atan2(q[3], q[0]);
  terrain_patch_t *p = &t->patch[t->n++];
  p->x_m = m->geom_pos[3 * g];
  p->y_m = m->geom_pos[3 * g + 1];
  p->cos_yaw = cos(yaw);
  p->sin_yaw = sin(yaw);
  p->half_x_m = m->geom_size[3 * g];
  p->half_y_m = m->geom_size[3 * g + 1];
  p->mu = m->geom_friction[3 * g];
  return 0;
}

int terrain_load(terrain_t *t, const mjModel *map, const char *path, char *err, size_t err_sz) {
  memset(t, 0, sizeof *t);
  const int id = mj_name2id(map, mjOBJ_TEXT, TERRAIN_LIST_TEXT);
  if (id < 0) return 0;
  const char *list = map->text_data + map->text_adr[id];
  if (strlen(list) >= sizeof t->names) {
    snprintf(err, err_sz, "map file '%s': custom text '%s' is longer than %d characters", path,
             TERRAIN_LIST_TEXT, TERRAIN_NAMES_MAX - 1);
    return -1;
  }
  snprintf(t->names, sizeof t->names, "%s", list);
  char name[256];
  for (const char *w = list; *w;) {
    w += strspn(w, " ");
    const size_t k = strcspn(w, " ");
    if (k == 0) break;
    if (k >= sizeof name) {
      snprintf(err, err_sz, "map file '%s': a name in custom text '%s' is too long", path,
               TERRAIN_LIST_TEXT);
      return -1;
    }
    memcpy(name, w, k);
    name[k] = '\0';
    if (terrain_add(t, map, name, path, err, err_sz) != 0) return -1;
    w += k;
  }
  return 0;
}

double terrain_mu(const terrain_t *t, double x_m, double y_m, double fallback) {
  double mu = fallback;
  for (int i = 0; i < t->n; i++) {
    const terrain_patch_t *p = &t->patch[i];
    const double dx = x_m - p->x_m, dy = y_m - p->y_m;
    const double u = p->cos_yaw * dx + p->sin_yaw * dy, v = -p->sin_yaw * dx + p->cos_yaw * dy;
    if (fabs(u) <= p->half_x_m && fabs(v) <= p->half_y_m) mu = p->mu;
  }
  return mu;
}
