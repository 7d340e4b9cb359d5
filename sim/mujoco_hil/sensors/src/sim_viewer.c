/* sim_viewer: see sim_viewer.h. */
#include "sim_viewer.h"

#include <autodrive_channels.h>
#include <dirent.h>
#include <dlfcn.h> /* RTLD_NODELETE, dl_iterate_phdr: _GNU_SOURCE from the build */
#include <link.h>
#include <sys/resource.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include <GLFW/glfw3.h>

#include "sim_viewer_internal.h"

#ifndef GL_READ_FRAMEBUFFER /* GL 3.0, not in every GL/gl.h */
#define GL_READ_FRAMEBUFFER 0x8CA8
#define GL_DRAW_FRAMEBUFFER 0x8CA9
#endif

/* LIDAR rays drawn, at most (a scan of the RPLIDAR A1 has ~360-720) */
#define VIEWER_MAX_RAYS 1024

static int glfw_users; /* glfwInit/glfwTerminate are process-wide */

static int viewer_pin_dri(struct dl_phdr_info *info, size_t size, void *unused) {
  (void)size;
  (void)unused;
  if (info->dlpi_name && strstr(info->dlpi_name, "/dri/")) {
    void *h = dlopen(info->dlpi_name, RTLD_NOW | RTLD_NOLOAD | RTLD_NODELETE);
    if (h) dlclose(h); /* the reference goes; RTLD_NODELETE keeps it mapped */
  }
  return 0;
}

/* Mesa's DRI driver (swrast_dri.so: llvmpipe under Xvfb) is loaded with the window's GL
 * context and unloaded at glfwTerminate, before LeakSanitizer reads the stacks at exit: its
 * frames would be an "<unknown module>" that no suppression can name. Kept mapped, its
 * allocations carry its name (tests/lsan.supp). */
static void viewer_pin_gl_driver(void) {
  dl_iterate_phdr(viewer_pin_dri, NULL);
}

/* The ids of this process's threads named llvmpipe-* (Mesa's rasteriser threads), up to max;
 * returns how many. */
static int viewer_raster_threads(int *tid, int max) {
  DIR *dir = opendir("/proc/self/task");
  int n = 0;
  struct dirent *e;
  while (dir && n < max && (e = readdir(dir)) != NULL) {
    char path[64], comm[32] = "";
    snprintf(path, sizeof path, "/proc/self/task/%.20s/comm", e->d_name);
    FILE *f = e->d_name[0] != '.' ? fopen(path, "r") : NULL;
    if (!f) continue;
    if (fgets(comm, sizeof comm, f) && !strncmp(comm, "llvmpipe", 8)) tid[n++] = atoi(e->d_name);
    fclose(f);
  }
  if (dir) closedir(dir);
  return n;
}

/* The rasteriser threads the window's context started: those not in before[0..nbefore). */
static void viewer_find_raster_threads(sim_viewer_t *v, const int *before, int nbefore) {
  int now[SIM_VIEWER_MAX_RASTER];
  const int n = viewer_raster_threads(now, SIM_VIEWER_MAX_RASTER);
  for (int i = 0; i < n; i++) {
    int old = 0;
    for (int k = 0; k < nbefore && !old; k++) old = before[k] == now[i];
    if (!old) v->raster_tid[v->nraster++] = now[i];
  }
}

void sim_viewer_nice(sim_viewer_t *v, int nice) {
  for (int i = 0; i < v->nraster; i++) setpriority(PRIO_PROCESS, (id_t)v->raster_tid[i], nice);
}

int sim_viewer_display_available(void) {
  const char *x = getenv("DISPLAY"), *wl = getenv("WAYLAND_DISPLAY");
  return (x && *x) || (wl && *wl);
}

void sim_viewer_key(sim_viewer_t *v, int key) {
  switch (key) {
    case GLFW_KEY_1: v->in.view = SIM_VIEW_DRIVER; break;
    case GLFW_KEY_2: v->in.view = SIM_VIEW_BIRD; break;
    case GLFW_KEY_3: v->in.view = SIM_VIEW_GOD; break;
    case GLFW_KEY_4: v->in.view = SIM_VIEW_FREE; break;
    case GLFW_KEY_TAB: v->in.car = v->in.car % v->ncars + 1; break;
    case GLFW_KEY_N:
      v->in.day = !v->in.day;
      v->in.light_level = v->in.day ? 1.0 : SIM_VIEWER_NIGHT_LEVEL;
      break;
    case GLFW_KEY_M: v->panel = !v->panel; break;
    case GLFW_KEY_H: v->in.hud = !v->in.hud; break;
    case GLFW_KEY_C: v->in.thumbnails = !v->in.thumbnails; break;
    case GLFW_KEY_SPACE: v->in.paused = !v->in.paused; break;
    case GLFW_KEY_R: v->in.reset_requested = 1; break;
    case GLFW_KEY_T: v->in.manual = !v->in.manual; break;
    case GLFW_KEY_ESCAPE: v->in.quit = 1; break;
    default: break;
  }
}

