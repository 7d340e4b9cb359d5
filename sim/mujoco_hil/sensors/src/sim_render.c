/* sim_render: see sim_render.h. */
#include "sim_render_internal.h"

#include <dlfcn.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static void err_set(char *err, size_t n, const char *msg) {
  if (err && n) snprintf(err, n, "sim_render: %s", msg);
}

/* dlsym into a function pointer without the object/function pointer cast warning */
static int sym(void *lib, const char *name, void *fnptr) {
  void *p = dlsym(lib, name);
  if (!p) return -1;
  memcpy(fnptr, &p, sizeof p);
  return 0;
}

static int egl_load(egl_api_t *e) {
  e->lib = dlopen("libEGL.so.1", RTLD_NOW | RTLD_GLOBAL);
  if (!e->lib) return -1;
  if (sym(e->lib, "eglGetProcAddress", &e->GetProcAddress) ||
      sym(e->lib, "eglInitialize", &e->Initialize) || sym(e->lib, "eglTerminate", &e->Terminate) ||
      sym(e->lib, "eglChooseConfig", &e->ChooseConfig) || sym(e->lib, "eglBindAPI", &e->BindAPI) ||
      sym(e->lib, "eglCreateContext", &e->CreateContext) ||
      sym(e->lib, "eglDestroyContext", &e->DestroyContext) ||
      sym(e->lib, "eglMakeCurrent", &e->MakeCurrent) ||
      sym(e->lib, "eglGetCurrentContext", &e->GetCurrentContext))
    return -1;
  return 0;
}

static int egl_init(sim_render_t *r) {
  egl_api_t *e = &r->egl;
  if (egl_load(e) != 0) return -1;
  PFNEGLGETPLATFORMDISPLAYEXTPROC get_display;
  __eglMustCastToProperFunctionPointerType gp = e->GetProcAddress("eglGetPlatformDisplayEXT");
  if (!gp) return -1;
  memcpy(&get_display, &gp, sizeof gp);
  r->egl_dpy = get_display(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, NULL);
  if (r->egl_dpy == EGL_NO_DISPLAY) return -1;
  EGLint major, minor;
  if (!e->Initialize(r->egl_dpy, &major, &minor)) return -1;
  /* Mesa's surfaceless platform offers no configs; MuJoCo draws into its own FBO, so a
   * config-less context (EGL_KHR_no_config_context) is all it needs */
  const EGLint attr[] = {EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT, EGL_NONE};
  EGLConfig cfg = (EGLConfig)0; /* EGL_NO_CONFIG_KHR */
  EGLint ncfg = 0;
  if (!e->ChooseConfig(r->egl_dpy, attr, &cfg, 1, &ncfg) || ncfg < 1) cfg = (EGLConfig)0;
  if (!e->BindAPI(EGL_OPENGL_API)) goto fail;
  r->egl_ctx = e->CreateContext(r->egl_dpy, cfg, EGL_NO_CONTEXT, NULL);
  if (r->egl_ctx == EGL_NO_CONTEXT) goto fail;
  if (!e->MakeCurrent(r->egl_dpy, EGL_NO_SURFACE, EGL_NO_SURFACE, r->egl_ctx)) goto fail;
  r->backend = SIM_RENDER_EGL;
  return 0;
fail:
  if (r->egl_ctx != EGL_NO_CONTEXT) e->DestroyContext(r->egl_dpy, r->egl_ctx);
  r->egl_ctx = EGL_NO_CONTEXT;
  e->Terminate(r->egl_dpy);
  r->egl_dpy = EGL_NO_DISPLAY;
  return -1;
}

