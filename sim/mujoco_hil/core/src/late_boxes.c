/* Late boxes (sim_internal.h): the --late-box boxes and the map's late_obstacles, world geoms
 * parked out of the way until their time (or their car coming near), then on the floor, and
 * away again after their stay. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "sim_internal.h"

/* A late box is a world geom, moved by its model position: MuJoCo's kinematics recompute world
 * geoms each step, and a world geom costs the step far less than a (mocap) body would. */
static void sim_move_late_box(sim_t *s, int k, const mjtNum pos_m[3]) {
  mju_copy3(s->m->geom_pos + 3 * s->box_geom[k], pos_m);
  if (s->mv) mju_copy3(s->mv->geom_pos + 3 * s->box_geom_v[k], pos_m);
}

/* Back to the run's start: every box parked where it waits, none appeared yet. */
void sim_reset_late_boxes(sim_t *s) {
  for (int k = 0; k < s->nbox; k++) sim_move_late_box(s, k, s->box_parked[k]);
  for (int k = 0; k < s->nbox; k++)
    s->box_placed[k] = s->box_new[k] = s->box_car_below[k] = s->box_gone[k] = s->box_left[k] = 0;
}

/* Moves the late boxes that are due onto the floor (again after a reset). */
void sim_place_late_boxes(sim_t *s) {
  for (int k = 0; k < s->nbox; k++) {
    s->box_new[k] = s->box_left[k] = 0;
    const scn_late_box_t *b = &s->box[k];
    if (s->box_gone[k] || s->time_us < (int64_t)llround(b->t_s * 1e6)) continue;
    if (!s->box_placed[k] && b->near_m > 0) { /* a box that steps out as the car comes near */
      const mjtNum *car = s->d->qpos + s->car[0].root_qpos;
      if (hypot(car[0] - b->x_m, car[1] - b->y_m) > b->near_m) continue;
    }
    if (s->box_placed[k] && b->stay_s > 0 &&
        s->time_us - s->box_at_us[k] >= (int64_t)llround(b->stay_s * 1e6)) {
      sim_move_late_box(s, k, s->box_parked[k]); /* back where it waited */
      s->box_gone[k] = s->box_left[k] = 1;
      continue;
    }
    if (s->box_placed[k]) continue;
    const mjtNum pos[3] = {b->x_m, b->y_m, scn_late_box_half_z(b)};
    sim_move_late_box(s, k, pos);
    s->box_placed[k] = s->box_new[k] = 1;
    s->box_at_us[k] = s->time_us;
    clearance_prism_t bp, cp;
    sim_box_prism(b, &bp);
    for (int i = 0; i < s->ncars && !s->box_car_below[k]; i++) {
      sim_car_prism(s, i, &cp);
      if (clearance_prisms_overlap(&bp, &cp)) s->box_car_below[k] = i + 1;
    }
  }
}

int sim_bind_late_boxes(sim_t *s, char *err, size_t err_sz) {
  for (int k = 0; k < s->nbox; k++) {
    char name[48];
    snprintf(name, sizeof name, "scenario/late_box%d", k + 1);
    const int g = mj_name2id(s->m, mjOBJ_GEOM, name);
    const int gv = s->mv ? mj_name2id(s->mv, mjOBJ_GEOM, name) : -1;
    if (g < 0 || s->m->geom_bodyid[g] != 0 || (s->mv && gv < 0)) {
      snprintf(err, err_sz, "generated model lacks world geom '%s'", name);
      return -1;
    }
    s->box_geom[k] = g;
    s->box_geom_v[k] = gv;
    mju_copy3(s->box_parked[k], s->m->geom_pos + 3 * g);
  }
  return 0;
}
/* The map's late_obstacles (tools/gen-maps writes each as the custom numeric late_<name>:
 * x y yaw [m, rad], full sizes x y z [m], appear_s [s] or 0, trigger_radius_m [m] or 0) join
 * the --late-box boxes, after them. */
int sim_read_map_late_boxes(sim_t *s, const mjModel *mm, const char *path, char *err,
                            size_t err_sz) {
  int found = 0;
  for (int i = 0; i < mm->nnumeric; i++) {
    const char *name = mm->names + mm->name_numericadr[i];
    if (strncmp(name, "late_", 5) != 0) continue;
    if (++found > SCN_MAX_MAP_LATE_BOXES) {
      snprintf(err, err_sz, "map file '%s': more than %d late obstacles", path,
               SCN_MAX_MAP_LATE_BOXES);
      return -1;
    }
    const mjtNum *v = mm->numeric_data + mm->numeric_adr[i];
    if (mm->numeric_size[i] != 8 || !(v[3] > 0 && v[4] > 0 && v[5] > 0) || v[6] < 0 || v[7] < 0) {
      snprintf(err, err_sz,
               "map file '%s': numeric '%s' must be x y yaw sx sy sz appear_s trigger_radius_m "
               "(sizes > 0, times and radius >= 0)",
               path, name);
      return -1;
    }
    scn_late_box_t *b = &s->box[s->nbox++];
    memset(b, 0, sizeof *b);
    snprintf(b->name, sizeof b->name, "%s", name + 5);
    b->x_m = v[0];
    b->y_m = v[1];
    b->yaw_rad = v[2];
    b->half_x_m = 0.5 * v[3];
    b->half_y_m = 0.5 * v[4];
    b->half_z_m = 0.5 * v[5];
    b->t_s = v[6];
    b->near_m = v[7];
  }
  return 0;
}
int sim_late_boxes(const sim_t *s) {
  return s->nbox;
}
const scn_late_box_t *sim_late_box(const sim_t *s, int k) {
  return &s->box[k];
}
int sim_late_box_appeared(const sim_t *s, int k, int *car_below) {
  if (car_below) *car_below = s->box_car_below[k];
  return s->box_new[k];
}
int sim_late_box_left(const sim_t *s, int k) {
  return s->box_left[k];
}
