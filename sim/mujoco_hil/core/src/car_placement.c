/* Where the cars stand (sim_internal.h): start poses at the spawn site or --start, the
 * footprints the scenario checks test against the map, and the learning API's reset and
 * teleport, which move cars and check them the same way. */
#include <math.h>
#include <stdio.h>

#include "sim_internal.h"

void sim_set_car_pose(sim_t *s, int i, const double base[3], double yaw, int row, int col) {
  mjtNum *qp = s->d->qpos + s->car[i].root_qpos;
  const double right = -SIM_CAR_SPACING_M * col, back = -SIM_CAR_ROW_PITCH_M * row;
  qp[0] = base[0] + back * cos(yaw) - right * sin(yaw);
  qp[1] = base[1] + back * sin(yaw) + right * cos(yaw);
  qp[2] = SIM_SPAWN_Z_M;
  qp[3] = cos(0.5 * yaw);
  qp[4] = qp[5] = 0.0;
  qp[6] = sin(0.5 * yaw);
  mju_copy(s->m->qpos0 + s->car[i].root_qpos, qp, 7);
}

/* Car 1 stands at --start, else at the map's "spawn" site (or the origin); the others side
 * by side to its right. With --start they stay in that one row and sim_check_scenario judges
 * it; at the spawn site a car that would stand on a wall, an obstacle or off the floor takes
 * the next free place, in rows behind car 1 when a row is full. The model's qpos0 gets the
 * same poses, so a reset (mj_resetData, the viewer's R) puts the cars back where they
 * started. Returns 0, or -1 when a car finds no place. */
int sim_place_cars(sim_t *s, char *err, size_t err_sz) {
  double base[3] = {0, 0, 0}, yaw = 0.0;
  const int site = mj_name2id(s->m, mjOBJ_SITE, "spawn");
  if (s->has_start) {
    base[0] = s->start.x_m;
    base[1] = s->start.y_m;
    yaw = s->start.yaw_deg * (M_PI / 180.0);
  } else if (site >= 0) {
    mju_copy3(base, s->m->site_pos + 3 * site);
    const mjtNum *q = s->m->site_quat + 4 * site;
    yaw = atan2(2.0 * (q[0] * q[3] + q[1] * q[2]), 1.0 - 2.0 * (q[2] * q[2] + q[3] * q[3]));
  }
  if (s->has_start) {
    for (int i = 0; i < s->ncars; i++) sim_set_car_pose(s, i, base, yaw, 0, i);
    return 0;
  }
  mj_kinematics(s->m, s->d); /* the static geoms' poses, for the clearance check */
  const mjModel *m = s->m;
  const int ct = m->geom_contype[s->car[0].chassis_geom],
            ca = m->geom_conaffinity[s->car[0].chassis_geom];
  int place = 0; /* next place to try: row place / SIM_PLACES_PER_ROW, column the rest */
  for (int i = 0; i < s->ncars; i++) {
    for (;; place++) {
      if (place >= SIM_PLACES_PER_ROW * SIM_PLACE_ROWS) {
        snprintf(err, err_sz,
                 "no room for NIGEL%d: %d rows of %d places from the map's spawn site are taken "
                 "or blocked (fewer --cars, or --start elsewhere)",
                 i + 1, SIM_PLACE_ROWS, SIM_PLACES_PER_ROW);
        return -1;
      }
      sim_set_car_pose(s, i, base, yaw, place / SIM_PLACES_PER_ROW, place % SIM_PLACES_PER_ROW);
      clearance_prism_t pr;
      sim_car_prism(s, i, &pr);
      char why[512];
      if (clearance_check_on_map(m, s->d, &pr, ct, ca, why, sizeof why) == 0) break;
    }
    place++;
  }
  return 0;
}

/* The upright prism around car i's chassis and wheels at its current pose. */
void sim_car_prism(const sim_t *s, int i, clearance_prism_t *out) {
  const mjtNum *qp = s->d->qpos + s->car[i].root_qpos;
  const double yaw =
      atan2(2.0 * (qp[3] * qp[6] + qp[4] * qp[5]), 1.0 - 2.0 * (qp[5] * qp[5] + qp[6] * qp[6]));
  sim_car_prism_at(s, qp[0], qp[1], qp[2], yaw, out);
}

