/* sim_render: headless CPU rendering of a MuJoCo model (EGL surfaceless on Mesa llvmpipe,
 * falling back to OSMesa), at fast settings: no MSAA, no shadows, no reflections.
 *
 * One sim_render_t owns one OpenGL context, one mjrContext and one mjvScene. OpenGL contexts
 * are bound to a thread: create, use and destroy a renderer on the same thread. One renderer
 * serves every camera of every car (cameras render one after the other into its offscreen
 * buffer), which is the cheapest arrangement on a CPU rasteriser.
 */
#ifndef SIM_RENDER_H
#define SIM_RENDER_H

#include <stddef.h>
#include <stdint.h>

#include <mujoco/mujoco.h>

#ifdef __cplusplus
extern "C" {
#endif

typedef struct sim_render sim_render_t;

typedef enum sim_render_backend {
  SIM_RENDER_AUTO = 0, /* EGL surfaceless, else OSMesa */
  SIM_RENDER_EGL,
  SIM_RENDER_OSMESA,
} sim_render_backend_t;

/* Creates a renderer for model m whose offscreen buffer holds max_width_px x max_height_px
 * (the largest camera image you will render). The model's own offwidth/offheight/offsamples
 * are overridden on a private shallow copy, so m is not modified. Returns NULL with a message
 * in err if no GL context can be made. Caller owns the result (sim_render_destroy). */
sim_render_t *sim_render_create(const mjModel *m, int max_width_px, int max_height_px,
                                sim_render_backend_t backend, char *err, size_t err_len);
void sim_render_destroy(sim_render_t *r);

/* 1 if a width_px x height_px image fits the renderer's offscreen buffer, else 0. */
int sim_render_fits(const sim_render_t *r, int width_px, int height_px);

/* Name of the backend in use: "egl" or "osmesa". */
const char *sim_render_backend_name(const sim_render_t *r);

/* Renders fixed camera cam_id (mjModel camera index) of the current state d at width x height
 * into rgb (width * height * 3 bytes, caller's buffer), rows TOP-DOWN (image order; MuJoCo's
 * bottom-up rows are flipped here). Returns 0, or -1 if the size exceeds the buffer or cam_id
 * is out of range. */
int sim_render_camera(sim_render_t *r, const mjModel *m, mjData *d, int cam_id, int width_px,
                      int height_px, uint8_t *rgb);

/* Scene options shared by all cameras of this renderer (e.g. hide geom groups). Borrowed. */
mjvOption *sim_render_options(sim_render_t *r);

/* Day (1) or night (0) lighting: night dims the headlight and the model's lights. */
void sim_render_set_daylight(sim_render_t *r, const mjModel *m, int day);

/* Re-uploads texture tex_id after its pixels in m->tex_rgb changed. */
void sim_render_upload_texture(sim_render_t *r, const mjModel *m, int tex_id);

#ifdef __cplusplus
}
#endif
#endif /* SIM_RENDER_H */
