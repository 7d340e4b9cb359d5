/* The image rectangles a fixed camera's moving geoms can cover (sim_render_cache.c): each
 * geom's bounding sphere projected and grown by a margin, overlapping ones merged. Internal to
 * the sensors library. */
#ifndef SIM_RENDER_RECTS_H
#define SIM_RENDER_RECTS_H

#include <mujoco/mujoco.h>

#define RENDER_RECTS_MAX 16      /* more groups than this are drawn as their union */
#define RENDER_RECTS_MARGIN_PX 3 /* around a projected sphere: the rasteriser's rounding */

typedef struct render_rect {
  int x, y, w, h; /* [px], OpenGL rows (y from the bottom) */
} render_rect_t;

/* Groups the scene's geoms into rectangles of the w x h image (scn's camera). group[i] is the
 * rectangle of geom i, -1 when it is out of view. A geom with no bound (no model radius, or
 * reaching the near plane) makes the whole image one rectangle. Returns how many (0: none in
 * view). */
int render_rects_group(const mjvScene *scn, int w, int h, render_rect_t rects[RENDER_RECTS_MAX],
                       int *group);

/* cam's frustum narrowed to rect of the w x h image: mjr_render into a viewport of rect's size
 * then draws the image's pixels of rect. */
void render_rects_frustum(mjvGLCamera cam[2], int w, int h, const render_rect_t *rect);

#endif /* SIM_RENDER_RECTS_H */