/* The SIM_VIEWER_KEY_* bit of a drive key, 0 for the others. */
static int viewer_drive_bit(int key) {
  switch (key) {
    case GLFW_KEY_UP:
    case GLFW_KEY_W: return SIM_VIEWER_KEY_FORWARD;
    case GLFW_KEY_DOWN:
    case GLFW_KEY_S: return SIM_VIEWER_KEY_BACK;
    case GLFW_KEY_LEFT:
    case GLFW_KEY_A: return SIM_VIEWER_KEY_LEFT;
    case GLFW_KEY_RIGHT:
    case GLFW_KEY_D: return SIM_VIEWER_KEY_RIGHT;
    default: return 0;
  }
}

void sim_viewer_key_state(sim_viewer_t *v, int key, int down) {
  const int bit = viewer_drive_bit(key);
  if (bit) v->in.drive_keys = down ? (v->in.drive_keys | bit) : (v->in.drive_keys & ~bit);
  if (down) sim_viewer_key(v, key);
}

/* Threaded: an event for the drawing thread (which alone changes the input state). */
static void viewer_push(sim_viewer_t *v, sim_viewer_event_t e) {
  pthread_mutex_lock(&v->mu);
  if (v->nqueued < SIM_VIEWER_QUEUE)
    v->queue[v->nqueued++] = e;
  else
    v->dropped++;
  pthread_mutex_unlock(&v->mu);
}

static void viewer_set_manual_now(sim_viewer_t *v, int manual) {
  v->in.manual = manual != 0;
  v->in.drive_keys = 0;
}

void sim_viewer_set_manual(sim_viewer_t *v, int manual) {
  if (v->threaded)
    viewer_push(v, (sim_viewer_event_t){.kind = SIM_VIEWER_EV_MANUAL, .code = manual != 0});
  else
    viewer_set_manual_now(v, manual);
}

static void on_key(GLFWwindow *w, int key, int scancode, int action, int mods) {
  (void)scancode;
  (void)mods;
  sim_viewer_t *v = glfwGetWindowUserPointer(w);
  if (action == GLFW_REPEAT) return;
  if (v->threaded)
    viewer_push(v, (sim_viewer_event_t){
                       .kind = SIM_VIEWER_EV_KEY, .code = key, .down = action == GLFW_PRESS});
  else
    sim_viewer_key_state(v, key, action == GLFW_PRESS);
}

static void on_cursor(GLFWwindow *w, double x, double y) {
  sim_viewer_t *v = glfwGetWindowUserPointer(w);
  v->cursor_x = x;
  v->cursor_y = y;
}

static void on_button(GLFWwindow *w, int button, int action, int mods) {
  (void)mods;
  sim_viewer_t *v = glfwGetWindowUserPointer(w);
  if (button != GLFW_MOUSE_BUTTON_LEFT) return;
  if (v->threaded) /* the panel's event handling touches GL: the drawing thread's */
    viewer_push(v, (sim_viewer_event_t){.kind = SIM_VIEWER_EV_BUTTON,
                                        .down = action == GLFW_PRESS,
                                        .x_px = v->cursor_x,
                                        .y_px = v->cursor_y});
  else
    sim_viewer_ui_mouse(v, v->cursor_x, v->cursor_y, action == GLFW_PRESS);
}

void sim_viewer_click(sim_viewer_t *v, double x_px, double y_px) {
  sim_viewer_ui_mouse(v, x_px, y_px, 1);
  sim_viewer_ui_mouse(v, x_px, y_px, 0);
}

void sim_viewer_set_hud(sim_viewer_t *v, const char *titles, const char *values) {
  snprintf(v->hud_titles, sizeof v->hud_titles, "%s", titles ? titles : "");
  snprintf(v->hud_values, sizeof v->hud_values, "%s", values ? values : "");
}

void sim_viewer_set_map_name(sim_viewer_t *v, const char *name) {
  snprintf(v->map_name, sizeof v->map_name, "%s", name ? name : "");
  char *ext = strrchr(v->map_name, '.');
  if (ext && !strcmp(ext, ".xml")) *ext = 0;
  v->ui_dirty = 1;
  if (v->ui.nsect > 0) /* the Simulation section's title: "Simulation  <map>" */
    snprintf(v->ui.sect[0].name, sizeof v->ui.sect[0].name, "Simulation  %.26s",
             v->map_name[0] ? v->map_name : "-");
}

