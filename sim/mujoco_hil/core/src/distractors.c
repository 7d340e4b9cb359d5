/* Distractors (sim_internal.h, sim_config_t.distractors): static cones, boxes and
 * parked-car-sized boxes beside the road, for domain randomisation. Their kinds, sizes, yaws
 * and colours are drawn from the seed before the scene is written (a geom's shape is fixed in
 * MuJoCo 2.2); their places once the cars stand, like a late box's, through the model's
 * geom_pos, so that the check sees the cars' start footprints. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "route.h"
#include "sim_internal.h"

#define DIS_TRIES 4000        /* random places tried per distractor before giving up */
#define DIS_CAR_MARGIN_M 0.15 /* clear of a car's start footprint */
#define DIS_GAP_M 0.05        /* between distractors and late boxes */
/* beyond a lane's edge: the road's kerb side (a 0.64 m road holds 2 x 0.28 m lanes) */
#define DIS_LANE_MARGIN_M 0.06
/* every distractor reaches above the LIDAR's scan plane (0.176 m over base_link, which rides
 * ~2 mm above the floor), so the LIDAR sees it as the cameras do */
#define DIS_MIN_HALF_Z_M 0.095

static double dis_between(rng_t *r, double lo, double hi) {
  return lo + (hi - lo) * rng_uniform(r);
}

void sim_draw_distractors(sim_t *s, const sim_config_t *cfg) {
  s->ndistractor_keep_clear = 0;
  for (int i = 0; i < cfg->distractor_keep_clear && i < 2 * SIM_MAX_CARS; i++)
    s->distractor_keep_clear[s->ndistractor_keep_clear++] = cfg->distractor_keep_clear_pose[i];
  rng_t r;
  rng_seed(&r, (cfg->seed ^ 0xd157ac7ull) * 0xBF58476D1CE4E5B9ull);
  s->ndistractor = cfg->distractors;
  for (int k = 0; k < s->ndistractor; k++) {
    mjcf_gen_distractor_t *d = &s->distractor[k];
    memset(d, 0, sizeof *d);
    d->kind = (mjcf_gen_distractor_kind_t)(int)(3.0 * rng_uniform(&r));
    d->yaw_rad = dis_between(&r, -M_PI, M_PI);
    const float shade = (float)dis_between(&r, 0.6, 1.0);
    if (d->kind == MG_CONE) { /* a pylon: 19..24 cm tall, 4..8 cm across */
      d->half_m[0] = d->half_m[1] = dis_between(&r, 0.02, 0.04);
      d->half_m[2] = dis_between(&r, DIS_MIN_HALF_Z_M, 0.12);
      d->yaw_rad = 0.0;
      memcpy(d->rgba, (float[4]){shade, 0.45f * shade, 0.05f, 1}, sizeof d->rgba);
    } else if (d->kind == MG_BOX) { /* construction boxes, 6..24 cm across, 19..30 cm tall */
      for (int a = 0; a < 2; a++) d->half_m[a] = dis_between(&r, 0.03, 0.12);
      d->half_m[2] = dis_between(&r, DIS_MIN_HALF_Z_M, 0.15);
      memcpy(d->rgba, (float[4]){0.75f * shade, 0.55f * shade, 0.3f * shade, 1}, sizeof d->rgba);
    } else { /* a parked Nigel's size (the maps' parked cars: 0.24 x 0.18 x 0.24 m) */
      d->half_m[0] = 0.12;
      d->half_m[1] = 0.09;
      d->half_m[2] = 0.12;
      memcpy(d->rgba,
             (float[4]){(float)rng_uniform(&r), (float)rng_uniform(&r), (float)rng_uniform(&r), 1},
             sizeof d->rgba);
    }
  }
}

