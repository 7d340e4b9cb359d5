/* sim_render_cache: see sim_render_cache.h. */
#include "sim_render_cache.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "sim_render_internal.h"
#include "sim_render_rects.h"

#define CACHE_OPAQUE_ALPHA 0.995f /* mjr_render treats a geom below this alpha as transparent */

struct sim_render_cache {
  int cam_id, w, h, ngeom;
  uint8_t *world;   /* per model geom: 1 while the cached image shows it */
  uint8_t *rgb;     /* the cached image, rows top-down */
  float *depth;     /* its depth buffer, OpenGL rows (bottom-up) */
  float *dyn_depth; /* the moving geoms' depth over one rectangle */
  uint8_t *out;     /* the frame: the cached image with the moving geoms drawn over it */
  render_rect_t dirty[RENDER_RECTS_MAX]; /* where the frame holds moving geoms */
  int ndirty;
  int *group;       /* per moving geom of the scene: its rectangle in dirty */
  mjvGeom *held;    /* the world geoms as the cached image shows them */
  mjvGeom *scratch; /* the whole scene while the image is rebuilt */
  int nheld, cap;   /* cap: geoms held and scratch have room for */
  mjvLight lights[mjMAXLIGHT];
  int nlight;
  mjvGLCamera camera[2];
  long epoch; /* the renderer's epoch the image was made in */
  int valid;
  float clear_depth; /* what mjr_render clears the depth buffer to (1, or 0 with reversed z) */
  sim_render_cache_stats_t st;
};

int sim_render_cache_applies(const mjModel *m, int cam_id) {
  if (!m || cam_id < 0 || cam_id >= m->ncam || m->cam_mode[cam_id] != mjCAMLIGHT_FIXED) return 0;
  const int body = m->cam_bodyid[cam_id];
  return m->body_weldid[body] == 0 && m->body_mocapid[body] < 0;
}

sim_render_cache_t *sim_render_cache_create(const mjModel *m, int cam_id, int width_px,
                                            int height_px, char *err, size_t err_len) {
  if (!sim_render_cache_applies(m, cam_id) || width_px < 1 || height_px < 1) {
    if (err && err_len)
      snprintf(err, err_len,
               "sim_render_cache: camera %d is not fixed in the world, or bad size %dx%d px",
               cam_id, width_px, height_px);
    return NULL;
  }
  sim_render_cache_t *c = calloc(1, sizeof *c);
  const size_t px = (size_t)width_px * (size_t)height_px;
  if (c) {
    c->world = calloc((size_t)m->ngeom + 1, 1);
    c->rgb = malloc(px * 3);
    c->depth = malloc(px * sizeof(float));
    c->dyn_depth = malloc(px * sizeof(float));
    c->out = malloc(px * 3);
  }
  if (!c || !c->world || !c->rgb || !c->depth || !c->dyn_depth || !c->out) {
    sim_render_cache_destroy(c);
    if (err && err_len) snprintf(err, err_len, "sim_render_cache: out of memory");
    return NULL;
  }
  c->cam_id = cam_id;
  c->w = width_px;
  c->h = height_px;
  c->ngeom = m->ngeom;
  for (int g = 0; g < m->ngeom; g++) {
    const int body = m->geom_bodyid[g];
    c->world[g] = m->body_weldid[body] == 0 && m->body_mocapid[body] < 0;
  }
  return c;
}

void sim_render_cache_destroy(sim_render_cache_t *c) {
  if (!c) return;
  free(c->world);
  free(c->rgb);
  free(c->depth);
  free(c->dyn_depth);
  free(c->out);
  free(c->group);
  free(c->held);
  free(c->scratch);
  free(c);
}

void sim_render_cache_get_stats(const sim_render_cache_t *c, sim_render_cache_stats_t *st) {
  *st = c->st;
}

/* Drawn from the cached image: a world geom not seen to change, or a site of the world body. */
static int cache_is_world(const sim_render_cache_t *c, const mjvGeom *g) {
  if (g->objtype == mjOBJ_GEOM) return g->objid >= 0 && g->objid < c->ngeom && c->world[g->objid];
  return g->objtype == mjOBJ_SITE && g->category == mjCAT_STATIC;
}

/* What a geom looks like: everything mjr_render draws it from (not its scene index, label or
 * the fields mjr_render itself sets). */
static int cache_same_geom(const mjvGeom *a, const mjvGeom *b) {
  return a->type == b->type && a->dataid == b->dataid && a->objtype == b->objtype &&
         a->objid == b->objid && a->category == b->category && a->texid == b->texid &&
         a->texuniform == b->texuniform && a->texcoord == b->texcoord &&
         !memcmp(a->texrepeat, b->texrepeat,
                 offsetof(mjvGeom, label) - offsetof(mjvGeom, texrepeat));
}