void sim_viewer_set_rays(sim_viewer_t *v, const double origin[3], const float *ends_xyz, int n) {
  v->nrays = (!origin || !ends_xyz || n < 0) ? 0 : (n > VIEWER_MAX_RAYS ? VIEWER_MAX_RAYS : n);
  if (v->nrays == 0) return;
  memcpy(v->ray_origin, origin, sizeof v->ray_origin);
  memcpy(v->ray_end, ends_xyz, (size_t)v->nrays * 3 * sizeof(float));
}

/* GL_RENDERER and whether it rasterises in software (then the scene is drawn scaled down). */
static void viewer_detect_renderer(sim_viewer_t *v) {
  typedef const unsigned char *(*get_string_fn)(unsigned int);
  const get_string_fn get_string = (get_string_fn)glfwGetProcAddress("glGetString");
  const unsigned char *name = get_string ? get_string(GL_RENDERER) : NULL;
  snprintf(v->renderer, sizeof v->renderer, "%s", name ? (const char *)name : "unknown");
  v->software = strstr(v->renderer, "llvmpipe") || strstr(v->renderer, "softpipe") ||
                strstr(v->renderer, "Software Rasterizer") || strstr(v->renderer, "SWR");
  v->gl_finish = (void (*)(void))glfwGetProcAddress("glFinish");
  v->gl_bind_fb = (void (*)(unsigned, unsigned))glfwGetProcAddress("glBindFramebuffer");
  v->gl_blit_fb = (void (*)(int, int, int, int, int, int, int, int, unsigned,
                            unsigned))glfwGetProcAddress("glBlitFramebuffer");
}

sim_viewer_t *sim_viewer_create(const mjModel *m, int ncars, const char *body_fmt,
                                const char *cam_fmt, int width_px, int height_px, char *err,
                                size_t err_len) {
  if (!m || ncars < 1 || !body_fmt || !cam_fmt || width_px < 64 || height_px < 64) {
    if (err && err_len)
      snprintf(err, err_len, "sim_viewer: bad arguments (need a model, >= 1 car, size >= 64 px)");
    return NULL;
  }
  if (!sim_viewer_display_available()) {
    if (err && err_len)
      snprintf(err, err_len, "sim_viewer: no display (DISPLAY / WAYLAND_DISPLAY unset)");
    return NULL;
  }
  if (glfw_users == 0 && !glfwInit()) {
    if (err && err_len)
      snprintf(err, err_len, "sim_viewer: glfwInit failed (display '%s')",
               getenv("DISPLAY") ? getenv("DISPLAY") : "");
    return NULL;
  }
  glfw_users++;
  sim_viewer_t *v = calloc(1, sizeof *v);
  if (!v) return NULL;
  int raster_before[SIM_VIEWER_MAX_RASTER];
  const int nraster_before = viewer_raster_threads(raster_before, SIM_VIEWER_MAX_RASTER);
  glfwWindowHint(GLFW_CONTEXT_CREATION_API, GLFW_EGL_CONTEXT_API);
  glfwWindowHint(GLFW_SAMPLES, 0);
  glfwWindowHint(GLFW_DOUBLEBUFFER, GLFW_TRUE);
  v->win = glfwCreateWindow(width_px, height_px, "AutoDRIVE Nigel sim", NULL, NULL);
  if (!v->win) {
    if (err && err_len)
      snprintf(err, err_len, "sim_viewer: cannot open a %dx%d EGL window", width_px, height_px);
    sim_viewer_destroy(v);
    return NULL;
  }
  glfwSetWindowUserPointer(v->win, v);
  glfwSetKeyCallback(v->win, on_key);
  glfwSetCursorPosCallback(v->win, on_cursor);
  glfwSetMouseButtonCallback(v->win, on_button);
  glfwMakeContextCurrent(v->win);
  glfwSwapInterval(0); /* never let vsync throttle the sim */
  glfwGetFramebufferSize(v->win, &v->w, &v->h);
  v->fb_w = v->w;
  v->fb_h = v->h;
  /* the offscreen buffer holds the scaled scene: the window's size, no multisampling (a
   * software rasteriser pays for every sample); a shallow copy, the arrays stay shared */
  mjModel vis = *m;
  vis.vis.global.offwidth = v->w;
  vis.vis.global.offheight = v->h;
  vis.vis.quality.offsamples = 0;
  /* the maps turn the shadow map off for the sensor cameras; the window's Shadows need one */
  if (vis.vis.quality.shadowsize <= 0) vis.vis.quality.shadowsize = SIM_VIEWER_SHADOW_PX;
  mjr_defaultContext(&v->con);
  mjr_makeContext(&vis, &v->con, mjFONTSCALE_100);
  viewer_pin_gl_driver();
  mjr_setBuffer(mjFB_WINDOW, &v->con);
  viewer_detect_renderer(v);
  viewer_find_raster_threads(v, raster_before, nraster_before);
  mjv_defaultScene(&v->scn);
  mjv_makeScene(m, &v->scn, 2000 + 4 * m->ngeom);
  v->scn.flags[mjRND_SHADOW] = 0;
  v->scn.flags[mjRND_REFLECTION] = 0;
  mjv_defaultOption(&v->opt);
  mjv_defaultCamera(&v->cam);
  v->ncars = ncars;
  v->car_body = calloc((size_t)ncars, sizeof(int));
  v->car_cam = calloc((size_t)ncars, sizeof(int));
  v->car_rear_cam = calloc((size_t)ncars, sizeof(int));
  v->ray_end = malloc(VIEWER_MAX_RAYS * 3 * sizeof(float));
  v->rgb_px = (size_t)v->w * (size_t)v->h;
  v->rgb = malloc(v->rgb_px * 3);
  if (!v->car_body || !v->car_cam || !v->car_rear_cam || !v->rgb || !v->ray_end) {
    sim_viewer_destroy(v);
    return NULL;
  }
  for (int i = 1; i <= ncars; i++) {
    char name[128];
    snprintf(name, sizeof name, body_fmt, i);
    v->car_body[i - 1] = mj_name2id(m, mjOBJ_BODY, name);
    snprintf(name, sizeof name, cam_fmt, i);
    v->car_cam[i - 1] = mj_name2id(m, mjOBJ_CAMERA, name);
    char *front = strstr(name, "front"); /* nigel1/cam_front -> nigel1/cam_rear */
    v->car_rear_cam[i - 1] = -1;
    if (front) {
      char rear[128];
      snprintf(rear, sizeof rear, "%.*srear%s", (int)(front - name), name, front + 5);
      v->car_rear_cam[i - 1] = mj_name2id(m, mjOBJ_CAMERA, rear);
    }
  }
  for (int id = 0; id < m->ncam && v->neyes < SIM_VIEWER_MAX_EYES; id++) {
    const char *name = mj_id2name(m, mjOBJ_CAMERA, id);
    if (name && (!strcmp(name, "eye") || !strncmp(name, "eye_", 4))) v->eye_cam[v->neyes++] = id;
  }
  v->model = m;
  v->in.day = 1;
  v->in.light_level = 1.0;
  v->in.hud = 1;
  v->in.car = 1;
  v->in.view = SIM_VIEW_BIRD;
  v->in.render_scale = v->software ? SIM_VIEWER_SOFTWARE_SCALE : 1.0;
  v->in.camera_scale = 1.0;
  v->cam_pub = -1;
  v->panel = 1;
  if (pthread_mutex_init(&v->mu, NULL) != 0) {
    if (err && err_len) snprintf(err, err_len, "sim_viewer: cannot make its lock");
    sim_viewer_destroy(v);
    return NULL;
  }
  v->mu_made = 1;
  sim_viewer_ui_init(v);
  return v;
}

