/* The viewer's Menu Panel (sim_viewer_internal.h): MuJoCo 2.2's own mjui, drawn over the
 * left of the scene. Its items point straight at the viewer's input state, so a click, a key
 * and a test's scripted click all change the same fields. Sections: Simulation, Car, View,
 * Sensors, Record (docs/reference/simulator.md, "The window"). */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "sim_viewer_internal.h"

/* Button names: sim_viewer_ui_mouse acts on them. */
#define UI_STEP "Step"
#define UI_RESET "Reset"
#define UI_QUIT "Quit"
#define UI_RECORD "Start or stop"
#define UI_ROW_GAP_PX 2 /* [px] between the panel's rows */

/* The Cam scale radio's elements: the cars' sensor cameras' render scale per side. */
static const double ui_cam_scales[] = {1.0, 0.5, 0.25};
#define UI_NCAM_SCALES ((int)(sizeof ui_cam_scales / sizeof *ui_cam_scales))

/* The radio's element of in.camera_scale, or -1 for a scale that is none of them. */
static int ui_cam_scale_index(double scale) {
  for (int k = 0; k < UI_NCAM_SCALES; k++)
    if (scale == ui_cam_scales[k]) return k;
  return -1;
}

void sim_viewer_ui_camera_names(const sim_viewer_t *v, const mjModel *m, char *out, size_t n) {
  int len = snprintf(out, n, "Driver\nBird\nGod\nFree");
  for (int k = 0; k < v->neyes && len > 0 && (size_t)len < n; k++)
    len += snprintf(out + len, n - (size_t)len, "\n%s", mj_id2name(m, mjOBJ_CAMERA, v->eye_cam[k]));
}

static void ui_add(sim_viewer_t *v, int type, const char *name, void *pdata, const char *other) {
  mjuiDef d[2];
  memset(d, 0, sizeof d);
  d[0].type = type;
  snprintf(d[0].name, sizeof d[0].name, "%s", name);
  d[0].state = 1;
  d[0].pdata = pdata;
  snprintf(d[0].other, sizeof d[0].other, "%s", other ? other : "");
  d[1].type = mjITEM_END;
  mjui_add(&v->ui, d);
}

