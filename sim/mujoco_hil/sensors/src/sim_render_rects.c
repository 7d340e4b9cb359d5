/* The image rectangles of a fixed camera's moving geoms (sim_render_rects.h). */
#include "sim_render_rects.h"

#include <math.h>

/* The image span [lo, hi] of a/z over a sphere at (a, z) of radius rad (z - rad > 0), from the
 * box around it: a/z is extreme at the box's corners. */
static void rects_sphere_span(double a, double z, double rad, double *lo, double *hi) {
  *hi = (a + rad) / (a + rad >= 0 ? z - rad : z + rad);
  *lo = (a - rad) / (a - rad <= 0 ? z - rad : z + rad);
}

/* A geom's bounding radius [m]: the model's, else (decor: sites, frames) one its size bounds;
 * 0 for a plane, mesh or height field without one. */
static double rects_radius(const mjvGeom *g) {
  if (g->modelrbound > 0) return g->modelrbound;
  switch (g->type) {
    case mjGEOM_SPHERE:
    case mjGEOM_CAPSULE:
    case mjGEOM_ELLIPSOID:
    case mjGEOM_CYLINDER:
    case mjGEOM_BOX: /* |s0| + |s1| + |s2| bounds each of them */
      return fabs(g->size[0]) + fabs(g->size[1]) + fabs(g->size[2]);
    default: return 0.0;
  }
}

/* Geom g's rectangle: 1 in view, 0 out of view, -1 unbounded. */
static int rects_of_geom(const mjvGLCamera *cam, int w, int h, const mjvGeom *g, render_rect_t *r) {
  const float *f = cam->forward, *u = cam->up;
  const double right[3] = {f[1] * u[2] - f[2] * u[1], f[2] * u[0] - f[0] * u[2],
                           f[0] * u[1] - f[1] * u[0]};
  const double half_h = 0.5 * (cam->frustum_top - cam->frustum_bottom);
  const double mid_y = 0.5 * (cam->frustum_top + cam->frustum_bottom), half_w = half_h * w / h;
  const double near = cam->frustum_near;
  const double v[3] = {g->pos[0] - cam->pos[0], g->pos[1] - cam->pos[1], g->pos[2] - cam->pos[2]};
  const double z = v[0] * f[0] + v[1] * f[1] + v[2] * f[2];
  const double rad = rects_radius(g);
  if (!(rad > 0) || z - rad <= near) return -1;
  double lo, hi;
  rects_sphere_span(v[0] * right[0] + v[1] * right[1] + v[2] * right[2], z, rad, &lo, &hi);
  const double x0 = ((lo * near - cam->frustum_center) / half_w + 1) * 0.5 * w;
  const double x1 = ((hi * near - cam->frustum_center) / half_w + 1) * 0.5 * w;
  rects_sphere_span(v[0] * u[0] + v[1] * u[1] + v[2] * u[2], z, rad, &lo, &hi);
  const double y0 = ((lo * near - mid_y) / half_h + 1) * 0.5 * h;
  const double y1 = ((hi * near - mid_y) / half_h + 1) * 0.5 * h;
  r->x = (int)fmax(0, floor(x0 - RENDER_RECTS_MARGIN_PX));
  r->y = (int)fmax(0, floor(y0 - RENDER_RECTS_MARGIN_PX));
  r->w = (int)fmin(w, ceil(x1 + RENDER_RECTS_MARGIN_PX)) - r->x;
  r->h = (int)fmin(h, ceil(y1 + RENDER_RECTS_MARGIN_PX)) - r->y;
  return r->w > 0 && r->h > 0;
}

static int rects_overlap(const render_rect_t *a, const render_rect_t *b) {
  return a->x < b->x + b->w && b->x < a->x + a->w && a->y < b->y + b->h && b->y < a->y + a->h;
}

static void rects_unite(render_rect_t *a, const render_rect_t *b) {
  const int x1 = a->x + a->w > b->x + b->w ? a->x + a->w : b->x + b->w;
  const int y1 = a->y + a->h > b->y + b->h ? a->y + a->h : b->y + b->h;
  a->x = a->x < b->x ? a->x : b->x;
  a->y = a->y < b->y ? a->y : b->y;
  a->w = x1 - a->x;
  a->h = y1 - a->y;
}

/* Merges rectangle `from` into `into` (its geoms too) and drops it (the last takes its place). */
static int rects_merge(render_rect_t *rects, int n, int into, int from, int *group, int ngeom) {
  rects_unite(&rects[into], &rects[from]);
  for (int i = 0; i < ngeom; i++) {
    if (group[i] == from)
      group[i] = into;
    else if (group[i] == n - 1)
      group[i] = from;
  }
  rects[from] = rects[n - 1];
  return n - 1;
}

/* Merges overlapping rectangles until none overlap. */
static int rects_merge_overlaps(render_rect_t *rects, int n, int *group, int ngeom) {
  for (int a = 0; a < n; a++)
    for (int b = a + 1; b < n; b++)
      if (rects_overlap(&rects[a], &rects[b])) {
        n = rects_merge(rects, n, a, b, group, ngeom);
        b = a; /* a grew: check it against every other again */
      }
  return n;
}

int render_rects_group(const mjvScene *scn, int w, int h, render_rect_t rects[RENDER_RECTS_MAX],
                       int *group) {
  const mjvGLCamera cam = mjv_averageCamera(&scn->camera[0], &scn->camera[1]);
  int n = 0;
  for (int i = 0; i < scn->ngeom; i++) {
    render_rect_t r;
    const int seen = rects_of_geom(&cam, w, h, &scn->geoms[i], &r);
    group[i] = -1;
    if (seen < 0) { /* unbounded: the whole image, every geom in it */
      rects[0] = (render_rect_t){0, 0, w, h};
      for (int k = 0; k < scn->ngeom; k++) group[k] = 0;
      return 1;
    }
    if (!seen) continue;
    if (n == RENDER_RECTS_MAX) n = rects_merge_overlaps(rects, n, group, i);
    if (n == RENDER_RECTS_MAX) /* still too many apart: one union */
      while (n > 1) n = rects_merge(rects, n, 0, n - 1, group, i);
    rects[n] = r;
    group[i] = n++;
  }
  return rects_merge_overlaps(rects, n, group, scn->ngeom);
}

void render_rects_frustum(mjvGLCamera cam[2], int w, int h, const render_rect_t *rect) {
  for (int e = 0; e < 2; e++) {
    mjvGLCamera *g = &cam[e];
    const double bottom = g->frustum_bottom, span = g->frustum_top - g->frustum_bottom;
    const double half_w = 0.5 * span * w / h; /* mjr_render's, from the whole image's aspect */
    const double left = g->frustum_center - half_w + 2.0 * half_w * rect->x / w;
    g->frustum_bottom = (float)(bottom + span * rect->y / h);
    g->frustum_top = (float)(bottom + span * (rect->y + rect->h) / h);
    g->frustum_center = (float)(left + half_w * rect->w / w);
  }
}
