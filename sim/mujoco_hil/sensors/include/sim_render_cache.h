/* sim_render_cache: a fixed camera's static world rendered once, the moving geoms drawn over it.
 *
 * An overhead Eye camera sees a town that does not move: floor tiles, walls, signs, poles. Only
 * the cars (and world geoms whose pose or colour changes: traffic-light lamps, late boxes)
 * differ between frames. Software OpenGL spends most of a 1280x960 frame texturing the town,
 * so the cache renders the world geoms (those of bodies welded to the world) once into colour
 * and depth, then per frame renders only the other geoms, each group of them in the image
 * rectangle their bounding spheres can cover (a frustum narrowed to it), and keeps a moving
 * geom's pixel where it is nearer than the cached depth. The last frame's rectangles are put
 * back from the cached image first, so a frame costs what its moving geoms cover.
 *
 * The cached image is rebuilt whenever what it shows would change: a world geom's pose, size,
 * colour, emission or material, a light (day/night, --light-level), the camera, a texture
 * upload. A world geom seen to change once is drawn every frame from then on (a lamp that
 * blinks costs one rebuild, not one per blink). A scene with a transparent geom is rendered in
 * full (blending needs what lies behind). The result equals sim_render_camera's full render but
 * for a few edge pixels of the moving geoms (the narrowed frustum rounds a vertex differently;
 * a depth tie where a wheel touches the floor): about 5e-6 of the pixels; tests/sim:
 * sim.EyeRenderCache.* holds it to at most 1e-4 per frame. */
#ifndef SIM_RENDER_CACHE_H
#define SIM_RENDER_CACHE_H

#include <stddef.h>
#include <stdint.h>

#include <mujoco/mujoco.h>

#include "sim_render.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct sim_render_cache sim_render_cache_t;

typedef struct sim_render_cache_stats {
  long frames;   /* frames rendered through the cache */
  long rebuilds; /* static image rendered again (the first frame, a world geom or light changed) */
  long full;     /* frames rendered in full (a transparent geom in the scene) */
  int promoted;  /* world geoms seen to change, drawn every frame since */
} sim_render_cache_stats_t;

/* 1 if camera cam_id of m is fixed in the world (mode fixed, its body welded to the world):
 * only then has it a static world to cache. */
int sim_render_cache_applies(const mjModel *m, int cam_id);

/* A cache for camera cam_id of m at width_px x height_px. Returns NULL with a message in err
 * if the camera is not fixed in the world, or out of memory. Caller owns the result. */
sim_render_cache_t *sim_render_cache_create(const mjModel *m, int cam_id, int width_px,
                                            int height_px, char *err, size_t err_len);
void sim_render_cache_destroy(sim_render_cache_t *c);

/* Renders the cache's camera for state d into rgb (width * height * 3 bytes, rows top-down),
 * as sim_render_camera does; rgb NULL: only into the cache's own frame (no copy). r must be
 * the renderer every call on this cache uses. Returns 0, or -1 if the size does not fit r's
 * buffer, the GL context is lost or memory is out. */
int sim_render_camera_cached(sim_render_t *r, sim_render_cache_t *c, const mjModel *m, mjData *d,
                             uint8_t *rgb);
/* The last frame (rows top-down). Borrowed: valid until the next call on c. */
const uint8_t *sim_render_cache_image(const sim_render_cache_t *c);

void sim_render_cache_get_stats(const sim_render_cache_t *c, sim_render_cache_stats_t *st);

#ifdef __cplusplus
}
#endif
#endif /* SIM_RENDER_CACHE_H */
