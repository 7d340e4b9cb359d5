/* sim_viewer: the optional GLFW window of the sim (only when a display exists).
 *
 * Views: driver's eye (the car's front camera), bird's eye (a camera tracking the car from
 * behind and above), god's eye (the map's "eye" camera, else an overview of the whole model),
 * free (an overview), and each overhead Eye camera of the map.
 * Keys: 1/2/3/4 views, Tab next car, N day/night, Space pause, R reset, M the Menu Panel,
 * H the HUD, C the camera thumbnails, T manual or autonomous driving, Esc or closing quits; in
 * manual mode the arrows or W/A/S/D held drive the ego car (the caller turns them into commands:
 * in.drive_keys). The Menu Panel (MuJoCo's mjui, sim_viewer_ui.c) has the sections Simulation (map,
 * pause, step, reset, quit), Car (the ego car, autonomous or manual driving), View (camera, light
 * level, quality: low, high or ultra; the window's render scale; the render scale of the cars'
 * sensor cameras, which the caller applies; HUD), Sensors (LIDAR rays, the ego car's front
 * and rear camera thumbnails, bottom left of the scene) and Record (start / stop). The HUD is text
 * the caller sets (sim_viewer_set_hud), drawn at the top right. The viewer only reports what the
 * user asked (sim_viewer_input_t); the sim's main loop acts.
 *
 * The window's OpenGL context is made with EGL (GLFW_EGL_CONTEXT_API) so that it coexists
 * with the headless sim_render EGL renderer in one process (MuJoCo binds its GL calls to one
 * loader); use it with the EGL backend. Caller owns the viewer.
 *
 * Threads: by default one thread does everything (sim_viewer_frame). After sim_viewer_detach,
 * the thread that made the viewer (GLFW's events belong to it) only polls (sim_viewer_poll),
 * sets the Driving radio (sim_viewer_set_manual) and reads sim_viewer_camera_id; one other
 * thread draws (sim_viewer_draw) and alone calls the other setters. The window's events reach
 * the drawing thread through a queue and the input state comes back through sim_viewer_poll,
 * both under a lock held for copies only: the polling thread never waits on GL.
 *
 * Render scale: the scene is drawn at in.render_scale of the window's pixels (0.25..1) and
 * stretched to the window; the HUD and the panel stay sharp. With a software rasteriser (Mesa's
 * llvmpipe, softpipe) the default is SIM_VIEWER_SOFTWARE_SCALE, else 1.
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
  SIM_VIEW_FREE,       /* an overview of the whole model */
  SIM_VIEW_EYE0,       /* the map's first overhead camera; SIM_VIEW_EYE0 + k its k-th */
} sim_viewer_view_t;

typedef struct sim_viewer_input {
  int quit;            /* 1 once Esc was pressed or the window closed */
  int reset_requested; /* R pressed since the previous frame (edge, cleared each frame) */
  int paused;          /* Space toggles: while 1 the sim should not step */
  int day;             /* N toggles: 1 day, 0 night (the light level 1 or 0.15) */
  int car;             /* shown (ego) car, 1-based (Tab cycles) */
  int view;            /* sim_viewer_view_t: 1/2/3/4, the Camera radio */
  double light_level;  /* 0..1 scales the scene's lights (1 day) */
  int shadows, reflections, skybox; /* graphics quality (all 0: the fast default) */
  int hud;             /* 1: the HUD (figures, status line, keys) is drawn (H toggles) */
  int lidar_rays;      /* 1: the caller's LIDAR rays are drawn */
  int thumbnails;      /* 1: the ego car's front and rear camera views are drawn (C toggles) */
  int step_requested;  /* Step clicked (edge): one step while paused */
  int record_toggled;  /* the Record button (edge): start or stop recording */
  int manual;          /* the Car section's Driving radio (T toggles): 0 autonomous, 1 manual */
  int drive_keys;      /* SIM_VIEWER_KEY_* bits of the drive keys held now */
  double render_scale; /* the scene's share of the window's pixels per side, 0.25..1 */
  double camera_scale; /* the View section's Cam scale radio: the render scale per side the
                          caller gives the cars' sensor cameras (1, 0.5 or 0.25) */
} sim_viewer_input_t;

#define SIM_VIEWER_SOFTWARE_SCALE 0.5 /* the default render scale on software GL */
#define SIM_VIEWER_MIN_SCALE 0.25

/* The parts of a frame that sim_viewer_parts times (with timing on). */
typedef enum sim_viewer_part {
  SIM_VIEWER_PART_UPDATE = 0, /* mjv_updateScene, the light level, the LIDAR rays (CPU) */
  SIM_VIEWER_PART_SCENE,      /* mjr_render: geoms, and shadows/reflections/skybox when on */
  SIM_VIEWER_PART_BLIT,       /* the scaled scene stretched to the window (scale < 1) */
  SIM_VIEWER_PART_THUMBS,     /* the front and rear camera thumbnails (when on) */
  SIM_VIEWER_PART_HUD,        /* mjr_overlay: the status line, the keys and the HUD's figures */
  SIM_VIEWER_PART_UI,         /* the Menu Panel (mjui_update when changed, mjui_render) */
  SIM_VIEWER_PART_SWAP,       /* glfwSwapBuffers */
  SIM_VIEWER_PARTS
} sim_viewer_part_t;

