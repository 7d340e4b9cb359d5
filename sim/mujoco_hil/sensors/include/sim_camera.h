/* sim_camera: one camera of the sim (front, rear or the overhead Eye): render, JPEG-encode
 * and publish on LCM as autodrive_compressed_image_t, with its autodrive_camera_info_t.
 *
 * MuJoCo 2.2 cameras take a vertical field of view only (fovy). Nigel's 62.2 deg horizontal
 * FOV at 4:3 is fovy = 2 atan(tan(31.1 deg) * 3/4) = 48.67 deg: put fovy="48.67" on the MJCF
 * <camera> (the often quoted 48.8 gives 62.33 deg). The intrinsics are derived from the model's
 * fovy: fy = fx = (h/2) / tan(fovy/2), cx = (w-1)/2, cy = (h-1)/2 (OpenCV pixel-centre convention),
 * no distortion.
 */
#ifndef SIM_CAMERA_H
#define SIM_CAMERA_H

#include <stddef.h>
#include <stdint.h>

#include <lcm/lcm.h>
#include <mujoco/mujoco.h>

#include "sim_render.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Nigel's cameras: 62.2 deg HFOV, 4:3, 640x480 by default. */
#define SIM_CAMERA_HFOV_DEG 62.2
#define SIM_CAMERA_FOVY_4_3_DEG 48.67
#define SIM_CAMERA_DEFAULT_WIDTH_PX 640
#define SIM_CAMERA_DEFAULT_HEIGHT_PX 480

typedef struct sim_camera sim_camera_t;

/* A camera bound to MJCF camera cam_name (e.g. "nigel1/cam_front" or "eye"), rendered at
 * width_px x height_px (must fit the renderer's buffer), JPEG quality 1..100 (e.g. 85).
 * frame_id goes into the LCM messages (copied). Returns NULL with a message in err on a
 * missing camera or a bad size. Caller owns the result (sim_camera_destroy); the renderer
 * must outlive it. */
sim_camera_t *sim_camera_create(sim_render_t *r, const mjModel *m, const char *cam_name,
                                const char *frame_id, int width_px, int height_px, int jpeg_quality,
                                char *err, size_t err_len);
void sim_camera_destroy(sim_camera_t *c);

/* An optional filter run on each rendered frame before JPEG encoding (camera realism: blur,
 * noise): rgb rows top-down, w*h*3 bytes, changed in place. NULL: none. */
typedef void (*sim_camera_filter_fn)(uint8_t *rgb, int width_px, int height_px, void *ctx);
void sim_camera_set_filter(sim_camera_t *c, sim_camera_filter_fn fn, void *ctx);

/* Renders the current state d and JPEG-encodes it. Returns 0, or -1 on failure. */
int sim_camera_capture(sim_camera_t *c, const mjModel *m, mjData *d, int64_t utime);
/* The render scale (SIM_CAMERA_MIN_SCALE..1, default 1): a frame is rendered at scale x the
 * camera's size per side and stretched back (bilinear) to it, so that a slow machine trades
 * sharpness for render time; the published size and intrinsics never change. A camera fixed in
 * the world with a render cache keeps rendering in full. Returns 0, or -1 (unchanged) for a
 * scale outside the range. */
#define SIM_CAMERA_MIN_SCALE 0.25
int sim_camera_set_render_scale(sim_camera_t *c, double scale);
/* The two halves of sim_camera_capture: render (the filter applied) into the RGB frame, then
 * JPEG-encode that frame stamped utime. Each returns 0, or -1 on failure. */
int sim_camera_render(sim_camera_t *c, const mjModel *m, mjData *d);
int sim_camera_encode(sim_camera_t *c, int64_t utime);

/* A camera fixed in the world (an overhead Eye camera) renders its static world once and
 * draws only what moves over it (sim_render_cache.h): on by default for such a camera.
 * full = 1 renders every frame in full instead. Returns the cache, or NULL when it has none
 * (a camera on a car, or full). Borrowed. */
struct sim_render_cache *sim_camera_render_cache(const sim_camera_t *c);
void sim_camera_set_full_render(sim_camera_t *c, int full);

/* The last frame: RGB rows top-down (width*height*3) and its JPEG. Borrowed, valid until the
 * next capture. */
const uint8_t *sim_camera_rgb(const sim_camera_t *c);
const uint8_t *sim_camera_jpeg(const sim_camera_t *c, size_t *size_bytes);
int sim_camera_width(const sim_camera_t *c);
int sim_camera_height(const sim_camera_t *c);

/* Camera matrix K (row-major, [px]) of camera cam_id at width_px x height_px, from its fovy. */
void sim_camera_intrinsics(const mjModel *m, int cam_id, int width_px, int height_px, double k[9]);

/* Publishes the last frame as compressed_image_t ("jpeg") on channel. Returns lcm_publish's
 * result (0 on success). */
int sim_camera_publish_image(const sim_camera_t *c, lcm_t *lcm, const char *channel);
/* Publishes the camera's camera_info_t (plumb_bob, zero distortion) stamped utime. */
int sim_camera_publish_info(const sim_camera_t *c, const mjModel *m, lcm_t *lcm,
                            const char *channel, int64_t utime);

#ifdef __cplusplus
}
#endif
#endif /* SIM_CAMERA_H */
