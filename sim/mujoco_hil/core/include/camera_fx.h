/* Camera realism for domain randomisation: the scene's light level, and per-frame blur and
 * sensor noise on rendered RGB images (seeded, so a run repeats).
 * - light level: 1 = day (MuJoCo's default headlight and the maps' sun at full strength, the
 *   map side's convention), 0 = dark. The map sets its own level; cfx_set_light_level scales
 *   the model's headlight and every light so that the scene shows the given level instead.
 * - blur: Gaussian, standard deviation blur_px [px] (separable, kernel radius 3 sigma).
 * - noise: additive Gaussian per channel and pixel, standard deviation noise_sigma [8-bit
 *   levels], clamped to 0..255.
 * - light colour: a gain per channel (R, G, B) on every light's diffuse and specular colour.
 * - exposure: the frame multiplied by 2^EV and clipped at 255, as a sensor clips, before blur
 *   and noise.
 * - mount jitter: a camera's mount moved and turned by a seeded offset, drawn once per run. */
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
#define CFX_MIN_LIGHT_GAIN 0.5 /* --light-rgb's gain per channel */
#define CFX_MAX_LIGHT_GAIN 1.5
#define CFX_MAX_EXPOSURE_EV 2.0 /* --camera-exposure: -2..2 [EV] */
#define CFX_MAX_JITTER_MM 10.0  /* --camera-jitter: the mount's tolerance, +-10 mm per axis */
#define CFX_MAX_JITTER_DEG 3.0  /* and +-3 deg about each axis */

typedef struct cfx {
  double noise_sigma; /* [8-bit levels], 0: none */
  double blur_px;     /* Gaussian sigma [px], 0: none */
  double gain;        /* exposure: 2^EV, 1: none (cfx_set_exposure) */
  rng_t rng;
  float *tmp; /* blur scratch, w*h*3 */
  size_t tmp_n;
} cfx_t;

/* The light level the model shows now (headlight relative to MuJoCo's default). */
double cfx_light_level(const mjModel *m);
/* Scales the headlight and every light of m so that it shows level (0..1). Returns 0, or -1
 * when the model's own level is 0 (nothing to scale from). */
int cfx_set_light_level(mjModel *m, double level);

/* Multiplies every light's diffuse and specular colour of m (the map's lights and the
 * headlight) by gain_rgb[c] per channel c (R, G, B). Applied after cfx_set_light_level, which
 * reads the level from the headlight's red channel. */
void cfx_set_light_rgb(mjModel *m, const double gain_rgb[3]);

/* A camera mount's offset: moved by pos_m [m] along, and turned by rot_deg [deg] about, the
 * car's x, y, z axes (in that order, each about the car's fixed axes). */
typedef struct cfx_jitter {
  double pos_m[3];
  double rot_deg[3];
} cfx_jitter_t;
/* The offset of car's (1-based) mount, drawn from seed: each of pos_m uniform in +-mm/1000,
 * each of rot_deg uniform in +-deg. The same seed and car give the same offset. */
cfx_jitter_t cfx_jitter_draw(uint64_t seed, int car, double mm, double deg);
/* Moves and turns camera cam_id of m by j (its fovy, so the published intrinsics, stay). */
void cfx_jitter_camera(mjModel *m, int cam_id, const cfx_jitter_t *j);

void cfx_init(cfx_t *f, double noise_sigma, double blur_px, uint64_t seed);
/* Exposure of f's frames: multiplied by 2^ev (-CFX_MAX_EXPOSURE_EV..CFX_MAX_EXPOSURE_EV). */
void cfx_set_exposure(cfx_t *f, double ev);
void cfx_free(cfx_t *f);
/* 1 when it changes images at all. */
int cfx_active(const cfx_t *f);
/* Exposes, blurs, then adds noise to, an RGB image (rows top-down, w*h*3 bytes) in place. */
void cfx_apply(cfx_t *f, uint8_t *rgb, int w, int h);

#ifdef __cplusplus
}
#endif
#endif
