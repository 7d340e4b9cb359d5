/* Terrain patches: areas of the floor with a friction of their own (asphalt, dirt, lawn, snow,
 * water). The map lists their geoms in its custom text "terrain_patches" (tools/gen-maps). With
 * the paper tyre model the physics model leaves those geoms out, because MuJoCo 2.2 tests every
 * world geom against every car geom each step, and the tyres read the friction under each
 * ground contact from this table instead; the render model keeps them for the cameras. */
#ifndef SIM_TERRAIN_H
#define SIM_TERRAIN_H

#include <stddef.h>

#include <mujoco/mujoco.h>

#ifdef __cplusplus
extern "C" {
#endif

#define TERRAIN_MAX_PATCHES 32
#define TERRAIN_NAMES_MAX 2048 /* the custom text's length [characters] */

typedef struct terrain_patch {
  double x_m, y_m;           /* centre on the floor */
  double cos_yaw, sin_yaw;   /* heading of the patch's x axis */
  double half_x_m, half_y_m; /* half sizes along its own axes */
  double mu;                 /* sliding friction coefficient */
} terrain_patch_t;

typedef struct terrain {
  int n;
  terrain_patch_t patch[TERRAIN_MAX_PATCHES];
  char names[TERRAIN_NAMES_MAX]; /* the listed geom names, space-separated ("" for none) */
} terrain_t;

/* Reads the patches that map (the map MJCF alone, compiled) lists. A map without the list has
 * none. Returns 0, or -1 with a message naming the file at path and the element. */
int terrain_load(terrain_t *t, const mjModel *map, const char *path, char *err, size_t err_sz);

/* Friction under the ground point (x, y): the last listed patch that covers it, else fallback
 * (the floor's). */
double terrain_mu(const terrain_t *t, double x_m, double y_m, double fallback);

#ifdef __cplusplus
}
#endif
#endif