void sim_viewer_destroy(sim_viewer_t *v) {
  if (!v) return;
  if (v->win) {
    glfwMakeContextCurrent(v->win);
    mjv_freeScene(&v->scn);
    mjr_freeContext(&v->con);
    glfwDestroyWindow(v->win);
  }
  free(v->car_body);
  free(v->car_cam);
  free(v->car_rear_cam);
  free(v->ray_end);
  free(v->rgb);
  free(v->part_ms);
  if (v->mu_made) pthread_mutex_destroy(&v->mu);
  free(v);
  if (--glfw_users == 0) glfwTerminate();
}

void sim_viewer_capture(sim_viewer_t *v, int on) {
  v->capture = on;
}

void sim_viewer_size(const sim_viewer_t *v, int *width_px, int *height_px) {
  *width_px = v->w;
  *height_px = v->h;
}

int sim_viewer_read_rgb(const sim_viewer_t *v, unsigned char *rgb) {
  if (!v->have_rgb) return -1;
  memcpy(rgb, v->rgb, (size_t)v->w * (size_t)v->h * 3);
  return 0;
}

/* Points the abstract camera at the chosen view; falls back to a free overview. */
static void viewer_camera(sim_viewer_t *v, const mjModel *m) {
  int car = v->in.car - 1;
  mjvCamera *c = &v->cam;
  if (v->in.view == SIM_VIEW_DRIVER && v->car_cam[car] >= 0) {
    c->type = mjCAMERA_FIXED;
    c->fixedcamid = v->car_cam[car];
  } else if (v->in.view == SIM_VIEW_BIRD && v->car_body[car] >= 0) {
    c->type = mjCAMERA_TRACKING;
    c->trackbodyid = v->car_body[car];
    c->distance = 0.9;  /* [m] behind and above the car */
    c->elevation = -30; /* [deg] */
    c->azimuth = 180;   /* [deg] looking along +x of the world; follows position, not yaw */
  } else if (v->in.view == SIM_VIEW_GOD && v->neyes > 0) {
    c->type = mjCAMERA_FIXED;
    c->fixedcamid = v->eye_cam[0];
  } else if (v->in.view >= SIM_VIEW_EYE0 && v->in.view - SIM_VIEW_EYE0 < v->neyes) {
    c->type = mjCAMERA_FIXED;
    c->fixedcamid = v->eye_cam[v->in.view - SIM_VIEW_EYE0];
  } else {
    c->type = mjCAMERA_FREE;
    for (int i = 0; i < 3; i++) c->lookat[i] = m->stat.center[i];
    c->distance = 1.5 * m->stat.extent;
    c->elevation = -60;
    c->azimuth = 90;
  }
}