void sim_viewer_ui_init(sim_viewer_t *v) {
  mjUI *ui = &v->ui;
  memset(ui, 0, sizeof *ui);
  ui->spacing = mjui_themeSpacing(0);
  /* 2 px less between rows (theme 0 has 4): the panel's 20 rows, the Cam scale line among them,
   * fit a 600 px window */
  ui->spacing.itemver = UI_ROW_GAP_PX;
  ui->color = mjui_themeColor(0);
  ui->rectid = 1;
  ui->auxid = 0;
  ui->radiocol = 2;
  char cars[mjMAXUITEXT] = "";
  for (int i = 1, len = 0; i <= v->ncars && i <= mjMAXUIMULTI; i++)
    len += snprintf(cars + len, sizeof cars - (size_t)len, "%s%d", i > 1 ? "\n" : "", i);
  char cams[mjMAXUITEXT], cam_scales[mjMAXUITEXT]; /* the radio's names, from ui_cam_scales */
  for (int k = 0, len = 0; k < UI_NCAM_SCALES; k++)
    len += snprintf(cam_scales + len, sizeof cam_scales - (size_t)len, "%s%g", k ? "\n" : "",
                    ui_cam_scales[k]);
  sim_viewer_ui_camera_names(v, v->model, cams, sizeof cams);
  /* the map in the section's title, not a line of its own: the panel fits a 600 px window */
  ui_add(v, mjITEM_SECTION, "Simulation", NULL, "");
  ui_add(v, mjITEM_CHECKINT, "Pause", &v->in.paused, "");
  ui_add(v, mjITEM_BUTTON, UI_STEP, NULL, "");
  ui_add(v, mjITEM_BUTTON, UI_RESET, NULL, "");
  ui_add(v, mjITEM_BUTTON, UI_QUIT, NULL, "");
  ui_add(v, mjITEM_SECTION, "Car", NULL, "");
  ui_add(v, mjITEM_RADIO, "Ego car", &v->ui_car, cars);
  ui_add(v, mjITEM_RADIO, "Driving", &v->in.manual, "Autonomous\nManual");
  ui_add(v, mjITEM_SECTION, "View", NULL, "");
  ui_add(v, mjITEM_RADIO, "Camera", &v->in.view, cams);
  ui_add(v, mjITEM_SLIDERNUM, "Light level", &v->in.light_level, "0 1");
  ui_add(v, mjITEM_CHECKINT, "Shadows", &v->in.shadows, "");
  ui_add(v, mjITEM_CHECKINT, "Reflections", &v->in.reflections, "");
  ui_add(v, mjITEM_CHECKINT, "Skybox", &v->in.skybox, "");
  ui_add(v, mjITEM_CHECKINT, "HUD", &v->in.hud, "");
  /* after the check boxes, which mjui packs two to a row */
  ui_add(v, mjITEM_SLIDERNUM, "View scale", &v->in.render_scale, "0.25 1");
  /* one line: the sensor cameras' render scale, beside the window's */
  ui_add(v, mjITEM_RADIOLINE, "Cam scale", &v->ui_cam_scale, cam_scales);
  ui_add(v, mjITEM_SECTION, "Sensors", NULL, "");
  ui_add(v, mjITEM_CHECKINT, "LIDAR rays", &v->in.lidar_rays, "");
  ui_add(v, mjITEM_CHECKINT, "Cameras", &v->in.thumbnails,
         ""); /* beside: the panel keeps its height */
  ui_add(v, mjITEM_SECTION, "Record", NULL, "");
  ui_add(v, mjITEM_BUTTON, UI_RECORD, NULL, "");
  mjui_resize(ui, &v->con);
  mjr_addAux(ui->auxid, ui->width, ui->maxheight, ui->spacing.samples, &v->con);
  mjr_setBuffer(mjFB_WINDOW, &v->con);
}

/* The panel's rectangle (state rect 1): the left of the window, full height; rect 0 the whole
 * window. */
static void ui_rects(sim_viewer_t *v) {
  mjuiState *st = &v->ui_state;
  st->nrect = 2;
  st->rect[0] = (mjrRect){0, 0, v->w, v->h};
  st->rect[1] = (mjrRect){0, 0, v->panel ? v->ui.width : 0, v->h};
}

void sim_viewer_ui_render(sim_viewer_t *v) {
  if (!v->panel) return;
  ui_rects(v);
  v->ui_car = v->in.car - 1;
  v->ui_cam_scale = ui_cam_scale_index(v->in.camera_scale);
  /* redrawn into its buffer only when what it shows changed: a software rasteriser pays for
   * every item on every redraw */
  sim_viewer_input_t shown = v->in;
  shown.drive_keys = 0; /* the panel does not show them: holding a key costs no redraw */
  if (v->ui_dirty || memcmp(&v->ui_shown, &shown, sizeof shown) != 0) {
    mjui_update(-1, -1, &v->ui, &v->ui_state, &v->con);
    v->ui_shown = shown;
    v->ui_dirty = 0;
  }
  mjui_render(&v->ui, &v->ui_state, &v->con);
  mjr_setBuffer(mjFB_WINDOW, &v->con);
}

/* What a button does, by its name. */
static void ui_button(sim_viewer_t *v, const char *name) {
  if (!strcmp(name, UI_STEP)) v->in.step_requested = 1;
  if (!strcmp(name, UI_RESET)) v->in.reset_requested = 1;
  if (!strcmp(name, UI_QUIT)) v->in.quit = 1;
  if (!strcmp(name, UI_RECORD)) v->in.record_toggled = 1;
}