/* Distance from (x, y) to the polyline r [m]. */
static double dis_to_line(const route_t *r, double x, double y) {
  double best = INFINITY;
  const int nseg = r->loop ? r->n : r->n - 1;
  for (int i = 0; i < nseg; i++) {
    const double *a = r->xy + 2 * i, *b = r->xy + 2 * ((i + 1) % r->n);
    const double ex = b[0] - a[0], ey = b[1] - a[1], len_sq = ex * ex + ey * ey;
    double t = len_sq > 0 ? ((x - a[0]) * ex + (y - a[1]) * ey) / len_sq : 0.0;
    t = t < 0 ? 0 : (t > 1 ? 1 : t);
    best = fmin(best, hypot(x - a[0] - t * ex, y - a[1] - t * ey));
  }
  return best;
}

/* The map's lanes (lane_*) and routes (route_*) with their half widths. */
typedef struct dis_lanes {
  int n;
  route_t *line;
} dis_lanes_t;

static int dis_lanes_load(const mjModel *m, dis_lanes_t *l, char *err, size_t err_sz) {
  l->n = 0;
  l->line = calloc((size_t)(m->nnumeric > 0 ? m->nnumeric : 1), sizeof *l->line);
  if (!l->line) return sim_fail(err, err_sz, "%s%s", "--distractors: out of memory", "");
  for (int i = 0; i < m->nnumeric; i++) {
    const char *name = m->names + m->name_numericadr[i];
    const int lane = !strncmp(name, "lane_", 5), route = !strncmp(name, "route_", 6);
    if ((!lane && !route) || strstr(name, ".part")) continue;
    if (route_from_numeric(&l->line[l->n], m, i, route, err, err_sz) != 0) return -1;
    l->n++;
  }
  return 0;
}

static void dis_lanes_free(dis_lanes_t *l) {
  for (int i = 0; i < l->n; i++) route_free(&l->line[i]);
  free(l->line);
}

/* The upright prism of distractor k centred at (x, y). */
static void dis_prism(const mjcf_gen_distractor_t *d, double x, double y, clearance_prism_t *p) {
  p->centre_m[0] = x;
  p->centre_m[1] = y;
  p->yaw_rad = d->yaw_rad;
  p->half_m[0] = d->half_m[0];
  p->half_m[1] = d->half_m[1];
  p->z_lo_m = SIM_GROUND_CLEARANCE_M;
  p->z_hi_m = 2.0 * d->half_m[2];
}

static void dis_grow(clearance_prism_t *p, double by_m) {
  p->half_m[0] += by_m;
  p->half_m[1] += by_m;
  p->z_lo_m = 0.0;
  p->z_hi_m = 1e3;
}

/* 1 when distractor d may stand at (x, y): off every lane, clear of the cars, the late boxes
 * and (through the map check, as world geoms) the map's obstacles and the distractors placed
 * before it. */
static int dis_fits(const sim_t *s, const dis_lanes_t *lanes, const mjcf_gen_distractor_t *d,
                    double x, double y, int ct, int ca) {
  const double radius = hypot(d->half_m[0], d->half_m[1]);
  for (int i = 0; i < lanes->n; i++)
    if (dis_to_line(&lanes->line[i], x, y) <
        lanes->line[i].half_width_m + radius + DIS_LANE_MARGIN_M)
      return 0;
  clearance_prism_t p, q;
  dis_prism(d, x, y, &p);
  for (int i = 0; i < s->ncars + s->ndistractor_keep_clear; i++) {
    if (i < s->ncars) {
      sim_car_prism(s, i, &q);
    } else {
      const scn_pose_t *at = &s->distractor_keep_clear[i - s->ncars];
      sim_car_prism_at(s, at->x_m, at->y_m, SIM_SPAWN_Z_M, at->yaw_deg * (M_PI / 180.0), &q);
    }
    dis_grow(&q, DIS_CAR_MARGIN_M);
    if (clearance_prisms_overlap(&p, &q)) return 0;
  }
  for (int k = 0; k < s->nbox; k++) {
    sim_box_prism(&s->box[k], &q);
    dis_grow(&q, DIS_GAP_M);
    if (clearance_prisms_overlap(&p, &q)) return 0;
  }
  clearance_prism_t wide = p; /* a gap to the map's obstacles and the other distractors */
  wide.half_m[0] += DIS_GAP_M;
  wide.half_m[1] += DIS_GAP_M;
  char why[256];
  return clearance_check_on_map(s->m, s->d, &wide, ct, ca, why, sizeof why) == 0;
}

