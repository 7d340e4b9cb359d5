/* sim_render: see sim_render.h. */
#include "sim_render.h"

#include <EGL/egl.h>
#include <EGL/eglext.h>
#include <GL/osmesa.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

struct sim_render {
  sim_render_backend_t backend;
  EGLDisplay egl_dpy;
  EGLContext egl_ctx;
  OSMesaContext osm_ctx;
  void *osm_buf;            /* OSMesa's default framebuffer (unused by MuJoCo's offscreen) */
  mjModel *mcopy;           /* shallow copy of the model with our render settings */
  mjrContext con;
  mjvScene scn;
  mjvOption opt;
  mjvCamera cam;
  int maxw, maxh;
  uint8_t *row;             /* one row, for the vertical flip */
  float light_k;            /* day 1, night < 1: scales every scene light */
};

static void err_set(char *err, size_t n, const char *msg) {
  if (err && n) snprintf(err, n, "sim_render: %s", msg);
}

static int egl_init(sim_render_t *r) {
  PFNEGLGETPLATFORMDISPLAYEXTPROC get_display =
      (PFNEGLGETPLATFORMDISPLAYEXTPROC)eglGetProcAddress("eglGetPlatformDisplayEXT");
  if (!get_display) return -1;
  r->egl_dpy = get_display(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, NULL);
  if (r->egl_dpy == EGL_NO_DISPLAY) return -1;
  EGLint major, minor;
  if (!eglInitialize(r->egl_dpy, &major, &minor)) return -1;
  /* Mesa's surfaceless platform offers no configs; MuJoCo draws into its own FBO, so a
   * config-less context (EGL_KHR_no_config_context) is all it needs */
  const EGLint attr[] = {EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT, EGL_NONE};
  EGLConfig cfg = (EGLConfig)0; /* EGL_NO_CONFIG_KHR */
  EGLint ncfg = 0;
  if (!eglChooseConfig(r->egl_dpy, attr, &cfg, 1, &ncfg) || ncfg < 1) cfg = (EGLConfig)0;
  if (!eglBindAPI(EGL_OPENGL_API)) goto fail;
  r->egl_ctx = eglCreateContext(r->egl_dpy, cfg, EGL_NO_CONTEXT, NULL);
  if (r->egl_ctx == EGL_NO_CONTEXT) goto fail;
  if (!eglMakeCurrent(r->egl_dpy, EGL_NO_SURFACE, EGL_NO_SURFACE, r->egl_ctx)) goto fail;
  r->backend = SIM_RENDER_EGL;
  return 0;
fail:
  if (r->egl_ctx != EGL_NO_CONTEXT) eglDestroyContext(r->egl_dpy, r->egl_ctx);
  r->egl_ctx = EGL_NO_CONTEXT;
  eglTerminate(r->egl_dpy);
  r->egl_dpy = EGL_NO_DISPLAY;
  return -1;
}

static int osmesa_init(sim_render_t *r) {
  r->osm_ctx = OSMesaCreateContextExt(OSMESA_RGBA, 24, 8, 0, NULL);
  if (!r->osm_ctx) return -1;
  /* MuJoCo renders into its own FBO; the default buffer only has to exist */
  r->osm_buf = calloc(4 * 4, 4);
  if (!r->osm_buf || !OSMesaMakeCurrent(r->osm_ctx, r->osm_buf, GL_UNSIGNED_BYTE, 4, 4)) {
    OSMesaDestroyContext(r->osm_ctx);
    r->osm_ctx = NULL;
    return -1;
  }
  r->backend = SIM_RENDER_OSMESA;
  return 0;
}

