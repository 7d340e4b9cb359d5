/* sim_viewer: see sim_viewer.h. */
#include "sim_viewer.h"

#include <autodrive_channels.h>
#include <dlfcn.h> /* RTLD_NODELETE, dl_iterate_phdr: _GNU_SOURCE from the build */
#include <link.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <GLFW/glfw3.h>

#include "sim_viewer_internal.h"

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

void sim_viewer_set_manual(sim_viewer_t *v, int manual) {
  v->in.manual = manual != 0;
  v->in.drive_keys = 0;
}

static void on_key(GLFWwindow *w, int key, int scancode, int action, int mods) {
  (void)scancode;
  (void)mods;
  if (action != GLFW_REPEAT)
    sim_viewer_key_state(glfwGetWindowUserPointer(w), key, action == GLFW_PRESS);
}

static void on_cursor(GLFWwindow *w, double x, double y) {
  sim_viewer_t *v = glfwGetWindowUserPointer(w);
  v->cursor_x = x;
  v->cursor_y = y;
}

static void on_button(GLFWwindow *w, int button, int action, int mods) {
  (void)mods;
  sim_viewer_t *v = glfwGetWindowUserPointer(w);
  if (button == GLFW_MOUSE_BUTTON_LEFT)
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
  for (int s = 0; s < v->ui.nsect; s++) /* the Simulation section's Map line */
    for (int i = 0; i < v->ui.sect[s].nitem; i++)
      if (!strcmp(v->ui.sect[s].item[i].name, "Map")) {
        v->ui.sect[s].item[i].multi.nelem = 1;
        snprintf(v->ui.sect[s].item[i].multi.name[0], mjMAXUINAME, "%.39s", v->map_name);
      }
}

void sim_viewer_set_rays(sim_viewer_t *v, const double origin[3], const float *ends_xyz, int n) {
  v->nrays = (!origin || !ends_xyz || n < 0) ? 0 : (n > VIEWER_MAX_RAYS ? VIEWER_MAX_RAYS : n);
  if (v->nrays == 0) return;
  memcpy(v->ray_origin, origin, sizeof v->ray_origin);
  memcpy(v->ray_end, ends_xyz, (size_t)v->nrays * 3 * sizeof(float));
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
  mjr_defaultContext(&v->con);
  mjr_makeContext(m, &v->con, mjFONTSCALE_100);
  viewer_pin_gl_driver();
  mjr_setBuffer(mjFB_WINDOW, &v->con);
  mjv_defaultScene(&v->scn);
  mjv_makeScene(m, &v->scn, 2000 + 4 * m->ngeom);
  v->scn.flags[mjRND_SHADOW] = 0;
  v->scn.flags[mjRND_REFLECTION] = 0;
  mjv_defaultOption(&v->opt);
  mjv_defaultCamera(&v->cam);
  v->ncars = ncars;
  v->car_body = calloc((size_t)ncars, sizeof(int));
  v->car_cam = calloc((size_t)ncars, sizeof(int));
  v->ray_end = malloc(VIEWER_MAX_RAYS * 3 * sizeof(float));
  v->rgb_px = (size_t)v->w * (size_t)v->h;
  v->rgb = malloc(v->rgb_px * 3);
  if (!v->car_body || !v->car_cam || !v->rgb || !v->ray_end) {
    sim_viewer_destroy(v);
    return NULL;
  }
  for (int i = 1; i <= ncars; i++) {
    char name[128];
    snprintf(name, sizeof name, body_fmt, i);
    v->car_body[i - 1] = mj_name2id(m, mjOBJ_BODY, name);
    snprintf(name, sizeof name, cam_fmt, i);
    v->car_cam[i - 1] = mj_name2id(m, mjOBJ_CAMERA, name);
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
  v->panel = 1;
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
  free(v->ray_end);
  free(v->rgb);
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
  return v->cam.type == mjCAMERA_FIXED ? v->cam.fixedcamid : -1;
}

/* The scene of the chosen view with the light level, the graphics quality and the LIDAR rays. */
static void viewer_scene(sim_viewer_t *v, const mjModel *m, mjData *d) {
  viewer_camera(v, m);
  mjv_updateScene(m, d, &v->opt, NULL, &v->cam, mjCAT_ALL, &v->scn);
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
  char text[160];
  const char *view = v->in.view >= 0 && v->in.view < 4 ? names[v->in.view] : "overhead";
  snprintf(text, sizeof text, AUTODRIVE_VEHICLE_PREFIX "%d  %s view  t = %.2f s%s%s%s", v->in.car,
           view, t_s, v->in.manual ? "  MANUAL" : "", v->in.paused ? "  PAUSED" : "",
           v->in.day ? "" : "  night");
  mjr_overlay(mjFONT_NORMAL, mjGRID_BOTTOMRIGHT, vp, text,
              v->in.manual ? "arrows / WASD drive  T autonomous  1-4 view  Space pause  Esc quit"
                           : "1-4 view  Tab car  N night  Space pause  R reset  T manual  M menu  "
                             "H HUD  Esc quit",
              &v->con);
  if (v->hud_titles[0])
    mjr_overlay(mjFONT_NORMAL, mjGRID_TOPRIGHT, vp, v->hud_titles, v->hud_values, &v->con);
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

void sim_viewer_poll(sim_viewer_t *v, sim_viewer_input_t *in) {
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
  viewer_scene(v, m, d);
  const mjrRect vp = {0, 0, v->w, v->h};
  mjr_setBuffer(mjFB_WINDOW, &v->con);
  mjr_render(vp, &v->scn, &v->con);
  viewer_overlays(v, vp, d->time);
  sim_viewer_ui_render(v);
  v->have_rgb = 0;
  if (v->capture && viewer_read_back(v, vp) != 0) return -1;
  glfwSwapBuffers(v->win);
  viewer_take_input(v, in);
  return 0;
}