/* Moves distractor k's geom to (x, y) on the floor, in both models. */
static void dis_move(sim_t *s, int k, double x, double y) {
  const mjtNum pos[3] = {x, y, s->distractor[k].half_m[2]};
  char name[48];
  snprintf(name, sizeof name, "scenario/distractor%d", k + 1);
  mju_copy3(s->m->geom_pos + 3 * s->distractor_geom[k], pos);
  const int gv = s->mv ? mj_name2id(s->mv, mjOBJ_GEOM, name) : -1;
  if (gv >= 0) mju_copy3(s->mv->geom_pos + 3 * gv, pos);
  s->distractor_xy[k][0] = x;
  s->distractor_xy[k][1] = y;
}

/* The floor's extent: the first upward plane with a drawn size. */
static int dis_floor(const mjModel *m, double *cx, double *cy, double *hx, double *hy) {
  for (int g = 0; g < m->ngeom; g++)
    if (m->geom_type[g] == mjGEOM_PLANE && m->geom_bodyid[g] == 0 && m->geom_size[3 * g] > 0 &&
        m->geom_size[3 * g + 1] > 0) {
      *cx = m->geom_pos[3 * g];
      *cy = m->geom_pos[3 * g + 1];
      *hx = m->geom_size[3 * g];
      *hy = m->geom_size[3 * g + 1];
      return 0;
    }
  return -1;
}

int sim_place_distractors(sim_t *s, char *err, size_t err_sz) {
  if (s->ndistractor == 0) return 0;
  double cx, cy, hx, hy;
  if (dis_floor(s->m, &cx, &cy, &hx, &hy) != 0)
    return sim_fail(err, err_sz, "%s%s", "--distractors: the map has no floor plane to stand on",
                    "");
  for (int k = 0; k < s->ndistractor; k++) {
    char name[48];
    snprintf(name, sizeof name, "scenario/distractor%d", k + 1);
    if ((s->distractor_geom[k] = mj_name2id(s->m, mjOBJ_GEOM, name)) < 0)
      return sim_fail(err, err_sz, "generated model lacks world geom '%s'%s", name, "");
  }
  dis_lanes_t lanes;
  if (dis_lanes_load(s->m, &lanes, err, err_sz) != 0) {
    dis_lanes_free(&lanes);
    return -1;
  }
  const int ct = s->m->geom_contype[s->car[0].chassis_geom],
            ca = s->m->geom_conaffinity[s->car[0].chassis_geom];
  rng_t r;
  rng_seed(&r, (s->seed ^ 0x91ace5ull) * 0x94D049BB133111EBull);
  mj_kinematics(s->m, s->d);
  int rc = 0;
  for (int k = 0; k < s->ndistractor && rc == 0; k++) {
    const mjcf_gen_distractor_t *d = &s->distractor[k];
    int placed = 0;
    for (int t = 0; t < DIS_TRIES && !placed; t++) {
      const double x = cx + dis_between(&r, -hx, hx), y = cy + dis_between(&r, -hy, hy);
      if (!dis_fits(s, &lanes, d, x, y, ct, ca)) continue;
      dis_move(s, k, x, y);
      mj_kinematics(s->m, s->d); /* the next one's map check sees this one */
      placed = 1;
    }
    if (!placed) {
      snprintf(err, err_sz,
               "--distractors %d: no free place beside the road for distractor %d after %d tries "
               "(off the lanes, clear of the cars' starts, obstacles and the other distractors): "
               "the map has no room for that many",
               s->ndistractor, k + 1, DIS_TRIES);
      rc = -1;
    }
  }
  dis_lanes_free(&lanes);
  return rc;
}
