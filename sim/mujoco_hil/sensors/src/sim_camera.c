/* sim_camera: see sim_camera.h. */
#include "sim_camera.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <autodrive_camera_info_t.h>
#include <autodrive_compressed_image_t.h>

#include "sim_jpeg.h"
#include "sim_render_cache.h"

struct sim_camera {
  sim_render_t *render;
  sim_jpeg_t *jpeg;
  int cam_id;
  int w, h;
  char frame_id[64];
  uint8_t *rgb;
  const uint8_t *frame; /* the last frame: rgb, or the cache's own image (no copy) */
  const uint8_t *jpg;
  size_t jpg_len;
  int64_t utime;
  sim_camera_filter_fn filter;
  void *filter_ctx;
  sim_render_cache_t *cache; /* a camera fixed in the world: its static world, or NULL */
  int full_render;           /* 1: render in full even with a cache */
  double scale;              /* render scale per side, SIM_CAMERA_MIN_SCALE..1 */
  uint8_t *small;            /* the frame at the render scale (scale < 1), else NULL */
  int *taps;                 /* camera_stretch's scratch: 6 x max(w, h) */
};

int sim_camera_set_render_scale(sim_camera_t *c, double scale) {
  if (!(scale >= SIM_CAMERA_MIN_SCALE && scale <= 1.0)) return -1; /* NaN too */
  if (scale < 1.0 && !c->small) /* enough for any scale below 1 */
    c->small = malloc((size_t)c->w * (size_t)c->h * 3);
  if (scale < 1.0 && !c->taps)
    c->taps = malloc(6 * (size_t)(c->w > c->h ? c->w : c->h) * sizeof(int));
  if (scale < 1.0 && (!c->small || !c->taps)) return -1;
  c->scale = scale;
  return 0;
}

/* Where output column (or row) i of n samples a source of sn: the two source indices and the
 * second's weight in 1/256, on pixel centres, clamped at the edges. */
static void camera_taps(int n, int sn, int *i0, int *i1, int *w256) {
  for (int i = 0; i < n; i++) {
    double s = (i + 0.5) * sn / n - 0.5;
    s = s < 0 ? 0 : s > sn - 1 ? sn - 1 : s;
    i0[i] = (int)s;
    i1[i] = i0[i] + 1 < sn ? i0[i] + 1 : i0[i];
    w256[i] = (int)((s - i0[i]) * 256.0);
  }
}

/* src (sw x sh RGB, rows top-down) stretched to dst (w x h), bilinear in 8-bit fixed point
 * (taps: 6 x max(w, h) ints of scratch). */
static void camera_stretch(const uint8_t *src, int sw, int sh, uint8_t *dst, int w, int h,
                           int *taps) {
  int *x0 = taps, *x1 = x0 + w, *wx = x1 + w, *y0 = wx + w, *y1 = y0 + h, *wy = y1 + h;
  camera_taps(w, sw, x0, x1, wx);
  camera_taps(h, sh, y0, y1, wy);
  for (int y = 0; y < h; y++) {
    const uint8_t *top = src + (size_t)y0[y] * sw * 3, *bot = src + (size_t)y1[y] * sw * 3;
    uint8_t *o = dst + (size_t)y * w * 3;
    for (int x = 0; x < w; x++, o += 3) {
      const uint8_t *a = top + x0[x] * 3, *b = top + x1[x] * 3;
      const uint8_t *p = bot + x0[x] * 3, *q = bot + x1[x] * 3;
      for (int k = 0; k < 3; k++) {
        const int t = a[k] * (256 - wx[x]) + b[k] * wx[x];
        const int u = p[k] * (256 - wx[x]) + q[k] * wx[x];
        o[k] = (uint8_t)((t * (256 - wy[y]) + u * wy[y] + 32768) >> 16);
      }
    }
  }
}

/* The frame at the render scale into c->rgb: rendered small, then stretched. */
static int camera_render_scaled(sim_camera_t *c, const mjModel *m, mjData *d) {
  const int sw = (int)lround(c->w * c->scale), sh = (int)lround(c->h * c->scale);
  if (sw < 1 || sh < 1) return -1;
  if (sim_render_camera(c->render, m, d, c->cam_id, sw, sh, c->small) != 0) return -1;
  camera_stretch(c->small, sw, sh, c->rgb, c->w, c->h, c->taps);
  return 0;
}

void sim_camera_set_filter(sim_camera_t *c, sim_camera_filter_fn fn, void *ctx) {
  c->filter = fn;
  c->filter_ctx = ctx;
}