void sim_car_prism_at(const sim_t *s, double x_m, double y_m, double z_m, double yaw,
                      clearance_prism_t *out) {
  const vehicle_params_t *p = &s->p;
  const double *co = p->chassis_offset_m, *cs = p->chassis_size_m;
  const double r = p->wheel_radius_m, wy = 0.5 * (p->track_m + p->wheel_width_m);
  const double x0 = fmin(co[0] - 0.5 * cs[0], -r),
               x1 = fmax(co[0] + 0.5 * cs[0], p->wheelbase_m + r);
  const double y0 = fmin(co[1] - 0.5 * cs[1], -wy), y1 = fmax(co[1] + 0.5 * cs[1], wy);
  const double cx = 0.5 * (x0 + x1), cy = 0.5 * (y0 + y1); /* in the car's frame */
  out->centre_m[0] = x_m + cos(yaw) * cx - sin(yaw) * cy;
  out->centre_m[1] = y_m + sin(yaw) * cx + cos(yaw) * cy;
  out->yaw_rad = yaw;
  out->half_m[0] = 0.5 * (x1 - x0);
  out->half_m[1] = 0.5 * (y1 - y0);
  out->z_lo_m = SIM_GROUND_CLEARANCE_M;
  out->z_hi_m = z_m + co[2] + 0.5 * cs[2];
}

void sim_box_prism(const scn_late_box_t *b, clearance_prism_t *out) {
  out->centre_m[0] = b->x_m;
  out->centre_m[1] = b->y_m;
  out->yaw_rad = b->yaw_rad;
  out->half_m[0] = b->half_x_m;
  out->half_m[1] = b->half_y_m;
  out->z_lo_m = SIM_GROUND_CLEARANCE_M;
  out->z_hi_m = 2.0 * scn_late_box_half_z(b);
}

int sim_check_scenario(const sim_t *s, char *err, size_t err_sz) {
  const mjModel *m = s->m;
  const int ct = m->geom_contype[s->car[0].chassis_geom],
            ca = m->geom_conaffinity[s->car[0].chassis_geom];
  char why[512];
  clearance_prism_t pr;
  for (int i = 0; s->has_start && i < s->ncars; i++) {
    sim_car_prism(s, i, &pr);
    if (clearance_check_on_map(m, s->d, &pr, ct, ca, why, sizeof why) == 0) continue;
    const mjtNum *qp = s->d->qpos + s->car[i].root_qpos;
    char who[96] = "";
    if (i > 0)
      snprintf(who, sizeof who, " (%.2f m to the right of NIGEL1 with --cars %d)",
               SIM_CAR_SPACING_M * i, s->ncars);
    snprintf(err, err_sz, "--start '%g,%g,%g': NIGEL%d%s at x %.3f, y %.3f m %s", s->start.x_m,
             s->start.y_m, s->start.yaw_deg, i + 1, who, qp[0], qp[1], why);
    return -1;
  }
  for (int k = 0; k < s->nbox; k++) {
    const scn_late_box_t *b = &s->box[k];
    sim_box_prism(b, &pr);
    if (clearance_check_on_map(m, s->d, &pr, ct, ca, why, sizeof why) == 0) continue;
    if (b->name[0])
      snprintf(err, err_sz, "map late obstacle '%s' at x %g, y %g m: the box %s", b->name, b->x_m,
               b->y_m, why);
    else
      snprintf(err, err_sz, "--late-box '%g,%g,%g,%g,%g': the box %s", b->x_m, b->y_m, b->t_s,
               b->half_x_m, b->half_y_m, why);
    return -1;
  }
  return 0;
}
int sim_reset(sim_t *s, uint64_t seed, const double *poses, char *err, size_t err_sz) {
  if (poses) {
    mjtNum saved[7 * SIM_MAX_CARS]; /* the old start poses, back in place on a refusal */
    for (int i = 0; i < s->ncars; i++)
      mju_copy(saved + 7 * i, s->m->qpos0 + s->car[i].root_qpos, 7);
    for (int i = 0; i < s->ncars; i++) {
      const double *p = poses + 3 * i;
      if (!isfinite(p[0]) || !isfinite(p[1]) || !isfinite(p[2]) || fabs(p[0]) > SCN_COORD_MAX_M ||
          fabs(p[1]) > SCN_COORD_MAX_M) {
        snprintf(err, err_sz, "reset pose of car %d (%g, %g, %g): not a finite pose on the map", i,
                 p[0], p[1], p[2]);
        return -1;
      }
      sim_set_car_pose(s, i, p, p[2], 0, 0); /* and qpos0: the new start pose */
    }
    mj_kinematics(s->m, s->d); /* the static geoms' poses, for the clearance check */
    const int ct = s->m->geom_contype[s->car[0].chassis_geom],
              ca = s->m->geom_conaffinity[s->car[0].chassis_geom];
    for (int i = 0; i < s->ncars; i++) {
      clearance_prism_t pr;
      char why[512];
      sim_car_prism(s, i, &pr);
      if (clearance_check_on_map(s->m, s->d, &pr, ct, ca, why, sizeof why) != 0) {
        snprintf(err, err_sz, "reset pose of car %d (x %.3f, y %.3f m, yaw %.3f rad): %s", i,
                 poses[3 * i], poses[3 * i + 1], poses[3 * i + 2], why);
        for (int j = 0; j < s->ncars; j++)
          mju_copy(s->m->qpos0 + s->car[j].root_qpos, saved + 7 * j, 7);
        return -1;
      }
    }
  }
  s->seed = seed;
  s->time_us = 0;
  mj_resetData(s->m, s->d); /* qpos0 holds the start poses */
  sim_reset_late_boxes(s);
  mj_forward(s->m, s->d);
  for (int i = 0; i < s->ncars; i++)
    if (sim_car_boot(s, &s->car[i], err, err_sz) != 0) return -1;
  return 0;
}

