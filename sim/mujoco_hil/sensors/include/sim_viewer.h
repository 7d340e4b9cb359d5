/* sim_viewer: the optional GLFW window of the sim (only when a display exists).
 *
 * Views: driver's eye (the car's front camera), bird's eye (a camera tracking the car from
 * behind and above), god's eye (the map's "eye" camera, else an overview of the whole model).
 * Keys: 1/2/3 views, Tab next car, N day/night, Space pause, R reset, Esc or closing quits.
 * The viewer only reports pause/reset/quit; the sim's main loop acts on them.
 *
 * The window's OpenGL context is made with EGL (GLFW_EGL_CONTEXT_API) so that it coexists
 * with the headless sim_render EGL renderer in one process (MuJoCo binds its GL calls to one
 * loader); use it with the EGL backend. Same thread as the renderer. Caller owns the viewer.
 */
#ifndef SIM_VIEWER_H
#define SIM_VIEWER_H

#include <stddef.h>

#include <mujoco/mujoco.h>

#ifdef __cplusplus
extern "C" {
#endif

typedef enum sim_viewer_view {
  SIM_VIEW_DRIVER = 0, /* the car's front camera */
  SIM_VIEW_BIRD,       /* tracking the car from behind and above */
  SIM_VIEW_GOD,        /* the map's "eye" camera, else a free overview */
} sim_viewer_view_t;

typedef struct sim_viewer_input {
  int quit;               /* 1 once Esc was pressed or the window closed */
  int reset_requested;    /* R pressed since the previous frame (edge, cleared each frame) */
  int paused;             /* Space toggles: while 1 the sim should not step */
  int day;                /* N toggles: 1 day, 0 night */
  int car;                /* shown car, 1-based (Tab cycles) */
  sim_viewer_view_t view; /* 1/2/3 */
} sim_viewer_input_t;

typedef struct sim_viewer sim_viewer_t;

/* 1 if an X11 or Wayland display is named in the environment, else 0. */
int sim_viewer_display_available(void);

/* Opens a width_px x height_px window for model m with ncars cars whose base bodies are
 * printf(body_fmt, i) (e.g. "nigel%d/base_link") and front cameras printf(cam_fmt, i)
 * (e.g. "nigel%d/cam_front"). Returns NULL with a message in err when there is no display or
 * no GL context. */
sim_viewer_t *sim_viewer_create(const mjModel *m, int ncars, const char *body_fmt,
                                const char *cam_fmt, int width_px, int height_px, char *err,
                                size_t err_len);
void sim_viewer_destroy(sim_viewer_t *v);

/* Renders the current view of d, swaps, polls events and copies the input state into *in.
 * Returns 0, or -1 on a GL error. */
int sim_viewer_frame(sim_viewer_t *v, const mjModel *m, mjData *d, sim_viewer_input_t *in);

/* Feeds one key as if pressed (GLFW_KEY_* code): the key handling, exposed for tests. */
void sim_viewer_key(sim_viewer_t *v, int glfw_key);

/* With capture on, every frame is also read back (before the swap) so that
 * sim_viewer_read_rgb can return it. Off by default (it costs a readback). For tests. */
void sim_viewer_capture(sim_viewer_t *v, int on);
/* The last captured frame as RGB rows top-down; rgb holds width*height*3 bytes of the window's
 * framebuffer size (sim_viewer_size). Returns 0, or -1 if nothing was captured. */
void sim_viewer_size(const sim_viewer_t *v, int *width_px, int *height_px);
int sim_viewer_read_rgb(const sim_viewer_t *v, unsigned char *rgb);

#ifdef __cplusplus
}
#endif
#endif /* SIM_VIEWER_H */