/* in.drive_keys: the arrows or W/S/A/D held */
#define SIM_VIEWER_KEY_FORWARD 1
#define SIM_VIEWER_KEY_BACK 2
#define SIM_VIEWER_KEY_LEFT 4
#define SIM_VIEWER_KEY_RIGHT 8

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

/* Threads (see the top): from now on this thread polls and another draws. Releases the GL
 * context from this thread. */
void sim_viewer_detach(sim_viewer_t *v);
/* The drawing thread's frame of d (the caller's snapshot, not written while drawn): applies the
 * queued window events, renders, swaps. Binds the GL context to the calling thread at its first
 * call. Returns 0, or -1 on a GL error. */
int sim_viewer_draw(sim_viewer_t *v, const mjModel *m, mjData *d);
/* The drawing thread, before it ends: releases the GL context (sim_viewer_destroy needs it). */
void sim_viewer_release(sim_viewer_t *v);

/* The render scale (clamped to SIM_VIEWER_MIN_SCALE..1): a flag's override of the default.
 * Before sim_viewer_detach. */
void sim_viewer_set_render_scale(sim_viewer_t *v, double scale);
/* The Cam scale radio's start (--camera-scale): the element equal to scale (1, 0.5, 0.25) is
 * lit, none for another value until one is clicked. Before sim_viewer_detach. */
void sim_viewer_set_camera_scale(sim_viewer_t *v, double scale);
/* Graphics quality, the paper's three levels set at once (the View section's check boxes):
 * low none, high shadows, ultra shadows, reflections and the skybox. Before sim_viewer_detach. */
enum { SIM_VIEWER_QUALITY_LOW = 0, SIM_VIEWER_QUALITY_HIGH, SIM_VIEWER_QUALITY_ULTRA };
void sim_viewer_set_quality(sim_viewer_t *v, int quality);
/* Sets the nice of the rasteriser threads (Mesa's llvmpipe-*) that the window's context
 * started (none on a GPU): a software rasteriser's frames then take the CPU that others leave. */
void sim_viewer_nice(sim_viewer_t *v, int nice);
/* The GL renderer's name (GL_RENDERER) and 1 if it is a software rasteriser. */
const char *sim_viewer_renderer(const sim_viewer_t *v, int *software);

/* Timing of the frame's parts: with on, every SIM_VIEWER_TIMED_EVERY-th frame ends each part
 * with glFinish (so that each is charged its own GPU or rasteriser time; on a busy CPU every
 * glFinish also waits for the rasteriser's threads to be scheduled, so a timed frame is slower
 * than the others) and the first SIM_VIEWER_TIMED_FRAMES of them are kept. Before the first
 * frame. sim_viewer_last_timed: 1 if the frame just drawn was one of them. */
#define SIM_VIEWER_TIMED_FRAMES 2048
#define SIM_VIEWER_TIMED_EVERY 4
void sim_viewer_time_parts(sim_viewer_t *v, int on);
int sim_viewer_last_timed(const sim_viewer_t *v);
/* The median wall time of each part over the timed frames [ms] into ms[SIM_VIEWER_PARTS], and
 * its name (e.g. "scene") into names when not NULL. Returns the number of frames timed. Not
 * while frames are drawn. */
long sim_viewer_parts(const sim_viewer_t *v, double *ms, const char **names);

/* Handles the window's events without drawing and copies the input state into *in (its edges
 * reported once, as by sim_viewer_frame). */
void sim_viewer_poll(sim_viewer_t *v, sim_viewer_input_t *in);

/* Feeds one key as if pressed (GLFW_KEY_* code): the key handling, exposed for tests. */
void sim_viewer_key(sim_viewer_t *v, int glfw_key);

/* The HUD's text: titles (left column) and values (right column), lines split by '\n', drawn at
 * the top right while in.hud is on. Copied (truncated at 4 kB). */
void sim_viewer_set_hud(sim_viewer_t *v, const char *titles, const char *values);
/* The map's name in the Simulation section (copied). */
void sim_viewer_set_map_name(sim_viewer_t *v, const char *name);
/* LIDAR rays to draw while in.lidar_rays is on: n end points (x, y, z [m], world) seen from
 * origin; replaces the previous set. NULL / 0 clears. */
void sim_viewer_set_rays(sim_viewer_t *v, const double origin[3], const float *ends_xyz, int n);

/* The MJCF camera id the current view shows (driver's, god's, an overhead Eye), or -1 for the
 * views that follow no fixed camera (bird's, free). After the first frame. */
int sim_viewer_camera_id(const sim_viewer_t *v);

/* Scripted input for tests (the same paths as the window's callbacks): a left click at
 * window position (x_px, y_px; y down from the top), and the centre of the Menu Panel item
 * named name (its label, e.g. "Pause", "Reset"; radio elements by "Camera/Bird's") after the
 * first frame. sim_viewer_item_at returns 0, or -1 when no such item is shown. */
void sim_viewer_click(sim_viewer_t *v, double x_px, double y_px);
int sim_viewer_item_at(const sim_viewer_t *v, const char *name, double *x_px, double *y_px);
/* A key pressed (1) or released (0), as from the keyboard (GLFW_KEY_* code). */
void sim_viewer_key_state(sim_viewer_t *v, int glfw_key, int down);
/* Sets the Driving radio (0 autonomous, 1 manual): the caller's way back when manual driving
 * cannot start. */
void sim_viewer_set_manual(sim_viewer_t *v, int manual);

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