sim_render_t *sim_render_create(const mjModel *m, int max_width_px, int max_height_px,
                                sim_render_backend_t backend, char *err, size_t err_len) {
  if (!m || max_width_px < 1 || max_height_px < 1 || max_width_px > 8192 ||
      max_height_px > 8192) {
    err_set(err, err_len, "null model or bad buffer size (1..8192 px)");
    return NULL;
  }
  sim_render_t *r = calloc(1, sizeof *r);
  if (!r) return NULL;
  r->egl_dpy = EGL_NO_DISPLAY;
  r->egl_ctx = EGL_NO_CONTEXT;
  int ok = -1;
  if (backend == SIM_RENDER_AUTO || backend == SIM_RENDER_EGL) ok = egl_init(r);
  if (ok != 0 && (backend == SIM_RENDER_AUTO || backend == SIM_RENDER_OSMESA))
    ok = osmesa_init(r);
  if (ok != 0) {
    free(r);
    err_set(err, err_len, "no headless OpenGL context (tried EGL surfaceless and/or OSMesa; "
                          "are Mesa's libegl-mesa0 / libosmesa6 installed?)");
    return NULL;
  }
  /* fast settings on a private shallow copy: the arrays stay shared, only vis changes */
  r->mcopy = malloc(sizeof *r->mcopy);
  r->row = malloc((size_t)max_width_px * 3);
  if (!r->mcopy || !r->row) {
    sim_render_destroy(r);
    err_set(err, err_len, "out of memory");
    return NULL;
  }
  *r->mcopy = *m;
  r->mcopy->vis.global.offwidth = max_width_px;
  r->mcopy->vis.global.offheight = max_height_px;
  r->mcopy->vis.quality.offsamples = 0;
  r->mcopy->vis.quality.shadowsize = 0;
  r->maxw = max_width_px;
  r->maxh = max_height_px;
  mjr_defaultContext(&r->con);
  mjr_makeContext(r->mcopy, &r->con, mjFONTSCALE_100);
  mjr_setBuffer(mjFB_OFFSCREEN, &r->con);
  if (r->con.currentBuffer != mjFB_OFFSCREEN || r->con.offWidth < max_width_px ||
      r->con.offHeight < max_height_px) {
    sim_render_destroy(r);
    err_set(err, err_len, "MuJoCo could not make an offscreen buffer of the requested size");
    return NULL;
  }
  mjv_defaultScene(&r->scn);
  mjv_makeScene(m, &r->scn, 2000 + 4 * m->ngeom);
  r->scn.flags[mjRND_SHADOW] = 0;
  r->scn.flags[mjRND_REFLECTION] = 0;
  mjv_defaultOption(&r->opt);
  mjv_defaultCamera(&r->cam);
  r->cam.type = mjCAMERA_FIXED;
  r->light_k = 1.0f;
  return r;
}

void sim_render_destroy(sim_render_t *r) {
  if (!r) return;
  mjv_freeScene(&r->scn);
  mjr_freeContext(&r->con);
  if (r->egl_dpy != EGL_NO_DISPLAY) {
    eglMakeCurrent(r->egl_dpy, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
    if (r->egl_ctx != EGL_NO_CONTEXT) eglDestroyContext(r->egl_dpy, r->egl_ctx);
    /* no eglTerminate: the surfaceless display is process-wide (EGL returns the same handle
     * to every renderer), and terminating it unloads Mesa's driver, whose small internal
     * allocations then show up as leaks under LeakSanitizer */
  }
  if (r->osm_ctx) OSMesaDestroyContext(r->osm_ctx);
  free(r->osm_buf);
  free(r->mcopy);
  free(r->row);
  free(r);
}

const char *sim_render_backend_name(const sim_render_t *r) {
  return r->backend == SIM_RENDER_EGL ? "egl" : "osmesa";
}

int sim_render_fits(const sim_render_t *r, int width_px, int height_px) {
  return width_px >= 1 && height_px >= 1 && width_px <= r->maxw && height_px <= r->maxh;
}

mjvOption *sim_render_options(sim_render_t *r) { return &r->opt; }

int sim_render_camera(sim_render_t *r, const mjModel *m, mjData *d, int cam_id, int width_px,
                      int height_px, uint8_t *rgb) {
  if (cam_id < 0 || cam_id >= m->ncam || width_px < 1 || height_px < 1 || width_px > r->maxw ||
      height_px > r->maxh || !rgb)
    return -1;
  r->cam.fixedcamid = cam_id;
  mjv_updateScene(m, d, &r->opt, NULL, &r->cam, mjCAT_ALL, &r->scn);
  if (r->light_k != 1.0f)
    for (int i = 0; i < r->scn.nlight; i++)
      for (int c = 0; c < 3; c++) {
        r->scn.lights[i].diffuse[c] *= r->light_k;
        r->scn.lights[i].ambient[c] *= r->light_k;
        r->scn.lights[i].specular[c] *= r->light_k;
      }
  mjrRect vp = {0, 0, width_px, height_px};
  mjr_render(vp, &r->scn, &r->con);
  mjr_readPixels(rgb, NULL, vp, &r->con);
  /* MuJoCo (OpenGL) rows are bottom-up; images are top-down */
  size_t stride = (size_t)width_px * 3;
  for (int y = 0; y < height_px / 2; y++) {
    uint8_t *a = rgb + (size_t)y * stride, *b = rgb + (size_t)(height_px - 1 - y) * stride;
    memcpy(r->row, a, stride);
    memcpy(a, b, stride);
    memcpy(b, r->row, stride);
  }
  return 0;
}

void sim_render_set_daylight(sim_render_t *r, const mjModel *m, int day) {
  (void)m;
  r->light_k = day ? 1.0f : 0.15f; /* night keeps 15 % of every light, headlight included */
}

void sim_render_upload_texture(sim_render_t *r, const mjModel *m, int tex_id) {
  mjr_uploadTexture(m, &r->con, tex_id);
}