static int osmesa_init(sim_render_t *r) {
  osmesa_api_t *o = &r->osm;
  void *egl = dlopen("libEGL.so.1", RTLD_NOW | RTLD_NOLOAD);
  if (egl) { /* MuJoCo would pick EGL's loader and abort in mjr_makeContext */
    dlclose(egl);
    return -2;
  }
  o->lib = dlopen("libOSMesa.so.8", RTLD_NOW | RTLD_GLOBAL);
  if (!o->lib) o->lib = dlopen("libOSMesa.so", RTLD_NOW | RTLD_GLOBAL);
  if (!o->lib || sym(o->lib, "OSMesaCreateContextExt", &o->CreateContextExt) ||
      sym(o->lib, "OSMesaMakeCurrent", &o->MakeCurrent) ||
      sym(o->lib, "OSMesaDestroyContext", &o->DestroyContext) ||
      sym(o->lib, "OSMesaGetProcAddress", &o->GetProcAddress) ||
      sym(o->lib, "OSMesaGetCurrentContext", &o->GetCurrentContext))
    return -1;
  r->osm_ctx = o->CreateContextExt(OSMESA_RGBA, 24, 8, 0, NULL);
  if (!r->osm_ctx) return -1;
  /* MuJoCo renders into its own FBO; the default buffer only has to exist */
  r->osm_buf = calloc(4 * 4, 4);
  if (!r->osm_buf || !o->MakeCurrent(r->osm_ctx, r->osm_buf, GL_UNSIGNED_BYTE, 4, 4)) {
    o->DestroyContext(r->osm_ctx);
    r->osm_ctx = NULL;
    return -1;
  }
  r->backend = SIM_RENDER_OSMESA;
  return 0;
}