int sim_viewer_camera_id(const sim_viewer_t *v) {
  if (!v->threaded) return v->cam.type == mjCAMERA_FIXED ? v->cam.fixedcamid : -1;
  sim_viewer_t *w = (sim_viewer_t *)v; /* the lock, not the viewer, changes */
  pthread_mutex_lock(&w->mu);
  const int id = w->cam_pub;
  pthread_mutex_unlock(&w->mu);
  return id;
}

/* The scene seen from cam with the light level and the graphics quality. */
static void viewer_fill_scene(sim_viewer_t *v, const mjModel *m, mjData *d, mjvCamera *cam) {
  mjv_updateScene(m, d, &v->opt, NULL, cam, mjCAT_ALL, &v->scn);
  v->scn.flags[mjRND_SHADOW] = (mjtByte)(v->in.shadows != 0);
  v->scn.flags[mjRND_REFLECTION] = (mjtByte)(v->in.reflections != 0);
  v->scn.flags[mjRND_SKYBOX] = (mjtByte)(v->in.skybox != 0);
  const float level = (float)(v->in.light_level < 0   ? 0
                              : v->in.light_level > 1 ? 1
                                                      : v->in.light_level);
  for (int i = 0; i < v->scn.nlight; i++)
    for (int k = 0; k < 3; k++) {
      v->scn.lights[i].diffuse[k] *= level;
      v->scn.lights[i].ambient[k] *= level;
    }
}

/* The scene of the chosen view, with the LIDAR rays when on. */
static void viewer_scene(sim_viewer_t *v, const mjModel *m, mjData *d) {
  viewer_camera(v, m);
  viewer_fill_scene(v, m, d, &v->cam);
  if (!v->in.lidar_rays) return;
  static const float ray_rgba[4] = {1.0f, 0.1f, 0.1f, 0.8f};
  const double *o = v->ray_origin;
  for (int i = 0; i < v->nrays && v->scn.ngeom < v->scn.maxgeom; i++) {
    mjvGeom *g = v->scn.geoms + v->scn.ngeom++;
    mjv_initGeom(g, mjGEOM_LINE, NULL, NULL, NULL, ray_rgba);
    const float *e = v->ray_end + 3 * i;
    mjv_makeConnector(g, mjGEOM_LINE, 1.0, o[0], o[1], o[2], e[0], e[1], e[2]);
  }
}

/* The HUD: the status line and the keys (bottom right), the caller's figures (top right). */
static void viewer_overlays(sim_viewer_t *v, mjrRect vp, double t_s) {
  if (!v->in.hud) return;
  static const char *names[4] = {"driver's", "bird's", "god's", "free"};
  char text[256];
  const char *view = v->in.view >= 0 && v->in.view < 4 ? names[v->in.view] : "overhead";
  char scale[96] = "";
  if (v->software || v->in.render_scale < 1.0) /* why the scene looks soft */
    snprintf(scale, sizeof scale, "  scale %.2f%s%.40s%s", v->in.render_scale,
             v->software ? " (" : "", v->software ? v->renderer : "", v->software ? ")" : "");
  snprintf(text, sizeof text, AUTODRIVE_VEHICLE_PREFIX "%d  %s view  t = %.2f s%s%s%s%s", v->in.car,
           view, t_s, v->in.manual ? "  MANUAL" : "", v->in.paused ? "  PAUSED" : "",
           v->in.day ? "" : "  night", scale);
  mjr_overlay(mjFONT_NORMAL, mjGRID_BOTTOMRIGHT, vp, text,
              v->in.manual ? "arrows / WASD drive  T autonomous  1-4 view  Space pause  Esc quit"
                           : "1-4 view  Tab car  N night  Space pause  R reset  T manual  M menu  "
                             "H HUD  Esc quit",
              &v->con);
  if (!v->hud_titles[0]) return;
  /* the render scale as the HUD's last line: the status line's left half is under the panel */
  char titles[SIM_VIEWER_HUD_CHARS + 32], values[SIM_VIEWER_HUD_CHARS + 96];
  snprintf(titles, sizeof titles, "%s\nrender scale", v->hud_titles);
  snprintf(values, sizeof values, "%s\n%.2f%s%.40s%s", v->hud_values, v->in.render_scale,
           v->software ? " (" : "", v->software ? v->renderer : "", v->software ? ")" : "");
  mjr_overlay(mjFONT_NORMAL, mjGRID_TOPRIGHT, vp, titles, values, &v->con);
}