/* 1 if the cached image still shows the scene's world: the same world geoms looking the same,
 * the same lights and camera. Every world geom that changed is drawn each frame from now on. */
static int cache_unchanged(sim_render_cache_t *c, const mjvScene *scn) {
  if (!c->valid) return 0;
  int same = scn->nlight == c->nlight &&
             !memcmp(scn->lights, c->lights, (size_t)scn->nlight * sizeof(mjvLight)) &&
             !memcmp(scn->camera, c->camera, sizeof c->camera);
  int k = 0;
  for (int i = 0; i < scn->ngeom; i++) {
    const mjvGeom *g = &scn->geoms[i];
    if (!cache_is_world(c, g)) continue;
    if (k >= c->nheld || c->held[k].objtype != g->objtype || c->held[k].objid != g->objid)
      return 0; /* shown or hidden (geom groups) */
    if (!cache_same_geom(g, &c->held[k])) {
      same = 0;
      if (g->objtype == mjOBJ_GEOM) { /* a lamp, a late box: it moves or changes colour */
        c->world[g->objid] = 0;
        c->st.promoted++;
      }
    }
    k++;
  }
  return same && k == c->nheld;
}

static int cache_reserve(sim_render_cache_t *c, int n) {
  if (n <= c->cap) return 0;
  mjvGeom *held = realloc(c->held, (size_t)n * sizeof *held);
  if (held) c->held = held;
  mjvGeom *scratch = realloc(c->scratch, (size_t)n * sizeof *scratch);
  if (scratch) c->scratch = scratch;
  int *group = realloc(c->group, (size_t)n * sizeof *group);
  if (group) c->group = group;
  if (!held || !scratch || !group) return -1;
  c->cap = n;
  return 0;
}

/* Renders the world geoms alone into the cached colour and depth; the scene is whole again
 * afterwards. */
static int cache_rebuild(sim_render_t *r, sim_render_cache_t *c) {
  mjvScene *scn = &r->scn;
  if (cache_reserve(c, scn->maxgeom) != 0) return -1;
  const int n = scn->ngeom;
  memcpy(c->scratch, scn->geoms, (size_t)n * sizeof(mjvGeom));
  int nw = 0;
  for (int i = 0; i < n; i++)
    if (cache_is_world(c, &c->scratch[i])) scn->geoms[nw++] = c->scratch[i];
  memcpy(c->held, scn->geoms, (size_t)nw * sizeof(mjvGeom)); /* before mjr_render edits them */
  c->nheld = nw;
  scn->ngeom = nw;
  c->nlight = scn->nlight;
  memcpy(c->lights, scn->lights, (size_t)scn->nlight * sizeof(mjvLight));
  memcpy(c->camera, scn->camera, sizeof c->camera);
  const mjrRect vp = {0, 0, c->w, c->h};
  mjr_render(vp, scn, &r->con);
  r->GetFloatv(GL_DEPTH_CLEAR_VALUE, &c->clear_depth);
  sim_render_read_rgb(r, c->w, c->h, c->rgb);
  r->ReadPixels(0, 0, c->w, c->h, GL_DEPTH_COMPONENT, GL_FLOAT, c->depth);
  memcpy(c->out, c->rgb, (size_t)c->w * (size_t)c->h * 3);
  c->ndirty = 0;
  memcpy(scn->geoms, c->scratch, (size_t)n * sizeof(mjvGeom));
  scn->ngeom = n;
  c->epoch = r->epoch;
  c->valid = 1;
  c->st.rebuilds++;
  return 0;
}

/* Puts the pixels of rect back to the cached image in the frame. */
static void cache_restore(sim_render_cache_t *c, const render_rect_t *rect) {
  for (int y = rect->y; y < rect->y + rect->h; y++) {
    const size_t at = ((size_t)(c->h - 1 - y) * (size_t)c->w + (size_t)rect->x) * 3;
    memcpy(c->out + at, c->rgb + at, (size_t)rect->w * 3);
  }
}

/* Draws the scene's geoms (moving ones of rect) in rect alone, and keeps each of their pixels
 * that is nearer than the cached depth; ties go to the moving geom, drawn after the world in a
 * full render. */