sim_camera_t *sim_camera_create(sim_render_t *r, const mjModel *m, const char *cam_name,
                                const char *frame_id, int width_px, int height_px, int jpeg_quality,
                                char *err, size_t err_len) {
  if (!r || !m || !cam_name || !frame_id) {
    if (err && err_len) snprintf(err, err_len, "sim_camera: null argument");
    return NULL;
  }
  int id = mj_name2id(m, mjOBJ_CAMERA, cam_name);
  if (id < 0) {
    if (err && err_len) snprintf(err, err_len, "sim_camera: no camera '%s' in the model", cam_name);
    return NULL;
  }
  /* a size larger than the renderer's buffer fails here, not at the first frame */
  if (!sim_render_fits(r, width_px, height_px) || jpeg_quality < 1 || jpeg_quality > 100) {
    if (err && err_len)
      snprintf(err, err_len,
               "sim_camera: bad size %dx%d px (must fit the renderer's buffer) or JPEG quality "
               "%d (1..100) for '%s'",
               width_px, height_px, jpeg_quality, cam_name);
    return NULL;
  }
  sim_camera_t *c = calloc(1, sizeof *c);
  if (!c) return NULL;
  c->render = r;
  c->cam_id = id;
  c->w = width_px;
  c->h = height_px;
  c->scale = 1.0;
  snprintf(c->frame_id, sizeof c->frame_id, "%s", frame_id);
  c->rgb = calloc((size_t)width_px * (size_t)height_px, 3);
  c->frame = c->rgb;
  c->jpeg = sim_jpeg_create(jpeg_quality);
  if (sim_render_cache_applies(m, id))
    c->cache = sim_render_cache_create(m, id, width_px, height_px, NULL, 0);
  if (!c->rgb || !c->jpeg || (sim_render_cache_applies(m, id) && !c->cache)) {
    sim_camera_destroy(c);
    if (err && err_len) snprintf(err, err_len, "sim_camera: out of memory for '%s'", cam_name);
    return NULL;
  }
  return c;
}

void sim_camera_destroy(sim_camera_t *c) {
  if (!c) return;
  sim_jpeg_destroy(c->jpeg);
  sim_render_cache_destroy(c->cache);
  free(c->rgb);
  free(c->small);
  free(c->taps);
  free(c);
}

struct sim_render_cache *sim_camera_render_cache(const sim_camera_t *c) {
  return c->full_render ? NULL : c->cache;
}

void sim_camera_set_full_render(sim_camera_t *c, int full) {
  c->full_render = full != 0;
}

int sim_camera_render(sim_camera_t *c, const mjModel *m, mjData *d) {
  const int cached = c->cache && !c->full_render;
  /* a filter changes the frame: it works on our copy, never on the cache's own image */
  uint8_t *into = cached && !c->filter ? NULL : c->rgb;
  const int rc = cached ? sim_render_camera_cached(c->render, c->cache, m, d, into)
                 : c->scale < 1.0 && !c->cache
                     ? camera_render_scaled(c, m, d)
                     : sim_render_camera(c->render, m, d, c->cam_id, c->w, c->h, c->rgb);
  if (rc != 0) return -1;
  c->frame = into ? c->rgb : sim_render_cache_image(c->cache);
  if (c->filter) c->filter(c->rgb, c->w, c->h, c->filter_ctx);
  return 0;
}

int sim_camera_encode(sim_camera_t *c, int64_t utime) {
  if (sim_jpeg_encode(c->jpeg, c->frame, c->w, c->h, &c->jpg, &c->jpg_len) != 0) return -1;
  c->utime = utime;
  return 0;
}

int sim_camera_capture(sim_camera_t *c, const mjModel *m, mjData *d, int64_t utime) {
  return sim_camera_render(c, m, d) == 0 ? sim_camera_encode(c, utime) : -1;
}

const uint8_t *sim_camera_rgb(const sim_camera_t *c) {
  return c->frame;
}
const uint8_t *sim_camera_jpeg(const sim_camera_t *c, size_t *size_bytes) {
  if (size_bytes) *size_bytes = c->jpg_len;
  return c->jpg;
}
int sim_camera_width(const sim_camera_t *c) {
  return c->w;
}
int sim_camera_height(const sim_camera_t *c) {
  return c->h;
}

void sim_camera_intrinsics(const mjModel *m, int cam_id, int width_px, int height_px, double k[9]) {
  double fovy_rad = m->cam_fovy[cam_id] * M_PI / 180.0;
  double f = 0.5 * height_px / tan(0.5 * fovy_rad);
  memset(k, 0, 9 * sizeof(double));
  k[0] = f;
  k[2] = 0.5 * (width_px - 1);
  k[4] = f;
  k[5] = 0.5 * (height_px - 1);
  k[8] = 1.0;
}

int sim_camera_publish_image(const sim_camera_t *c, lcm_t *lcm, const char *channel) {
  if (!c->jpg) return -1;
  autodrive_compressed_image_t msg;
  msg.utime = c->utime;
  msg.frame_id = (char *)c->frame_id;
  msg.format = (char *)"jpeg";
  msg.width_px = c->w;
  msg.height_px = c->h;
  msg.size_bytes = (int32_t)c->jpg_len;
  msg.data = (uint8_t *)c->jpg;
  return autodrive_compressed_image_t_publish(lcm, channel, &msg);
}

int sim_camera_publish_info(const sim_camera_t *c, const mjModel *m, lcm_t *lcm,
                            const char *channel, int64_t utime) {
  autodrive_camera_info_t msg;
  double d[5] = {0, 0, 0, 0, 0};
  msg.utime = utime;
  msg.frame_id = (char *)c->frame_id;
  msg.width_px = c->w;
  msg.height_px = c->h;
  sim_camera_intrinsics(m, c->cam_id, c->w, c->h, msg.k);
  msg.distortion_model = (char *)"plumb_bob";
  msg.num_d = 5;
  msg.d = d;
  return autodrive_camera_info_t_publish(lcm, channel, &msg);
}