/* Reads the frame back (before the swap) into v->rgb, rows top-down. Returns 0, or -1. */
static int viewer_read_back(sim_viewer_t *v, mjrRect vp) {
  if ((size_t)v->w * (size_t)v->h > v->rgb_px) { /* the window grew */
    unsigned char *p = realloc(v->rgb, (size_t)v->w * (size_t)v->h * 3);
    if (!p) return -1;
    v->rgb = p;
    v->rgb_px = (size_t)v->w * (size_t)v->h;
  }
  mjr_readPixels(v->rgb, NULL, vp, &v->con);
  const size_t stride = (size_t)v->w * 3;
  for (int y = 0; y < v->h / 2; y++) { /* bottom-up -> top-down */
    unsigned char *a = v->rgb + (size_t)y * stride, *b = v->rgb + (size_t)(v->h - 1 - y) * stride;
    for (size_t k = 0; k < stride; k++) {
      const unsigned char t = a[k];
      a[k] = b[k];
      b[k] = t;
    }
  }
  v->have_rgb = 1;
  return 0;
}

/* The input state to *in; its edges are reported once. */
static void viewer_take_input(sim_viewer_t *v, sim_viewer_input_t *in) {
  if (in) *in = v->in;
  v->in.reset_requested = v->in.step_requested = v->in.record_toggled = 0;
}

static double viewer_now_ms(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return ts.tv_sec * 1e3 + ts.tv_nsec * 1e-6;
}

/* With timing on: the part that just ended (after glFinish) into this frame's row. */
static void viewer_part_done(sim_viewer_t *v, int part, double *t_ms) {
  if (!v->timing_now) return;
  if (v->gl_finish && part != SIM_VIEWER_PART_UPDATE) v->gl_finish();
  const double now = viewer_now_ms();
  v->part_ms[v->timed * SIM_VIEWER_PARTS + part] = (float)(now - *t_ms);
  *t_ms = now;
}

/* The scene at the render scale: straight into the window at 1, else into the offscreen
 * buffer and stretched to the window. */
static void viewer_render_scene(sim_viewer_t *v, mjrRect vp, double *t_ms) {
  double s = v->in.render_scale;
  s = s < SIM_VIEWER_MIN_SCALE ? SIM_VIEWER_MIN_SCALE : s > 1.0 ? 1.0 : s;
  mjrRect small = {0, 0, (int)lround(vp.width * s), (int)lround(vp.height * s)};
  if (small.width > v->con.offWidth) small.width = v->con.offWidth; /* the window grew */
  if (small.height > v->con.offHeight) small.height = v->con.offHeight;
  const int scaled = s < 1.0 && small.width > 0 && small.height > 0;
  mjr_setBuffer(scaled ? mjFB_OFFSCREEN : mjFB_WINDOW, &v->con);
  if (scaled && v->con.currentBuffer != mjFB_OFFSCREEN) { /* no offscreen buffer: full size */
    mjr_render(vp, &v->scn, &v->con);
    viewer_part_done(v, SIM_VIEWER_PART_SCENE, t_ms);
    return;
  }
  mjr_render(scaled ? small : vp, &v->scn, &v->con);
  viewer_part_done(v, SIM_VIEWER_PART_SCENE, t_ms);
  if (scaled && v->gl_bind_fb && v->gl_blit_fb) {
    /* nearest, not mjr_blitBuffer's linear: a software rasteriser then reads one texel per
     * pixel, not four */
    v->gl_bind_fb(GL_READ_FRAMEBUFFER, v->con.offFBO);
    v->gl_bind_fb(GL_DRAW_FRAMEBUFFER, 0);
    v->gl_blit_fb(0, 0, small.width, small.height, vp.left, vp.bottom, vp.left + vp.width,
                  vp.bottom + vp.height, GL_COLOR_BUFFER_BIT, GL_NEAREST);
    mjr_setBuffer(mjFB_WINDOW, &v->con);
  } else if (scaled) {
    mjr_blitBuffer(small, vp, 1, 0, &v->con);
    mjr_setBuffer(mjFB_WINDOW, &v->con);
  }
  viewer_part_done(v, SIM_VIEWER_PART_BLIT, t_ms);
}

/* The ego car's front and rear cameras, side by side at the bottom left of the scene's area
 * (scene: that area), each labelled; drawn straight into the window at their own small size,
 * so they cost what their pixels cost, whatever the render scale. */