static void cache_draw_rect(sim_render_t *r, sim_render_cache_t *c, const render_rect_t *rect) {
  mjvGLCamera whole[2];
  memcpy(whole, r->scn.camera, sizeof whole);
  render_rects_frustum(r->scn.camera, c->w, c->h, rect);
  const mjrRect vp = {0, 0, rect->w, rect->h};
  mjr_render(vp, &r->scn, &r->con);
  memcpy(r->scn.camera, whole, sizeof whole);
  r->BindFramebuffer(GL_READ_FRAMEBUFFER, r->con.offFBO);
  r->ReadPixels(0, 0, rect->w, rect->h, GL_DEPTH_COMPONENT, GL_FLOAT, c->dyn_depth);
  r->ReadPixels(0, 0, rect->w, rect->h, GL_RGBA, GL_UNSIGNED_BYTE, r->rgba);
  const float clear = c->clear_depth;
  const int far_is_one = clear >= 0.5f;
  for (int y = 0; y < rect->h; y++) {
    const float *dd = c->dyn_depth + (size_t)y * (size_t)rect->w;
    const float *ds = c->depth + (size_t)(rect->y + y) * (size_t)c->w + (size_t)rect->x;
    const uint8_t *src = r->rgba + (size_t)y * (size_t)rect->w * 4;
    uint8_t *dst = c->out + ((size_t)(c->h - 1 - rect->y - y) * (size_t)c->w + (size_t)rect->x) * 3;
    for (int x = 0; x < rect->w; x++) {
      if (dd[x] == clear || (far_is_one ? dd[x] > ds[x] : dd[x] < ds[x])) continue;
      memcpy(dst + 3 * x, src + 4 * x, 3);
    }
  }
}

/* The frame: the cached image, the last frame's moving pixels put back, this frame's moving
 * geoms (the scene holds only them) drawn rectangle by rectangle. */
static void cache_draw_moving(sim_render_t *r, sim_render_cache_t *c) {
  for (int k = 0; k < c->ndirty; k++) cache_restore(c, &c->dirty[k]);
  mjvScene *scn = &r->scn;
  const int n = scn->ngeom;
  c->ndirty = n > 0 ? render_rects_group(scn, c->w, c->h, c->dirty, c->group) : 0;
  if (c->ndirty == 0) return;
  const mjtByte sky = scn->flags[mjRND_SKYBOX];
  scn->flags[mjRND_SKYBOX] = 0; /* the cached image has it */
  memcpy(c->scratch, scn->geoms, (size_t)n * sizeof(mjvGeom));
  for (int k = 0; k < c->ndirty; k++) {
    scn->ngeom = 0;
    for (int i = 0; i < n; i++)
      if (c->group[i] == k) scn->geoms[scn->ngeom++] = c->scratch[i];
    cache_draw_rect(r, c, &c->dirty[k]);
  }
  scn->flags[mjRND_SKYBOX] = sky;
}

static int cache_has_transparent(const mjvScene *scn) {
  for (int i = 0; i < scn->ngeom; i++)
    if (scn->geoms[i].rgba[3] < CACHE_OPAQUE_ALPHA) return 1;
  return 0;
}

int sim_render_camera_cached(sim_render_t *r, sim_render_cache_t *c, const mjModel *m, mjData *d,
                             uint8_t *rgb) {
  if (!c || c->cam_id >= m->ncam || c->ngeom != m->ngeom || !sim_render_fits(r, c->w, c->h))
    return -1;
  if (sim_render_make_current(r) != 0) return -1;
  sim_render_update_scene(r, m, d, c->cam_id);
  c->st.frames++;
  mjvScene *scn = &r->scn;
  if (cache_has_transparent(scn)) { /* blending needs what lies behind: no cache */
    c->st.full++;
    const mjrRect vp = {0, 0, c->w, c->h};
    mjr_render(vp, scn, &r->con);
    sim_render_read_rgb(r, c->w, c->h, c->out);
    mjr_restoreBuffer(&r->con);
    c->valid = 0; /* the frame holds more than the cached image: start again from it */
    if (rgb) memcpy(rgb, c->out, (size_t)c->w * (size_t)c->h * 3);
    return 0;
  }
  if ((c->epoch != r->epoch || !cache_unchanged(c, scn)) && cache_rebuild(r, c) != 0) return -1;
  if (cache_reserve(c, scn->maxgeom) != 0) return -1;
  int n = 0; /* the moving geoms alone, in their order */
  for (int i = 0; i < scn->ngeom; i++)
    if (!cache_is_world(c, &scn->geoms[i])) scn->geoms[n++] = scn->geoms[i];
  scn->ngeom = n;
  cache_draw_moving(r, c);
  mjr_restoreBuffer(&r->con);
  if (rgb) memcpy(rgb, c->out, (size_t)c->w * (size_t)c->h * 3);
  return 0;
}

const uint8_t *sim_render_cache_image(const sim_render_cache_t *c) {
  return c->out;
}
