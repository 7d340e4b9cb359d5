/* The viewer's own state, shared by sim_viewer.c (window, scene, frame) and sim_viewer_ui.c
 * (the Menu Panel: mjui sections, mouse and keys). Not a public header. */
#ifndef SIM_VIEWER_INTERNAL_H
#define SIM_VIEWER_INTERNAL_H

#include <pthread.h>

#include <mujoco/mujoco.h>

#include "sim_viewer.h"

#define SIM_VIEWER_HUD_CHARS 4096
#define SIM_VIEWER_MAX_EYES 8
#define SIM_VIEWER_NIGHT_LEVEL 0.15 /* N: the light level of night (day 1) */
#define SIM_VIEWER_QUEUE 256        /* window events queued for the drawing thread */
#define SIM_VIEWER_SHADOW_PX 2048   /* [px] the shadow map's side when the model has none */
#define SIM_VIEWER_MAX_RASTER 64    /* rasteriser threads (llvmpipe-*) looked at */
#define SIM_VIEWER_THUMB_SHARE 0.3  /* a thumbnail's width as a share of the scene's */

/* A window event on its way from the polling thread to the drawing thread. */
typedef struct sim_viewer_event {
  enum { SIM_VIEWER_EV_KEY, SIM_VIEWER_EV_BUTTON, SIM_VIEWER_EV_MANUAL } kind;
  int code, down; /* GLFW key and pressed (KEY), pressed (BUTTON), the radio (MANUAL) */
  double x_px, y_px;
} sim_viewer_event_t;

struct GLFWwindow;

struct sim_viewer {
  struct GLFWwindow *win;
  mjrContext con;
  mjvScene scn;
  mjvOption opt;
  mjvCamera cam;
  int ncars;
  int *car_body;                    /* base body id per car (index car-1), -1 if missing */
  int *car_cam;                     /* front camera id per car, -1 if missing */
  int *car_rear_cam;                /* rear camera id per car (the front's name, rear), or -1 */
  int eye_cam[SIM_VIEWER_MAX_EYES]; /* the map's overhead cameras ("eye", "eye_*") */
  int neyes;
  int w, h;
  sim_viewer_input_t in;
  int capture;
  unsigned char *rgb; /* last captured frame, top-down */
  size_t rgb_px;      /* its capacity [px] */
  int have_rgb;
  /* the Menu Panel */
  mjUI ui;
  mjuiState ui_state;
  int panel;                   /* 1: shown (M toggles) */
  int ui_car;                  /* the Ego car radio: in.car - 1 */
  int ui_cam_scale;            /* the Cam scale radio: in.camera_scale's element, or -1 */
  int ui_dirty;                /* the panel's buffer needs a redraw (mjui_update) */
  sim_viewer_input_t ui_shown; /* the state the buffer shows */
  const mjModel *model;
  double cursor_x, cursor_y; /* [px] window coordinates, y down (GLFW) */
  char map_name[128], rtf_text[64];
  double ray_origin[3]; /* [m] world */
  float *ray_end;       /* nrays x 3 [m] world */
  int nrays;
  char hud_titles[SIM_VIEWER_HUD_CHARS], hud_values[SIM_VIEWER_HUD_CHARS];
  char renderer[128];                    /* GL_RENDERER */
  int raster_tid[SIM_VIEWER_MAX_RASTER]; /* the rasteriser threads its context started */
  int nraster;
  int software; /* 1: a software rasteriser (llvmpipe, softpipe) */
  /* threads (sim_viewer_detach): mu guards the queue, in_pub, cam_pub and fb_w/h */
  int threaded, bound; /* bound: the context is current on the drawing thread */
  int mu_made;
  pthread_mutex_t mu;
  sim_viewer_event_t queue[SIM_VIEWER_QUEUE];
  int nqueued;
  long dropped;              /* events lost to a full queue */
  sim_viewer_input_t in_pub; /* the drawing thread's input state, edges kept until polled */
  int cam_pub;               /* sim_viewer_camera_id as of the last frame */
  int fb_w, fb_h;            /* [px] the framebuffer's size, read on the polling thread */
  /* timing (sim_viewer_time_parts) */
  int timing, timing_now; /* timing_now: this frame's parts are timed */
  long timed, drawn;      /* frames timed, drawn */
  float *part_ms;         /* SIM_VIEWER_TIMED_FRAMES x SIM_VIEWER_PARTS [ms] */
  void (*gl_finish)(void);
  /* glBindFramebuffer and glBlitFramebuffer of the backend in use (MuJoCo exports neither) */
  void (*gl_bind_fb)(unsigned, unsigned);
  void (*gl_blit_fb)(int, int, int, int, int, int, int, int, unsigned, unsigned);
};

/* The Menu Panel: built once (sim_viewer_create), its figures refreshed and drawn each frame
 * over the left of the scene, and the mouse events it owns. */
void sim_viewer_ui_init(sim_viewer_t *v);
void sim_viewer_ui_render(sim_viewer_t *v);
/* A mouse button (press 1 / release 0) at window position (x_px, y_px, y down). Returns 1 when
 * the panel took it. */
int sim_viewer_ui_mouse(sim_viewer_t *v, double x_px, double y_px, int press);
/* The names of the camera radio (driver, bird, god, free, then the overhead cameras). */
void sim_viewer_ui_camera_names(const sim_viewer_t *v, const mjModel *m, char *out, size_t n);

#endif
