/* Cameras rendered headless and published on LCM (cameras.h). */
#include "cameras.h"

#include <ctype.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <autodrive_channels.h>

static void cameras_filter(uint8_t *rgb, int w, int h, void *ctx) {
  cfx_apply(ctx, rgb, w, h);
}

void cameras_set_effects(cameras_t *k, double noise, double blur_px, double exposure_ev,
                         uint64_t seed) {
  for (int i = 0; i < k->n; i++) {
    cfx_init(&k->fx[i], noise, blur_px, seed * 2654435761ull + (uint64_t)i);
    if (!k->eye[i]) cfx_set_exposure(&k->fx[i], exposure_ev);
    if (cfx_active(&k->fx[i])) sim_camera_set_filter(k->cam[i], cameras_filter, &k->fx[i]);
  }
}

void cameras_set_render_scale(cameras_t *k, double scale) {
  for (int i = 0; i < k->n; i++)
    if (!k->eye[i]) sim_camera_set_render_scale(k->cam[i], scale); /* options checked the range */
}

/* A map's several overhead cameras (its eye_cameras): the MJCF cameras whose user data holds
 * their image size (width, height px), as tools/gen-maps writes them. */
static int cameras_eye_size(const mjModel *m, int id, int *w, int *h) {
  if (m->nuser_cam < 2 || m->cam_user[id * m->nuser_cam] <= 0) return 0;
  *w = (int)m->cam_user[id * m->nuser_cam];
  *h = (int)m->cam_user[id * m->nuser_cam + 1];
  return 1;
}

static int cameras_eye_count(const mjModel *m) {
  int n = 0, w, h;
  for (int id = 0; id < m->ncam; id++) n += cameras_eye_size(m, id, &w, &h);
  return n;
}

/* Each on <CAM>_IMAGE and <CAM>_CAMERA_INFO, <CAM> its name in capitals. */
static int cameras_open_eyes(cameras_t *k, const mjModel *m, char *err, size_t err_sz) {
  for (int id = 0, w, h; id < m->ncam; id++) {
    if (!cameras_eye_size(m, id, &w, &h)) continue;
    if (k->n >= CAMERAS_MAX) {
      snprintf(err, err_sz, "--eye: more than %d overhead cameras", CAMERAS_MAX_EYES);
      return -1;
    }
    const char *name = mj_id2name(m, mjOBJ_CAMERA, id);
    char cam[24];
    size_t i = 0;
    for (; name[i] && i + 1 < sizeof cam; i++) cam[i] = (char)toupper((unsigned char)name[i]);
    cam[i] = '\0';
    k->cam[k->n] = sim_camera_create(k->render, m, name, name, w, h, 90, err, err_sz);
    if (!k->cam[k->n]) return -1;
    k->cam_id[k->n] = id;
    k->eye[k->n] = 1;
    snprintf(k->channel[k->n], sizeof k->channel[0], "%s" AUTODRIVE_CH_IMAGE_SUFFIX, cam);
    snprintf(k->info_channel[k->n], sizeof k->info_channel[0], "%s" AUTODRIVE_CH_CAMERA_INFO_SUFFIX,
             cam);
    k->n++;
  }
  return 0;
}

/* The overhead cameras' render mode and its buffers (--eye-render). */
static int cameras_eye_render(cameras_t *k, int eye_render, int w, int h, char *err,
                              size_t err_sz) {
  k->eye_render = eye_render;
  if (render_stats_init(&k->stats) != 0 ||
      (eye_render == CAMERAS_RENDER_COMPARE && !(k->full_rgb = malloc((size_t)w * h * 3)))) {
    snprintf(err, err_sz, "--eye: out of memory for the render statistics");
    return -1;
  }
  for (int i = 0; i < k->n; i++)
    if (k->eye[i]) sim_camera_set_full_render(k->cam[i], eye_render == CAMERAS_RENDER_FULL);
  return 0;
}

