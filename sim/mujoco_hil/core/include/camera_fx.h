/* Camera realism for domain randomisation: the scene's light level, and per-frame blur and
 * sensor noise on rendered RGB images (seeded, so a run repeats).
 * - light level: 1 = day (MuJoCo's default headlight and the maps' sun at full strength, the
 *   map side's convention), 0 = dark. The map sets its own level; cfx_set_light_level scales
 *   the model's headlight and every light so that the scene shows the given level instead.
 * - blur: Gaussian, standard deviation blur_px [px] (separable, kernel radius 3 sigma).
 * - noise: additive Gaussian per channel and pixel, standard deviation noise_sigma [8-bit
 *   levels], clamped to 0..255. */
#ifndef SIM_CAMERA_FX_H
#define SIM_CAMERA_FX_H

#include <stddef.h>
#include <stdint.h>

#include <mujoco/mujoco.h>

#include "rng.h"

#ifdef __cplusplus
extern "C" {
#endif

#define CFX_MAX_BLUR_PX 10.0
#define CFX_KERNEL_MAX_R_PX 30 /* 3 sigma at the largest blur */
#define CFX_MAX_NOISE 100.0

typedef struct cfx {
  double noise_sigma; /* [8-bit levels], 0: none */
  double blur_px;     /* Gaussian sigma [px], 0: none */
  rng_t rng;
  float *tmp; /* blur scratch, w*h*3 */
  size_t tmp_n;
} cfx_t;

/* The light level the model shows now (headlight relative to MuJoCo's default). */
double cfx_light_level(const mjModel *m);
/* Scales the headlight and every light of m so that it shows level (0..1). Returns 0, or -1
 * when the model's own level is 0 (nothing to scale from). */
int cfx_set_light_level(mjModel *m, double level);

void cfx_init(cfx_t *f, double noise_sigma, double blur_px, uint64_t seed);
void cfx_free(cfx_t *f);
/* 1 when it changes images at all. */
int cfx_active(const cfx_t *f);
/* Blurs, then adds noise to, an RGB image (rows top-down, w*h*3 bytes) in place. */
void cfx_apply(cfx_t *f, uint8_t *rgb, int w, int h);

#ifdef __cplusplus
}
#endif
#endif
