/* Cameras rendered headless (sensors library) and published on LCM: front/rear of every car,
 * the map's overhead Eye camera(s), with the --camera-noise / --camera-blur effects. */
#ifndef SIM_APP_CAMERAS_H
#define SIM_APP_CAMERAS_H

#include <stdint.h>

#include <lcm/lcm.h>

#include "camera_fx.h"
#include "render_stats.h"
#include "sim.h"
#include "sim_camera.h"
#include "sim_render.h"

#define CAMERAS_ALL 1      /* --cameras: front and rear */
#define CAMERAS_FRONT 2    /* --front-camera: front only */
#define CAMERAS_MAX_EYES 8 /* a map's eye_cameras (autodrive.maps MAX_EYE_CAMERAS) */
#define CAMERAS_MAX (2 * SIM_MAX_CARS + CAMERAS_MAX_EYES)
/* --eye-render: how the overhead cameras render (sim_render_cache.h) */
enum { CAMERAS_RENDER_CACHED = 0, CAMERAS_RENDER_FULL, CAMERAS_RENDER_COMPARE };
typedef struct cameras {
  int n;
  sim_render_t *render;
  sim_camera_t *cam[CAMERAS_MAX];
  int cam_id[CAMERAS_MAX];
  char channel[CAMERAS_MAX][48], info_channel[CAMERAS_MAX][48];
  int64_t next_info_us;
  cfx_t fx[CAMERAS_MAX]; /* --camera-noise / -blur / -exposure, seeded per camera */
  int eye[CAMERAS_MAX];  /* 1: an overhead camera (its render timed, per eye_render) */
  int eye_render;        /* CAMERAS_RENDER_* */
  uint8_t *full_rgb;     /* compare: the full render of the camera at hand */
  render_stats_t stats;  /* the overhead cameras' render times, cached vs full */
} cameras_t;

/* Opens the cameras asked for (cameras: 0, CAMERAS_ALL or CAMERAS_FRONT; eye: 0 or 1; eye_render:
 * CAMERAS_RENDER_*). */
int cameras_open(cameras_t *k, const sim_t *s, int cameras, int eye, int eye_render, char *err,
                 size_t err_sz);
/* Noise and blur on every camera: each its own seeded noise stream; exposure_ev [EV] on the
 * cars' cameras only (the Eye's are fixed installations with their own exposure). */
void cameras_set_effects(cameras_t *k, double noise, double blur_px, double exposure_ev,
                         uint64_t seed);
/* --camera-scale: the render scale of the cars' cameras (sim_camera_set_render_scale); the
 * overhead Eye cameras keep theirs (the Eye's detections are measured at full size). */
void cameras_set_render_scale(cameras_t *k, double scale);
/* Renders and publishes every camera from dv (the whole map at sim time now_us). */
int cameras_publish(cameras_t *k, const mjModel *mv, mjData *dv, lcm_t *lcm, int64_t now_us,
                    char *err, size_t err_sz);
void cameras_close(cameras_t *k);

#endif
