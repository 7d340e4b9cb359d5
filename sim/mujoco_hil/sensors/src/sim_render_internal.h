/* sim_render's internals, shared by sim_render.c (the renderer) and sim_render_cache.c (a fixed
 * camera's static world rendered once). Not part of the sensors library's interface. */
#ifndef SIM_RENDER_INTERNAL_H
#define SIM_RENDER_INTERNAL_H

#include <EGL/egl.h>
#include <EGL/eglext.h>
#include <GL/gl.h>
#include <GL/glext.h>
#include <GL/osmesa.h>

#include "sim_render.h"

/* EGL and OSMesa are loaded at run time (dlopen, RTLD_GLOBAL), only the one in use: MuJoCo's
 * GL loader looks for eglGetProcAddress before OSMesaGetProcAddress, so an OSMesa context
 * only works when libEGL was never loaded into the process. */
typedef struct egl_api {
  void *lib;
  __eglMustCastToProperFunctionPointerType (*GetProcAddress)(const char *);
  EGLBoolean (*Initialize)(EGLDisplay, EGLint *, EGLint *);
  EGLBoolean (*Terminate)(EGLDisplay);
  EGLBoolean (*ChooseConfig)(EGLDisplay, const EGLint *, EGLConfig *, EGLint, EGLint *);
  EGLBoolean (*BindAPI)(EGLenum);
  EGLContext (*CreateContext)(EGLDisplay, EGLConfig, EGLContext, const EGLint *);
  EGLBoolean (*DestroyContext)(EGLDisplay, EGLContext);
  EGLBoolean (*MakeCurrent)(EGLDisplay, EGLSurface, EGLSurface, EGLContext);
  EGLContext (*GetCurrentContext)(void);
} egl_api_t;

typedef struct osmesa_api {
  void *lib;
  void *(*GetProcAddress)(const char *);
  OSMesaContext (*CreateContextExt)(GLenum, GLint, GLint, GLint, OSMesaContext);
  GLboolean (*MakeCurrent)(OSMesaContext, void *, GLenum, GLsizei, GLsizei);
  OSMesaContext (*GetCurrentContext)(void);
  void (*DestroyContext)(OSMesaContext);
} osmesa_api_t;

struct sim_render {
  sim_render_backend_t backend;
  egl_api_t egl;
  osmesa_api_t osm;
  EGLDisplay egl_dpy;
  EGLContext egl_ctx;
  OSMesaContext osm_ctx;
  void *osm_buf;  /* OSMesa's default framebuffer (unused by MuJoCo's offscreen) */
  mjModel *mcopy; /* shallow copy of the model with our render settings */
  mjrContext con;
  mjvScene scn;
  mjvOption opt;
  mjvCamera cam;
  int maxw, maxh;
  uint8_t *rgba; /* RGBA readback: Mesa's fast glReadPixels path (RGB is ~30 % slower) */
  void (*ReadPixels)(GLint, GLint, GLsizei, GLsizei, GLenum, GLenum, void *);
  void (*BindFramebuffer)(GLenum, GLuint);
  void (*GetFloatv)(GLenum, GLfloat *);
  float light_k; /* day 1, night < 1: scales every scene light */
  long epoch;    /* counts changes of light_k and texture uploads: a cached image older is stale */
};

/* Makes the renderer's context current again (a viewer window may have taken it). 0 or -1. */
int sim_render_make_current(sim_render_t *r);
/* The scene of fixed camera cam_id for state d in r->scn, lights scaled by day or night. */
void sim_render_update_scene(sim_render_t *r, const mjModel *m, mjData *d, int cam_id);
/* Reads the offscreen buffer's width_px x height_px colour into rgb, rows top-down. */
void sim_render_read_rgb(sim_render_t *r, int width_px, int height_px, uint8_t *rgb);

#endif /* SIM_RENDER_INTERNAL_H */