int sim_viewer_ui_mouse(sim_viewer_t *v, double x_px, double y_px, int press) {
  if (!v->panel) return 0;
  ui_rects(v);
  mjuiState *st = &v->ui_state;
  st->x = x_px;
  st->y = v->h - y_px; /* mjui: y up from the bottom */
  const int inside = x_px >= 0 && x_px < v->ui.width && y_px >= 0 && y_px < v->h;
  st->mouserect = inside ? 1 : 0;
  st->type = press ? mjEVENT_PRESS : mjEVENT_RELEASE;
  st->left = press;
  st->button = mjBUTTON_LEFT;
  st->doubleclick = 0;
  if (press) {
    st->dragrect = st->mouserect;
    st->dragbutton = mjBUTTON_LEFT;
  }
  const int owned = st->dragrect == 1;
  v->ui_car = v->in.car - 1;
  v->ui_cam_scale = ui_cam_scale_index(v->in.camera_scale);
  mjuiItem *it = mjui_event(&v->ui, st, &v->con);
  v->ui_dirty = 1;
  if (it && it->type == mjITEM_BUTTON) ui_button(v, it->name); /* edges: once a frame */
  if (it && it->pdata == &v->ui_car) v->in.car = v->ui_car + 1;
  if (it && it->pdata == &v->ui_cam_scale && v->ui_cam_scale >= 0 &&
      v->ui_cam_scale < UI_NCAM_SCALES)
    v->in.camera_scale = ui_cam_scales[v->ui_cam_scale];
  if (it && it->pdata == &v->in.light_level) v->in.day = v->in.light_level >= 0.5;
  if (!press) st->dragrect = 0;
  mjr_setBuffer(mjFB_WINDOW, &v->con);
  return owned || inside;
}

/* The centre of element k of a radio item (radiocol columns; a radio line's all in one row) in
 * the item's own rectangle; y up. A radio line's elements are as wide as their text: equal
 * shares still land inside each (short names, few of them). */
static void ui_radio_centre(const mjUI *ui, const mjuiItem *it, int k, double *x, double *y) {
  const int ncol = it->type == mjITEM_RADIOLINE ? it->multi.nelem
                   : ui->radiocol > 0           ? ui->radiocol
                                                : 2;
  const int nrow = (it->multi.nelem + ncol - 1) / ncol;
  const double left = it->rect.left; /* the rectangle is the elements' (the label is left of it) */
  const double col_w = (double)it->rect.width / ncol;
  const double row_h = (double)it->rect.height / (nrow > 0 ? nrow : 1);
  *x = left + (k % ncol + 0.5) * col_w;
  *y = it->rect.bottom + it->rect.height - (k / ncol + 0.5) * row_h;
}

int sim_viewer_item_at(const sim_viewer_t *v, const char *name, double *x_px, double *y_px) {
  if (!v->panel) return -1;
  char item[mjMAXUINAME * 2];
  snprintf(item, sizeof item, "%s", name);
  char *element = strchr(item, '/');
  if (element) *element++ = 0;
  const mjUI *ui = &v->ui;
  for (int s = 0; s < ui->nsect; s++)
    for (int i = 0; i < ui->sect[s].nitem; i++) {
      const mjuiItem *it = &ui->sect[s].item[i];
      if (strcmp(it->name, item) != 0 || !ui->sect[s].state) continue;
      double x = it->rect.left + it->rect.width / 2.0, y = it->rect.bottom + it->rect.height / 2.0;
      if (element) {
        int k = 0;
        while (k < it->multi.nelem && strcmp(it->multi.name[k], element) != 0) k++;
        if (k == it->multi.nelem) return -1;
        ui_radio_centre(ui, it, k, &x, &y);
      }
      *x_px = x;
      *y_px = ui->height - y + ui->scroll; /* the panel's top is the window's top */
      return 0;
    }
  return -1;
}