sim_render_t *sim_render_create(const mjModel *m, int max_width_px, int max_height_px,
                                sim_render_backend_t backend, char *err, size_t err_len) {
  if (!m || max_width_px < 1 || max_height_px < 1 || max_width_px > 8192 || max_height_px > 8192) {
    err_set(err, err_len, "null model or bad buffer size (1..8192 px)");
    return NULL;
  }
  sim_render_t *r = calloc(1, sizeof *r);
  if (!r) return NULL;
  r->egl_dpy = EGL_NO_DISPLAY;
  r->egl_ctx = EGL_NO_CONTEXT;
  int ok = -1;
  if (backend == SIM_RENDER_AUTO || backend == SIM_RENDER_EGL) ok = egl_init(r);
  /* OSMesa cannot follow a loaded libEGL (see above): AUTO falls back only if EGL is absent */
  if (ok != 0 && (backend == SIM_RENDER_OSMESA || (backend == SIM_RENDER_AUTO && !r->egl.lib)))
    ok = osmesa_init(r);
  if (ok == -2) {
    free(r);
    err_set(err, err_len,
            "OSMesa cannot be used in a process that already loaded libEGL "
            "(MuJoCo would bind its GL calls to EGL): use one backend per process");
    return NULL;
  }
  if (ok != 0) {
    free(r);
    err_set(err, err_len,
            "no headless OpenGL context (tried EGL surfaceless and/or OSMesa; "
            "are Mesa's libegl-mesa0 / libosmesa6 installed?)");
    return NULL;
  }
  /* fast settings on a private shallow copy: the arrays stay shared, only vis changes */
  r->mcopy = malloc(sizeof *r->mcopy);
  r->rgba = malloc((size_t)max_width_px * (size_t)max_height_px * 4);
  if (!r->mcopy || !r->rgba) {
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
  /* glReadPixels, glBindFramebuffer, glGetFloatv from the backend in use (MuJoCo does not
   * export its own) */
  const char *names[3] = {"glReadPixels", "glBindFramebuffer", "glGetFloatv"};
  void *fp[3] = {NULL, NULL, NULL};
  for (int i = 0; i < 3; i++) {
    if (r->backend == SIM_RENDER_EGL) {
      __eglMustCastToProperFunctionPointerType f = r->egl.GetProcAddress(names[i]);
      memcpy(&fp[i], &f, sizeof f);
    } else {
      fp[i] = r->osm.GetProcAddress(names[i]);
    }
  }
  memcpy(&r->ReadPixels, &fp[0], sizeof fp[0]);
  memcpy(&r->BindFramebuffer, &fp[1], sizeof fp[1]);
  memcpy(&r->GetFloatv, &fp[2], sizeof fp[2]);
  if (!r->ReadPixels || !r->BindFramebuffer || !r->GetFloatv) {
    sim_render_destroy(r);
    err_set(err, err_len, "the GL context has no glReadPixels/glBindFramebuffer/glGetFloatv");
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
  /* GL objects are freed in the context that made them */
  if (r->egl_ctx != EGL_NO_CONTEXT || r->osm_ctx) sim_render_make_current(r);
  mjr_freeContext(&r->con);
  if (r->egl_dpy != EGL_NO_DISPLAY) {
    r->egl.MakeCurrent(r->egl_dpy, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
    if (r->egl_ctx != EGL_NO_CONTEXT) r->egl.DestroyContext(r->egl_dpy, r->egl_ctx);
    /* no eglTerminate: the surfaceless display is process-wide (EGL returns the same handle
     * to every renderer), and terminating it unloads Mesa's driver, whose small internal
     * allocations then show up as leaks under LeakSanitizer */
  }
  if (r->osm_ctx) {
    r->osm.MakeCurrent(NULL, NULL, 0, 0, 0); /* release the context before destroying it */
    r->osm.DestroyContext(r->osm_ctx);
  }
  /* the libraries stay loaded (no dlclose): MuJoCo keeps GL function pointers into them */
  free(r->osm_buf);
  free(r->mcopy);
  free(r->rgba);
  free(r);
}

const char *sim_render_backend_name(const sim_render_t *r) {
  return r->backend == SIM_RENDER_EGL ? "egl" : "osmesa";
}

int sim_render_fits(const sim_render_t *r, int width_px, int height_px) {
  return width_px >= 1 && height_px >= 1 && width_px <= r->maxw && height_px <= r->maxh;
}

mjvOption *sim_render_options(sim_render_t *r) {
  return &r->opt;
}

/* Makes the renderer's context current again if something else (a viewer window) took the
 * thread's current context since the last frame. */
int sim_render_make_current(sim_render_t *r) {
  if (r->backend == SIM_RENDER_EGL) {
    if (r->egl.GetCurrentContext() == r->egl_ctx) return 0;
    return r->egl.MakeCurrent(r->egl_dpy, EGL_NO_SURFACE, EGL_NO_SURFACE, r->egl_ctx) ? 0 : -1;
  }
  if (r->osm.GetCurrentContext() == r->osm_ctx) return 0;
  return r->osm.MakeCurrent(r->osm_ctx, r->osm_buf, GL_UNSIGNED_BYTE, 4, 4) ? 0 : -1;
}

void sim_render_update_scene(sim_render_t *r, const mjModel *m, mjData *d, int cam_id) {
  r->cam.fixedcamid = cam_id;
  mjv_updateScene(m, d, &r->opt, NULL, &r->cam, mjCAT_ALL, &r->scn);
  if (r->light_k != 1.0f)
    for (int i = 0; i < r->scn.nlight; i++)
      for (int c = 0; c < 3; c++) {
        r->scn.lights[i].diffuse[c] *= r->light_k;
        r->scn.lights[i].ambient[c] *= r->light_k;
        r->scn.lights[i].specular[c] *= r->light_k;
      }
}

void sim_render_read_rgb(sim_render_t *r, int width_px, int height_px, uint8_t *rgb) {
  /* read RGBA from MuJoCo's offscreen FBO (no MSAA: no resolve step), then drop alpha and
   * flip: OpenGL rows are bottom-up, images top-down */
  r->BindFramebuffer(GL_READ_FRAMEBUFFER, r->con.offFBO);
  r->ReadPixels(0, 0, width_px, height_px, GL_RGBA, GL_UNSIGNED_BYTE, r->rgba);
  for (int y = 0; y < height_px; y++) {
    const uint8_t *src = r->rgba + (size_t)(height_px - 1 - y) * (size_t)width_px * 4;
    uint8_t *dst = rgb + (size_t)y * (size_t)width_px * 3;
    for (int x = 0; x < width_px; x++, src += 4, dst += 3) {
      dst[0] = src[0];
      dst[1] = src[1];
      dst[2] = src[2];
    }
  }
}

int sim_render_camera(sim_render_t *r, const mjModel *m, mjData *d, int cam_id, int width_px,
                      int height_px, uint8_t *rgb) {
  if (cam_id < 0 || cam_id >= m->ncam || !sim_render_fits(r, width_px, height_px) || !rgb)
    return -1;
  if (sim_render_make_current(r) != 0) return -1;
  sim_render_update_scene(r, m, d, cam_id);
  mjrRect vp = {0, 0, width_px, height_px};
  mjr_render(vp, &r->scn, &r->con);
  sim_render_read_rgb(r, width_px, height_px, rgb);
  mjr_restoreBuffer(&r->con);
  return 0;
}

void sim_render_set_daylight(sim_render_t *r, const mjModel *m, int day) {
  (void)m;
  const float k = day ? 1.0f : 0.15f; /* night keeps 15 % of every light, headlight included */
  if (k != r->light_k) r->epoch++;
  r->light_k = k;
}

void sim_render_upload_texture(sim_render_t *r, const mjModel *m, int tex_id) {
  mjr_uploadTexture(m, &r->con, tex_id);
  r->epoch++;
}
