/* sim_viewer: see sim_viewer.h. */
#include "sim_viewer.h"

#include <autodrive_channels.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <GLFW/glfw3.h>

struct sim_viewer {
  GLFWwindow *win;
  mjrContext con;
  mjvScene scn;
  mjvOption opt;
  mjvCamera cam;
  int ncars;
  int *car_body; /* base body id per car (index car-1), -1 if missing */
  int *car_cam;  /* front camera id per car, -1 if missing */
  int eye_cam;   /* the map's "eye" camera, -1 if none */
  int w, h;
  sim_viewer_input_t in;
  int capture;
  unsigned char *rgb; /* last captured frame, top-down */
  size_t rgb_px;      /* its capacity [px] */
  int have_rgb;
};

static int glfw_users; /* glfwInit/glfwTerminate are process-wide */

int sim_viewer_display_available(void) {
  const char *x = getenv("DISPLAY"), *wl = getenv("WAYLAND_DISPLAY");
  return (x && *x) || (wl && *wl);
}

void sim_viewer_key(sim_viewer_t *v, int key) {
  switch (key) {
    case GLFW_KEY_1: v->in.view = SIM_VIEW_DRIVER; break;
    case GLFW_KEY_2: v->in.view = SIM_VIEW_BIRD; break;
    case GLFW_KEY_3: v->in.view = SIM_VIEW_GOD; break;
    case GLFW_KEY_TAB: v->in.car = v->in.car % v->ncars + 1; break;
    case GLFW_KEY_N: v->in.day = !v->in.day; break;
    case GLFW_KEY_SPACE: v->in.paused = !v->in.paused; break;
    case GLFW_KEY_R: v->in.reset_requested = 1; break;
    case GLFW_KEY_ESCAPE: v->in.quit = 1; break;
    default: break;
  }
}

static void on_key(GLFWwindow *w, int key, int scancode, int action, int mods) {
  (void)scancode;
  (void)mods;
  if (action == GLFW_PRESS) sim_viewer_key(glfwGetWindowUserPointer(w), key);
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
  glfwMakeContextCurrent(v->win);
  glfwSwapInterval(0); /* never let vsync throttle the sim */
  glfwGetFramebufferSize(v->win, &v->w, &v->h);
  mjr_defaultContext(&v->con);
  mjr_makeContext(m, &v->con, mjFONTSCALE_100);
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
  v->rgb_px = (size_t)v->w * (size_t)v->h;
  v->rgb = malloc(v->rgb_px * 3);
  if (!v->car_body || !v->car_cam || !v->rgb) {
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
  v->eye_cam = mj_name2id(m, mjOBJ_CAMERA, "eye");
  v->in.day = 1;
  v->in.car = 1;
  v->in.view = SIM_VIEW_BIRD;
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
  } else if (v->in.view == SIM_VIEW_GOD && v->eye_cam >= 0) {
    c->type = mjCAMERA_FIXED;
    c->fixedcamid = v->eye_cam;
  } else {
    c->type = mjCAMERA_FREE;
    for (int i = 0; i < 3; i++) c->lookat[i] = m->stat.center[i];
    c->distance = 1.5 * m->stat.extent;
    c->elevation = -60;
    c->azimuth = 90;
  }
}

int sim_viewer_frame(sim_viewer_t *v, const mjModel *m, mjData *d, sim_viewer_input_t *in) {
  glfwPollEvents();
  if (glfwWindowShouldClose(v->win)) v->in.quit = 1;
  glfwMakeContextCurrent(v->win);
  glfwGetFramebufferSize(v->win, &v->w, &v->h);
  viewer_camera(v, m);
  mjv_updateScene(m, d, &v->opt, NULL, &v->cam, mjCAT_ALL, &v->scn);
  if (!v->in.day)
    for (int i = 0; i < v->scn.nlight; i++)
      for (int k = 0; k < 3; k++) {
        v->scn.lights[i].diffuse[k] *= 0.15f;
        v->scn.lights[i].ambient[k] *= 0.15f;
      }
  mjrRect vp = {0, 0, v->w, v->h};
  mjr_render(vp, &v->scn, &v->con);
  static const char *names[3] = {"driver", "bird", "god"};
  char text[128];
  snprintf(text, sizeof text, AUTODRIVE_VEHICLE_PREFIX "%d %s view  t=%.2f s%s%s", v->in.car,
           names[v->in.view], d->time, v->in.paused ? "  PAUSED" : "", v->in.day ? "" : "  night");
  mjr_overlay(mjFONT_NORMAL, mjGRID_TOPLEFT, vp, text,
              "1/2/3 view  Tab car  N day/night  Space pause  R reset  Esc quit", &v->con);
  v->have_rgb = 0;
  if (v->capture && (size_t)v->w * (size_t)v->h > v->rgb_px) { /* the window grew */
    unsigned char *p = realloc(v->rgb, (size_t)v->w * (size_t)v->h * 3);
    if (!p) return -1;
    v->rgb = p;
    v->rgb_px = (size_t)v->w * (size_t)v->h;
  }
  if (v->capture) {
    mjr_readPixels(v->rgb, NULL, vp, &v->con);
    size_t stride = (size_t)v->w * 3;
    for (int y = 0; y < v->h / 2; y++) { /* bottom-up -> top-down */
      unsigned char *a = v->rgb + (size_t)y * stride, *b = v->rgb + (size_t)(v->h - 1 - y) * stride;
      for (size_t k = 0; k < stride; k++) {
        unsigned char t = a[k];
        a[k] = b[k];
        b[k] = t;
      }
    }
    v->have_rgb = 1;
  }
  glfwSwapBuffers(v->win);
  if (in) *in = v->in;
  v->in.reset_requested = 0; /* an edge: reported once */
  return 0;
}
