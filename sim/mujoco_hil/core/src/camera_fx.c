/* Camera realism (see camera_fx.h). */
#include "camera_fx.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

double cfx_light_level(const mjModel *m) {
  mjVisual def;
  mj_defaultVisual(&def);
  return m->vis.headlight.diffuse[0] / def.headlight.diffuse[0];
}

int cfx_set_light_level(mjModel *m, double level) {
  const double now = cfx_light_level(m);
  if (!(now > 0)) return -1;
  const float k = (float)(level / now);
  for (int c = 0; c < 3; c++) {
    m->vis.headlight.ambient[c] *= k;
    m->vis.headlight.diffuse[c] *= k;
    m->vis.headlight.specular[c] *= k;
  }
  for (int i = 0; i < 3 * m->nlight; i++) {
    m->light_ambient[i] *= k;
    m->light_diffuse[i] *= k;
    m->light_specular[i] *= k;
  }
  return 0;
}

void cfx_set_light_rgb(mjModel *m, const double gain_rgb[3]) {
  for (int c = 0; c < 3; c++) {
    const float k = (float)gain_rgb[c];
    m->vis.headlight.diffuse[c] *= k;
    m->vis.headlight.specular[c] *= k;
    for (int i = 0; i < m->nlight; i++) {
      m->light_diffuse[3 * i + c] *= k;
      m->light_specular[3 * i + c] *= k;
    }
  }
}

cfx_jitter_t cfx_jitter_draw(uint64_t seed, int car, double mm, double deg) {
  rng_t r;
  /* a stream of its own: not the IMU's, the noise's or another car's */
  rng_seed(&r, (seed ^ 0x6a177e5ull) * 0x9E3779B97F4A7C15ull + (uint64_t)car);
  cfx_jitter_t j;
  for (int a = 0; a < 3; a++) j.pos_m[a] = (2.0 * rng_uniform(&r) - 1.0) * mm * 1e-3;
  for (int a = 0; a < 3; a++) j.rot_deg[a] = (2.0 * rng_uniform(&r) - 1.0) * deg;
  return j;
}

void cfx_jitter_camera(mjModel *m, int cam_id, const cfx_jitter_t *j) {
  for (int a = 0; a < 3; a++) m->cam_pos[3 * cam_id + a] += j->pos_m[a];
  /* q = qz * qy * qx * q_cam: about the car's x, then y, then z (fixed axes) */
  mjtNum q[4] = {1, 0, 0, 0};
  for (int a = 0; a < 3; a++) {
    const double h = 0.5 * j->rot_deg[a] * (M_PI / 180.0);
    mjtNum qa[4] = {cos(h), 0, 0, 0}, t[4];
    qa[1 + a] = sin(h);
    mju_mulQuat(t, qa, q);
    mju_copy4(q, t);
  }
  mjtNum *cq = m->cam_quat + 4 * cam_id, out[4];
  mju_mulQuat(out, q, cq);
  mju_normalize4(out);
  mju_copy4(cq, out);
}

void cfx_init(cfx_t *f, double noise_sigma, double blur_px, uint64_t seed) {
  memset(f, 0, sizeof *f);
  f->noise_sigma = noise_sigma;
  f->blur_px = blur_px;
  f->gain = 1.0;
  rng_seed(&f->rng, seed);
}

void cfx_set_exposure(cfx_t *f, double ev) {
  f->gain = exp2(ev);
}

void cfx_free(cfx_t *f) {
  free(f->tmp);
  f->tmp = NULL;
}

int cfx_active(const cfx_t *f) {
  return f->noise_sigma > 0 || f->blur_px > 0 || f->gain != 1.0;
}

/* One pass of the separable Gaussian along x (dx = 3) or y (dx = 3 w), edges clamped. */
static void cfx_pass(const float *src, float *dst, int w, int h, int along_x, const float *k,
                     int r) {
  for (int y = 0; y < h; y++)
    for (int x = 0; x < w; x++)
      for (int c = 0; c < 3; c++) {
        float acc = 0.0f;
        for (int t = -r; t <= r; t++) {
          int xx = x, yy = y;
          if (along_x)
            xx = x + t < 0 ? 0 : (x + t >= w ? w - 1 : x + t);
          else
            yy = y + t < 0 ? 0 : (y + t >= h ? h - 1 : y + t);
          acc += k[t + r] * src[((size_t)yy * (size_t)w + (size_t)xx) * 3 + (size_t)c];
        }
        dst[((size_t)y * (size_t)w + (size_t)x) * 3 + (size_t)c] = acc;
      }
}

static void cfx_blur(cfx_t *f, uint8_t *rgb, int w, int h) {
  const size_t n = (size_t)w * (size_t)h * 3;
  if (f->tmp_n < 2 * n) {
    free(f->tmp);
    f->tmp = malloc(2 * n * sizeof(float));
    f->tmp_n = f->tmp ? 2 * n : 0;
    if (!f->tmp) return; /* out of memory: the frame stays sharp */
  }
  const int r = (int)ceil(3.0 * f->blur_px);
  float k[2 * CFX_KERNEL_MAX_R_PX + 1];
  double sum = 0.0;
  for (int t = -r; t <= r; t++)
    sum += k[t + r] = (float)exp(-0.5 * t * t / (f->blur_px * f->blur_px));
  for (int t = 0; t <= 2 * r; t++) k[t] = (float)(k[t] / sum);
  float *a = f->tmp, *b = f->tmp + n;
  for (size_t i = 0; i < n; i++) a[i] = rgb[i];
  cfx_pass(a, b, w, h, 1, k, r);
  cfx_pass(b, a, w, h, 0, k, r);
  for (size_t i = 0; i < n; i++) rgb[i] = (uint8_t)lrintf(a[i] < 0 ? 0 : (a[i] > 255 ? 255 : a[i]));
}

void cfx_apply(cfx_t *f, uint8_t *rgb, int w, int h) {
  if (f->gain != 1.0) { /* the sensor's exposure: brighter saturates at 255 */
    const size_t n = (size_t)w * (size_t)h * 3;
    for (size_t i = 0; i < n; i++) {
      const double v = rgb[i] * f->gain;
      rgb[i] = (uint8_t)lround(v > 255 ? 255 : v);
    }
  }
  if (f->blur_px > 0) cfx_blur(f, rgb, w, h);
  if (f->noise_sigma > 0) {
    const size_t n = (size_t)w * (size_t)h * 3;
    for (size_t i = 0; i < n; i++) {
      const double v = rgb[i] + rng_gauss(&f->rng, f->noise_sigma);
      rgb[i] = (uint8_t)lround(v < 0 ? 0 : (v > 255 ? 255 : v));
    }
  }
}