static void viewer_thumbnails(sim_viewer_t *v, const mjModel *m, mjData *d, mjrRect scene,
                              double *t_ms) {
  if (!v->in.thumbnails) return;
  const int car = v->in.car - 1;
  const int ids[2] = {v->car_cam[car], v->car_rear_cam[car]};
  static const char *labels[2] = {"front camera", "rear camera"};
  const int w = (int)lround(scene.width * SIM_VIEWER_THUMB_SHARE), h = w * 3 / 4; /* 4:3 */
  const int gap = 8, label_h = 22;                                                /* [px] */
  const int bottom = 34; /* [px] above the status line */
  mjr_setBuffer(mjFB_WINDOW, &v->con);
  for (int k = 0, shown = 0; k < 2; k++) {
    if (ids[k] < 0 || w < 32) continue;
    mjvCamera cam;
    mjv_defaultCamera(&cam);
    cam.type = mjCAMERA_FIXED;
    cam.fixedcamid = ids[k];
    viewer_fill_scene(v, m, d, &cam);
    const mjrRect r = {scene.left + gap + shown * (w + gap), bottom, w, h};
    mjr_render(r, &v->scn, &v->con);
    const mjrRect label = {r.left, bottom + h, w, label_h}; /* a strip above, not over it */
    mjr_label(label, mjFONT_NORMAL, labels[k], 0.1f, 0.1f, 0.1f, 0.8f, 1, 1, 1, &v->con);
    shown++;
  }
  viewer_part_done(v, SIM_VIEWER_PART_THUMBS, t_ms);
}

/* A frame of d into the window (its size in v->w, v->h): scene, HUD, panel, read-back, swap. */
static int viewer_draw_frame(sim_viewer_t *v, const mjModel *m, mjData *d) {
  v->timing_now =
      v->timing && v->timed < SIM_VIEWER_TIMED_FRAMES && v->drawn++ % SIM_VIEWER_TIMED_EVERY == 0;
  double t_ms = viewer_now_ms();
  viewer_scene(v, m, d);
  viewer_part_done(v, SIM_VIEWER_PART_UPDATE, &t_ms);
  const mjrRect vp = {0, 0, v->w, v->h};
  /* the scene right of the Menu Panel only: the panel is opaque, and every pixel drawn under
   * it would be paid for twice (a quarter of a 1024 px wide window) */
  const int left = v->panel && v->w - v->ui.width >= 64 ? v->ui.width : 0;
  const mjrRect scene = {left, 0, v->w - left, v->h};
  viewer_render_scene(v, scene, &t_ms);
  viewer_thumbnails(v, m, d, scene, &t_ms);
  viewer_overlays(v, vp, d->time);
  viewer_part_done(v, SIM_VIEWER_PART_HUD, &t_ms);
  sim_viewer_ui_render(v);
  viewer_part_done(v, SIM_VIEWER_PART_UI, &t_ms);
  v->have_rgb = 0;
  if (v->capture && viewer_read_back(v, vp) != 0) return -1;
  glfwSwapBuffers(v->win);
  viewer_part_done(v, SIM_VIEWER_PART_SWAP, &t_ms);
  if (v->timing_now) v->timed++;
  return 0;
}

void sim_viewer_poll(sim_viewer_t *v, sim_viewer_input_t *in) {
  if (v->threaded) { /* events only: the callbacks queue them for the drawing thread */
    glfwPollEvents();
    int fw = 0, fh = 0;
    glfwGetFramebufferSize(v->win, &fw, &fh);
    pthread_mutex_lock(&v->mu);
    v->fb_w = fw;
    v->fb_h = fh;
    if (glfwWindowShouldClose(v->win)) v->in_pub.quit = 1;
    if (in) *in = v->in_pub;
    v->in_pub.reset_requested = v->in_pub.step_requested = v->in_pub.record_toggled = 0;
    pthread_mutex_unlock(&v->mu);
    return;
  }
  glfwMakeContextCurrent(v->win); /* a click on the panel draws into its buffer */
  glfwPollEvents();
  if (glfwWindowShouldClose(v->win)) v->in.quit = 1;
  viewer_take_input(v, in);
}

int sim_viewer_frame(sim_viewer_t *v, const mjModel *m, mjData *d, sim_viewer_input_t *in) {
  glfwPollEvents();
  if (glfwWindowShouldClose(v->win)) v->in.quit = 1;
  glfwMakeContextCurrent(v->win);
  glfwGetFramebufferSize(v->win, &v->w, &v->h);
  const int rc = viewer_draw_frame(v, m, d);
  viewer_take_input(v, in);
  return rc;
}