int sim_teleport(sim_t *s, int car, double x_m, double y_m, double yaw_rad, char *err,
                 size_t err_sz) {
  if (car < 1 || car > s->ncars) {
    snprintf(err, err_sz, "no car %d (the sim has %d)", car, s->ncars);
    return -1;
  }
  if (!isfinite(x_m) || !isfinite(y_m) || !isfinite(yaw_rad) || fabs(x_m) > SCN_COORD_MAX_M ||
      fabs(y_m) > SCN_COORD_MAX_M) {
    snprintf(err, err_sz, "(%g, %g, %g) is not a finite pose on the map", x_m, y_m, yaw_rad);
    return -1;
  }
  sim_car_t *c = &s->car[car - 1];
  mjtNum *qp = s->d->qpos + c->root_qpos;
  mjtNum saved[7], saved0[7];
  mju_copy(saved, qp, 7);
  mju_copy(saved0, s->m->qpos0 + c->root_qpos, 7);
  const double base[3] = {x_m, y_m, 0.0};
  sim_set_car_pose(s, car - 1, base, yaw_rad, 0, 0);
  mju_copy(s->m->qpos0 + c->root_qpos, saved0, 7); /* the start pose stays the reset's */
  clearance_prism_t pr;
  char why[512];
  sim_car_prism(s, car - 1, &pr);
  if (clearance_check_on_map(s->m, s->d, &pr, s->m->geom_contype[c->chassis_geom],
                             s->m->geom_conaffinity[c->chassis_geom], why, sizeof why) != 0) {
    mju_copy(qp, saved, 7);
    snprintf(err, err_sz, "(x %.3f, y %.3f m, yaw %.3f rad): %s", x_m, y_m, yaw_rad, why);
    return -1;
  }
  for (int j = 0; j < s->m->njnt; j++) { /* every joint of the car: free, knuckles, wheels */
    int b = s->m->jnt_bodyid[j];
    while (b > 0 && b != c->body) b = s->m->body_parentid[b];
    if (b == c->body)
      mju_zero(s->d->qvel + s->m->jnt_dofadr[j], s->m->jnt_type[j] == mjJNT_FREE ? 6 : 1);
  }
  mj_forward(s->m, s->d);
  return 0;
}
