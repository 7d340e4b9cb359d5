/* The learning API's episode videos (autodrive_sim_api.h ad_video_*): sim_video with a copy of
 * each frame to stamp, so that the caller's array is left as it was. */
#include <stdlib.h>
#include <stdio.h>
#include <string.h>

#include "autodrive_sim_api.h"
#include "sim_video.h"

struct ad_video {
  sim_video_t *v;
  int w, h;
  uint8_t *rgb; /* the stamped copy */
};

ad_video_t *ad_video_open(const char *path, int width_px, int height_px, double fps, char *err,
                          size_t err_sz) {
  sim_video_t *v = sim_video_open(path, width_px, height_px, fps, err, err_sz);
  if (!v) return NULL;
  ad_video_t *a = calloc(1, sizeof *a);
  if (a) a->rgb = malloc((size_t)width_px * (size_t)height_px * 3);
  if (!a || !a->rgb) {
    sim_video_close(v, err, err_sz);
    free(a);
    snprintf(err, err_sz, "video '%s': out of memory", path);
    return NULL;
  }
  a->v = v;
  a->w = width_px;
  a->h = height_px;
  return a;
}

int ad_video_frame(ad_video_t *a, const uint8_t *rgb, size_t n_bytes, double t_s, char *err,
                   size_t err_sz) {
  if (n_bytes != (size_t)a->w * (size_t)a->h * 3) {
    snprintf(err, err_sz, "video frame: %zu bytes, the video takes %d x %d x 3", n_bytes, a->w,
             a->h);
    return -1;
  }
  memcpy(a->rgb, rgb, n_bytes);
  if (t_s >= 0) sim_video_stamp(a->rgb, a->w, a->h, t_s, a->w >= 320 ? 3 : 1);
  return sim_video_frame(a->v, a->rgb, err, err_sz);
}

int ad_video_close(ad_video_t *a, char *err, size_t err_sz) {
  if (!a) return 0;
  const int rc = sim_video_close(a->v, err, err_sz);
  free(a->rgb);
  free(a);
  return rc;
}