void sim_viewer_detach(sim_viewer_t *v) {
  pthread_mutex_lock(&v->mu);
  v->threaded = 1;
  v->in_pub = v->in;
  v->cam_pub = v->cam.type == mjCAMERA_FIXED ? v->cam.fixedcamid : -1;
  pthread_mutex_unlock(&v->mu);
  glfwMakeContextCurrent(NULL); /* a context is current on one thread at a time */
}

/* The drawing thread: the queued events, applied as the single-threaded callbacks would. */
static void viewer_apply_events(sim_viewer_t *v) {
  sim_viewer_event_t q[SIM_VIEWER_QUEUE];
  pthread_mutex_lock(&v->mu);
  const int n = v->nqueued;
  memcpy(q, v->queue, (size_t)n * sizeof *q);
  v->nqueued = 0;
  v->w = v->fb_w;
  v->h = v->fb_h;
  pthread_mutex_unlock(&v->mu);
  for (int i = 0; i < n; i++) {
    if (q[i].kind == SIM_VIEWER_EV_KEY) sim_viewer_key_state(v, q[i].code, q[i].down);
    if (q[i].kind == SIM_VIEWER_EV_BUTTON) sim_viewer_ui_mouse(v, q[i].x_px, q[i].y_px, q[i].down);
    if (q[i].kind == SIM_VIEWER_EV_MANUAL) viewer_set_manual_now(v, q[i].code);
  }
}

int sim_viewer_draw(sim_viewer_t *v, const mjModel *m, mjData *d) {
  if (!v->bound) {
    glfwMakeContextCurrent(v->win);
    glfwSwapInterval(0); /* per context and thread: never let vsync throttle the frames */
    v->bound = 1;
  }
  viewer_apply_events(v);
  const int rc = viewer_draw_frame(v, m, d);
  pthread_mutex_lock(&v->mu); /* the state to the polling thread; its edges wait to be polled */
  const sim_viewer_input_t old = v->in_pub;
  v->in_pub = v->in;
  v->in_pub.reset_requested |= old.reset_requested;
  v->in_pub.step_requested |= old.step_requested;
  v->in_pub.record_toggled |= old.record_toggled;
  v->in_pub.quit |= old.quit;
  v->cam_pub = v->cam.type == mjCAMERA_FIXED ? v->cam.fixedcamid : -1;
  pthread_mutex_unlock(&v->mu);
  viewer_take_input(v, NULL);
  return rc;
}

void sim_viewer_release(sim_viewer_t *v) {
  if (v->bound) glfwMakeContextCurrent(NULL);
  v->bound = 0;
}

void sim_viewer_set_render_scale(sim_viewer_t *v, double scale) {
  v->in.render_scale = scale < SIM_VIEWER_MIN_SCALE ? SIM_VIEWER_MIN_SCALE
                       : scale > 1.0                ? 1.0
                                                    : scale;
  v->ui_dirty = 1;
}

void sim_viewer_set_camera_scale(sim_viewer_t *v, double scale) {
  v->in.camera_scale = scale;
  v->ui_dirty = 1;
}

void sim_viewer_set_quality(sim_viewer_t *v, int quality) {
  v->in.shadows = quality >= SIM_VIEWER_QUALITY_HIGH;
  v->in.reflections = v->in.skybox = quality >= SIM_VIEWER_QUALITY_ULTRA;
  v->ui_dirty = 1;
}

const char *sim_viewer_renderer(const sim_viewer_t *v, int *software) {
  if (software) *software = v->software;
  return v->renderer;
}

void sim_viewer_time_parts(sim_viewer_t *v, int on) {
  if (on && !v->part_ms)
    v->part_ms = calloc((size_t)SIM_VIEWER_TIMED_FRAMES * SIM_VIEWER_PARTS, sizeof(float));
  v->timing = on && v->part_ms;
}

int sim_viewer_last_timed(const sim_viewer_t *v) {
  return v->timing_now;
}

static int viewer_cmp_float(const void *a, const void *b) {
  const float x = *(const float *)a, y = *(const float *)b;
  return (x > y) - (x < y);
}

long sim_viewer_parts(const sim_viewer_t *v, double *ms, const char **names) {
  static const char *part_names[SIM_VIEWER_PARTS] = {"update", "scene", "blit", "thumbs",
                                                     "hud",    "ui",    "swap"};
  static float col[SIM_VIEWER_TIMED_FRAMES];
  for (int p = 0; p < SIM_VIEWER_PARTS; p++) {
    if (names) names[p] = part_names[p];
    ms[p] = 0.0;
    if (v->timed == 0) continue;
    for (long f = 0; f < v->timed; f++) col[f] = v->part_ms[f * SIM_VIEWER_PARTS + p];
    qsort(col, (size_t)v->timed, sizeof *col, viewer_cmp_float);
    const long n = v->timed;
    ms[p] = n % 2 ? col[n / 2] : 0.5 * (col[n / 2 - 1] + col[n / 2]);
  }
  return v->timed;
}