int cameras_open(cameras_t *k, const sim_t *s, int cameras, int eye, int eye_render, char *err,
                 size_t err_sz) {
  memset(k, 0, sizeof *k);
  if (!cameras && !eye) return 0;
  const mjModel *m = sim_render_model(s);
  int rw = eye ? 1280 : 640, rh = eye ? 960 : 480; /* the render buffer: the largest image */
  for (int id = 0, w, h; eye && id < m->ncam; id++)
    if (cameras_eye_size(m, id, &w, &h)) {
      rw = w > rw ? w : rw;
      rh = h > rh ? h : rh;
    }
  k->render = sim_render_create(m, rw, rh, SIM_RENDER_AUTO, err, err_sz);
  if (!k->render) return -1;
  for (int c = 1; cameras && c <= sim_cars(s); c++)
    for (int rear = 0; rear < (cameras == CAMERAS_FRONT ? 1 : 2); rear++) {
      char name[48], frame[48];
      snprintf(name, sizeof name, "nigel%d/cam_%s", c, rear ? "rear" : "front");
      snprintf(frame, sizeof frame, "camera_%s", rear ? "rear" : "front");
      k->cam[k->n] = sim_camera_create(k->render, m, name, frame, 640, 480, 85, err, err_sz);
      if (!k->cam[k->n]) return -1;
      k->cam_id[k->n] = mj_name2id(m, mjOBJ_CAMERA, name);
      snprintf(k->channel[k->n], sizeof k->channel[0], AUTODRIVE_VEHICLE_PREFIX "%d%s", c,
               rear ? AUTODRIVE_CH_CAM_REAR_SUFFIX : AUTODRIVE_CH_CAM_FRONT_SUFFIX);
      snprintf(k->info_channel[k->n], sizeof k->info_channel[0], AUTODRIVE_VEHICLE_PREFIX "%d%s", c,
               rear ? AUTODRIVE_CH_CAM_REAR_INFO_SUFFIX : AUTODRIVE_CH_CAM_FRONT_INFO_SUFFIX);
      k->n++;
    }
  if (eye && cameras_open_eyes(k, m, err, err_sz) != 0) return -1;
  if (eye && !cameras_eye_count(m)) {
    if (mj_name2id(m, mjOBJ_CAMERA, "eye") < 0) {
      snprintf(err, err_sz, "--eye: the map has no camera named 'eye'");
      return -1;
    }
    k->cam[k->n] = sim_camera_create(k->render, m, "eye", "eye", 1280, 960, 90, err, err_sz);
    if (!k->cam[k->n]) return -1;
    k->eye[k->n] = 1;
    snprintf(k->channel[k->n], sizeof k->channel[0], "%s", AUTODRIVE_CH_EYE_IMAGE);
    snprintf(k->info_channel[k->n], sizeof k->info_channel[0], "%s", AUTODRIVE_CH_EYE_CAMERA_INFO);
    k->n++;
  }
  return eye ? cameras_eye_render(k, eye_render, rw, rh, err, err_sz) : 0;
}

/* An overhead camera's frame, timed; compare: its full render first, then the cached one. */
static int cameras_render_eye(cameras_t *k, int i, const mjModel *mv, mjData *dv) {
  sim_camera_t *c = k->cam[i];
  const size_t n = (size_t)sim_camera_width(c) * (size_t)sim_camera_height(c) * 3;
  double t0[2];
  if (k->eye_render == CAMERAS_RENDER_COMPARE) {
    sim_camera_set_full_render(c, 1);
    render_stats_clock(t0);
    if (sim_camera_render(c, mv, dv) != 0) return -1;
    render_stats_add(&k->stats, RENDER_STATS_FULL, t0);
    memcpy(k->full_rgb, sim_camera_rgb(c), n);
    sim_camera_set_full_render(c, 0);
  }
  render_stats_clock(t0);
  if (sim_camera_render(c, mv, dv) != 0) return -1;
  render_stats_add(&k->stats, sim_camera_render_cache(c) ? RENDER_STATS_CACHED : RENDER_STATS_FULL,
                   t0);
  if (k->eye_render == CAMERAS_RENDER_COMPARE)
    render_stats_compare(&k->stats, k->full_rgb, sim_camera_rgb(c), n);
  return 0;
}

int cameras_publish(cameras_t *k, const mjModel *mv, mjData *dv, lcm_t *lcm, int64_t now_us,
                    char *err, size_t err_sz) {
  const int info = now_us >= k->next_info_us;
  if (info) k->next_info_us = now_us + 1000000; /* camera_info at 1 Hz */
  for (int i = 0; i < k->n; i++) {
    const int rendered =
        k->eye[i] ? cameras_render_eye(k, i, mv, dv) : sim_camera_render(k->cam[i], mv, dv);
    if (rendered != 0 || sim_camera_encode(k->cam[i], now_us) != 0) {
      snprintf(err, err_sz, "rendering %s failed", k->channel[i]);
      return -1;
    }
    sim_camera_publish_image(k->cam[i], lcm, k->channel[i]);
    if (info) sim_camera_publish_info(k->cam[i], mv, lcm, k->info_channel[i], now_us);
  }
  return 0;
}

void cameras_close(cameras_t *k) {
  for (int i = 0; i < k->n; i++) {
    sim_camera_destroy(k->cam[i]);
    cfx_free(&k->fx[i]);
  }
  if (k->render) sim_render_destroy(k->render);
  render_stats_free(&k->stats);
  free(k->full_rgb);
  k->full_rgb = NULL;
  k->n = 0;
}
