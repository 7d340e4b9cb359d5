/* sim_lidar: see sim_lidar.h. */
#include "sim_lidar.h"

#include <autodrive_vehicle.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define LIDAR_FEW_RAYS 8 /* rays per step up to which lidar_select_few is the cheaper path */
#define LIDAR_GROUP_MARGIN_M 0.05 /* added to a moving group's bounding sphere */

struct sim_lidar {
  sim_lidar_config_t cfg;
  int base_body; /* body carrying the scanner */
  int root_body; /* its root: geoms under it are the car itself */
  int *seen;     /* geoms the scanner can ever see: in a seen group, not the car's */
  int nseen;
  /* seen geoms grouped by root body: group k is seen[group_first[k] .. group_first[k + 1]).
   * A group that moves as one (another car, a late box) is culled as a whole by a sphere
   * around its root body (group_radius_m; < 0: never culled, e.g. the static world) */
  int *group_first, *group_root;
  double *group_radius_m;
  int ngroup;
  int groups_sized;          /* radii measured (needs kinematics: the first update) */
  int few_n[LIDAR_FEW_RAYS]; /* lidar_select_few: ray j's list is bucket[j * nseen..] */
  int *cand;                 /* candidates for this scan: seen, visible, crossing the scan plane */
  int *cand_lo, *cand_n;     /* per candidate: first ray index of its sector and its ray count */
  int ncand;
  int *bucket_start; /* rays [from, to): candidates of ray from+j are */
  int *bucket;       /*   bucket[bucket_start[j] .. bucket_start[j+1]) */
  size_t bucket_cap;
  double *ray_cos, *ray_sin;         /* per ray index i: cos, sin of i * 2 pi / num_rays [1]: the
                                      * rays' fixed angles, so no trig per ray per step */
  float *ranges_m, *quality;         /* revolution being filled */
  float *out_ranges_m, *out_quality; /* last completed revolution */
  sim_lidar_scan_t last;
  int64_t rev_start_us;   /* sim time at which the current revolution started [us] */
  int next_ray;           /* next sweep step of the current revolution */
  int cast_from, cast_to; /* sweep steps [from, to) cast by the last update */
  int started;
  uint64_t rng; /* xorshift64* state for the noise */
};

static void err_set(char *err, size_t n, const char *msg, const char *arg) {
  if (err && n) snprintf(err, n, "sim_lidar: %s%s%s", msg, arg ? ": " : "", arg ? arg : "");
}

void sim_lidar_config_default(sim_lidar_config_t *cfg) {
  memset(cfg, 0, sizeof *cfg);
  cfg->num_rays = 360;
  cfg->range_min_m = 0.15;
  cfg->range_max_m = 12.0;
  cfg->rate_hz = 7.0;
  cfg->mount_pos_m[0] = AUTODRIVE_VEHICLE_LIDAR_POS_M_X;
  cfg->mount_pos_m[1] = AUTODRIVE_VEHICLE_LIDAR_POS_M_Y;
  cfg->mount_pos_m[2] = AUTODRIVE_VEHICLE_LIDAR_POS_M_Z;
  cfg->noise_std_m = 0.0;
  cfg->seed = 1;
  for (int g = 0; g < mjNGROUP; g++) cfg->geomgroup[g] = g < 3;
}

/* Orders seen by root body (then geom id) and records the groups. */
static void lidar_group(const mjModel *m, sim_lidar_t *l) {
  for (int i = 1; i < l->nseen; i++) { /* insertion sort: once, a few hundred geoms */
    const int g = l->seen[i], root = m->body_rootid[m->geom_bodyid[g]];
    int j = i - 1;
    while (j >= 0 && m->body_rootid[m->geom_bodyid[l->seen[j]]] > root) {
      l->seen[j + 1] = l->seen[j];
      j--;
    }
    l->seen[j + 1] = g;
  }
  l->ngroup = 0;
  for (int i = 0; i < l->nseen; i++) {
    const int root = m->body_rootid[m->geom_bodyid[l->seen[i]]];
    if (l->ngroup == 0 || l->group_root[l->ngroup - 1] != root) {
      l->group_root[l->ngroup] = root;
      l->group_first[l->ngroup++] = i;
    }
  }
  l->group_first[l->ngroup] = l->nseen;
}

/* Each moving group's bounding sphere around its root body: the farthest geom's bounding
 * sphere from the root's origin, plus a margin for the joints inside the group (steering,
 * wheel spin move geoms by far less). The world's geoms are never culled as a group. */
static void lidar_size_groups(const mjModel *m, const mjData *d, sim_lidar_t *l) {
  for (int k = 0; k < l->ngroup; k++) {
    const int root = l->group_root[k];
    double r = root == 0 ? -1.0 : 0.0;
    for (int i = l->group_first[k]; r >= 0 && i < l->group_first[k + 1]; i++) {
      const int g = l->seen[i];
      if (m->geom_rbound[g] <= 0)
        r = -1.0; /* unbounded */
      else
        r = fmax(r, mju_dist3(d->geom_xpos + 3 * g, d->xpos + 3 * root) + m->geom_rbound[g]);
    }
    l->group_radius_m[k] = r >= 0 ? r + LIDAR_GROUP_MARGIN_M : -1.0;
  }
  l->groups_sized = 1;
}

sim_lidar_t *sim_lidar_create(const mjModel *m, const char *base_body,
                              const sim_lidar_config_t *cfg, char *err, size_t err_len) {
  if (!m || !base_body || !cfg) {
    err_set(err, err_len, "null model, body name or config", NULL);
    return NULL;
  }
  if (cfg->num_rays < 1 || cfg->num_rays > 100000 || !(cfg->rate_hz > 0) ||
      !(cfg->range_min_m >= 0) || !(cfg->range_max_m > cfg->range_min_m) ||
      !(cfg->noise_std_m >= 0)) {
    err_set(err, err_len,
            "bad config (need 1..100000 rays, rate_hz > 0, "
            "0 <= range_min_m < range_max_m, noise_std_m >= 0)",
            NULL);
    return NULL;
  }
  int body = mj_name2id(m, mjOBJ_BODY, base_body);
  if (body < 0) {
    err_set(err, err_len, "no such body in the model", base_body);
    return NULL;
  }
  sim_lidar_t *l = calloc(1, sizeof *l);
  if (!l) return NULL;
  l->cfg = *cfg;
  l->base_body = body;
  l->root_body = m->body_rootid[body];
  size_t ng = (size_t)(m->ngeom ? m->ngeom : 1);
  l->seen = calloc(ng, sizeof *l->seen);
  l->group_first = calloc(ng + 1, sizeof *l->group_first);
  l->group_root = calloc(ng, sizeof *l->group_root);
  l->group_radius_m = calloc(ng, sizeof *l->group_radius_m);
  l->cand = calloc(ng, sizeof *l->cand);
  l->cand_lo = calloc(ng, sizeof *l->cand_lo);
  l->cand_n = calloc(ng, sizeof *l->cand_n);
  l->bucket_start = calloc((size_t)cfg->num_rays + 1, sizeof *l->bucket_start);
  size_t n = (size_t)cfg->num_rays;
  l->ray_cos = calloc(n, sizeof(double));
  l->ray_sin = calloc(n, sizeof(double));
  l->ranges_m = calloc(n, sizeof(float));
  l->quality = calloc(n, sizeof(float));
  l->out_ranges_m = calloc(n, sizeof(float));
  l->out_quality = calloc(n, sizeof(float));
  if (!l->seen || !l->group_first || !l->group_root || !l->group_radius_m || !l->cand ||
      !l->cand_lo || !l->cand_n || !l->bucket_start || !l->ranges_m || !l->quality ||
      !l->out_ranges_m || !l->out_quality || !l->ray_cos || !l->ray_sin) {
    sim_lidar_destroy(l);
    err_set(err, err_len, "out of memory", NULL);
    return NULL;
  }
  for (int g = 0; g < m->ngeom; g++) {
    const int grp = m->geom_group[g];
    if (grp < 0 || grp >= mjNGROUP || !cfg->geomgroup[grp]) continue;
    if (m->body_rootid[m->geom_bodyid[g]] == l->root_body) continue; /* the car itself */
    l->seen[l->nseen++] = g;
  }
  const double inc = 2.0 * M_PI / cfg->num_rays;
  for (size_t i = 0; i < n; i++) {
    l->ray_cos[i] = cos((double)i * inc);
    l->ray_sin[i] = sin((double)i * inc);
  }
  lidar_group(m, l);
  l->rng = cfg->seed ? cfg->seed : 0x9E3779B97F4A7C15ull;
  l->last.num_rays = 0;
  l->last.ranges_m = l->out_ranges_m;
  l->last.intensities = l->out_quality;
  return l;
}

void sim_lidar_destroy(sim_lidar_t *l) {
  if (!l) return;
  free(l->cand);
  free(l->cand_lo);
  free(l->cand_n);
  free(l->seen);
  free(l->group_first);
  free(l->group_root);
  free(l->group_radius_m);
  free(l->bucket_start);
  free(l->bucket);
  free(l->ray_cos);
  free(l->ray_sin);
  free(l->ranges_m);
  free(l->quality);
  free(l->out_ranges_m);
  free(l->out_quality);
  free(l);
}

/* Scanner origin in world and its x/y axes (the car body's, as the scanner is fixed). */
static void lidar_frame(const mjData *d, const sim_lidar_t *l, mjtNum origin[3], mjtNum ax[3],
                        mjtNum ay[3]) {
  const mjtNum *xm = d->xmat + 9 * l->base_body;
  const mjtNum *xp = d->xpos + 3 * l->base_body;
  const double *p = l->cfg.mount_pos_m;
  for (int i = 0; i < 3; i++) {
    origin[i] = xp[i] + xm[3 * i + 0] * p[0] + xm[3 * i + 1] * p[1] + xm[3 * i + 2] * p[2];
    ax[i] = xm[3 * i + 0];
    ay[i] = xm[3 * i + 1];
  }
}

/* Culling compares squares, without square roots (with 16 cars their latency was most of the
 * LIDAR's time); this relative slack [1] keeps every geom the exact comparisons would keep,
 * so the candidates are a superset and the ranges, decided by the exact ray tests, the same. */
#define LIDAR_CULL_SLACK (1.0 + 1e-9)

/* Out of range [m]: the nearest point of a circle of squared radius r_sq [m^2] at squared
 * distance dist_sq [m^2] lies beyond the scanner's range (square roots only when it may). */
static int lidar_out_of_range(const sim_lidar_t *l, mjtNum dist_sq, mjtNum r_sq) {
  const double range = l->cfg.range_max_m;
  if (dist_sq <= range * range) return 0;
  return sqrt(dist_sq) - sqrt(r_sq) > range;
}

/* Where visible geom g meets the scan plane through origin (normal nrm, axes ax, ay): 0 not
 * within range; 1 its bounding sphere cuts the plane in a circle of squared radius *r_sq
 * [m^2] around (*px, *py) in the scanner's axes; 2 it may meet every ray (unbounded, or around
 * origin). */
static int lidar_in_plane(const mjModel *m, const mjData *d, const sim_lidar_t *l, int g,
                          const mjtNum origin[3], const mjtNum nrm[3], const mjtNum ax[3],
                          const mjtNum ay[3], mjtNum *px, mjtNum *py, mjtNum *r_sq) {
  const mjtNum rb = m->geom_rbound[g];
  if (rb <= 0) { /* rbound 0 means unbounded (planes) */
    if (m->geom_type[g] != mjGEOM_PLANE) return 2;
    /* A plane is hit from its front only, at h / -(n . ray) from a scanner h in front of it:
     * no ray of the scan plane comes nearer than h / |n projected on the scan plane|, so a
     * plane beyond the range that way (the floor under a level car) is left out. */
    const mjtNum *xm = d->geom_xmat + 9 * g, n[3] = {xm[2], xm[5], xm[8]};
    mjtNum rel[3];
    mju_sub3(rel, origin, d->geom_xpos + 3 * g);
    const mjtNum h = mju_dot3(rel, n), n_ax = mju_dot3(n, ax), n_ay = mju_dot3(n, ay);
    const double range = l->cfg.range_max_m;
    if (h <= 0 || h * h > range * range * (n_ax * n_ax + n_ay * n_ay) * LIDAR_CULL_SLACK) return 0;
    return 2;
  }
  mjtNum rel[3];
  mju_sub3(rel, d->geom_xpos + 3 * g, origin);
  const mjtNum dz = mju_dot3(rel, nrm);
  if (fabs(dz) > rb) return 0;         /* off the scan plane */
  if (m->geom_type[g] == mjGEOM_BOX) { /* the box's half thickness along the normal */
    const mjtNum *xm = d->geom_xmat + 9 * g, *sz = m->geom_size + 3 * g;
    mjtNum hz = 0;
    for (int k = 0; k < 3; k++)
      hz += fabs(xm[k] * nrm[0] + xm[3 + k] * nrm[1] + xm[6 + k] * nrm[2]) * sz[k];
    if (fabs(dz) > hz) return 0;
  }
  *r_sq = rb * rb - dz * dz; /* sphere cut by the scan plane [m^2] */
  *px = mju_dot3(rel, ax);
  *py = mju_dot3(rel, ay);
  const mjtNum dist_sq = *px * *px + *py * *py;
  if (lidar_out_of_range(l, dist_sq, *r_sq)) return 0;
  return dist_sq > *r_sq * LIDAR_CULL_SLACK ? 1 : 2;
}

/* Selects the geoms a ray from origin may hit: visible group, alpha > 0, not the car itself
 * (the same filters as mj_ray plus the root-body exclusion), and culls the rest: a geom must
 * cross the scan plane (exact slab for boxes, bounding sphere otherwise) within range. Each
 * candidate gets the sector of rays that can reach it, from the circle in which its bounding
 * sphere cuts the scan plane; unbounded geoms (planes) and geoms around the origin get all. */
static void lidar_select(const mjModel *m, const mjData *d, sim_lidar_t *l, const mjtNum origin[3],
                         const mjtNum ax[3], const mjtNum ay[3]) {
  mjtNum nrm[3];
  mju_cross(nrm, ax, ay);
  const int n = l->cfg.num_rays;
  const double inc = 2.0 * M_PI / n;
  l->ncand = 0;
  for (int s_i = 0; s_i < l->nseen; s_i++) { /* group and body never change: filtered once */
    const int g = l->seen[s_i];
    if (m->geom_rgba[4 * g + 3] == 0) continue; /* alpha does: late boxes appear */
    int lo = 0, cnt = n;
    mjtNum px, py, r_sq;
    const int where = lidar_in_plane(m, d, l, g, origin, nrm, ax, ay, &px, &py, &r_sq);
    if (where == 0) continue;
    if (where == 1) {
      const double centre = atan2(py, px),
                   half = asin(fmin(1.0, sqrt(r_sq) / sqrt(px * px + py * py)));
      lo = (int)ceil((centre - half) / inc - 1e-9);
      const int hi = (int)floor((centre + half) / inc + 1e-9);
      cnt = hi - lo + 1;
      if (cnt <= 0) continue; /* falls between two rays */
      if (cnt > n) cnt = n;
      lo = ((lo % n) + n) % n;
    }
    l->cand_lo[l->ncand] = lo;
    l->cand_n[l->ncand] = cnt;
    l->cand[l->ncand++] = g;
  }
}

/* Does any of the span rays (unit directions ux, uy in the scanner's axes) pass within
 * sqrt(r_sq) [m] of the point (px, py), which lies ahead of it? */
static int lidar_circle_on_rays(mjtNum px, mjtNum py, mjtNum r_sq, const double *ux,
                                const double *uy, int span, int *hit) {
  int any = 0;
  const mjtNum r_sq_slack = r_sq * LIDAR_CULL_SLACK;
  for (int j = 0; j < span; j++) {
    const mjtNum off = px * uy[j] - py * ux[j]; /* the point's distance from the ray's line */
    hit[j] = px * ux[j] + py * uy[j] > 0 && off * off <= r_sq_slack;
    any |= hit[j];
  }
  return any;
}

/* May a ray of the span reach group k at all? Its sphere against the scan plane and rays. */
static int lidar_group_reachable(const mjData *d, const sim_lidar_t *l, int k,
                                 const mjtNum origin[3], const mjtNum nrm[3], const mjtNum ax[3],
                                 const mjtNum ay[3], const double *ux, const double *uy, int span) {
  const double r = l->group_radius_m[k];
  if (r < 0) return 1;
  mjtNum rel[3];
  mju_sub3(rel, d->xpos + 3 * l->group_root[k], origin);
  const mjtNum dz = mju_dot3(rel, nrm);
  if (fabs(dz) > r) return 0;
  const mjtNum r_sq = r * r - dz * dz, px = mju_dot3(rel, ax), py = mju_dot3(rel, ay);
  const mjtNum dist_sq = px * px + py * py;
  if (lidar_out_of_range(l, dist_sq, r_sq)) return 0;
  int hit[LIDAR_FEW_RAYS];
  return dist_sq <= r_sq * LIDAR_CULL_SLACK ||
         lidar_circle_on_rays(px, py, r_sq, ux, uy, span, hit);
}

/* The spinning update casts a few rays per step: for those, lidar_select's sectors (an atan2
 * and an asin per geom) and the bucket sort cost more than testing each ray against each
 * geom's circle directly, and other cars are skipped whole when their sphere misses the
 * rays. Fills cand and, for ray from + j, the list bucket[j * nseen ..] of few_n[j]
 * candidates. Returns -1 on no memory. */
static int lidar_select_few(const mjModel *m, const mjData *d, sim_lidar_t *l,
                            const mjtNum origin[3], const mjtNum ax[3], const mjtNum ay[3],
                            int from, int to) {
  if (!l->groups_sized) lidar_size_groups(m, d, l);
  mjtNum nrm[3];
  mju_cross(nrm, ax, ay);
  const int span = to - from;
  const double *ux = l->ray_cos + from, *uy = l->ray_sin + from; /* rays from.. are contiguous */
  for (int j = 0; j < span; j++) l->few_n[j] = 0;
  const size_t need = (size_t)span * (size_t)(l->nseen > 0 ? l->nseen : 1);
  if (need > l->bucket_cap) {
    int *b = realloc(l->bucket, (need + 64) * sizeof *b);
    if (!b) return -1;
    l->bucket = b;
    l->bucket_cap = need + 64;
  }
  l->ncand = 0;
  for (int k = 0; k < l->ngroup; k++) {
    if (!lidar_group_reachable(d, l, k, origin, nrm, ax, ay, ux, uy, span)) continue;
    for (int s_i = l->group_first[k]; s_i < l->group_first[k + 1]; s_i++) {
      const int g = l->seen[s_i];
      if (m->geom_rgba[4 * g + 3] == 0) continue; /* alpha changes: late boxes appear */
      mjtNum px, py, r_sq;
      const int where = lidar_in_plane(m, d, l, g, origin, nrm, ax, ay, &px, &py, &r_sq);
      if (where == 0) continue;
      int hit[LIDAR_FEW_RAYS];
      if (where == 2)
        for (int j = 0; j < span; j++) hit[j] = 1;
      else if (!lidar_circle_on_rays(px, py, r_sq, ux, uy, span, hit))
        continue;
      for (int j = 0; j < span; j++)
        if (hit[j]) l->bucket[j * l->nseen + l->few_n[j]++] = l->ncand;
      l->cand[l->ncand++] = g;
    }
  }
  return 0;
}

/* Sorts the candidates into per-ray buckets for rays [from, to), so each ray tests only the
 * geoms whose sector holds it. Returns -1 on no memory. */
static int lidar_bucket(sim_lidar_t *l, int from, int to) {
  const int n = l->cfg.num_rays, span = to - from;
  int *start = l->bucket_start;
  memset(start, 0, (size_t)(span + 1) * sizeof *start);
  for (int pass = 0; pass < 2; pass++) {
    for (int k = 0; k < l->ncand; k++) {
      const int lo = l->cand_lo[k], cnt = l->cand_n[k];
      if (span <= 16) { /* a few rays (the spinning update): test each ray's membership */
        for (int i = from; i < to; i++) {
          int off = i - lo;
          if (off < 0) off += n;
          if (off >= cnt) continue;
          if (pass == 0)
            start[i - from + 1]++;
          else
            l->bucket[start[i - from]++] = k;
        }
      } else { /* many rays: walk the candidate's sector */
        for (int j = 0; j < cnt; j++) {
          int i = lo + j;
          if (i >= n) i -= n;
          if (i < from || i >= to) continue;
          if (pass == 0)
            start[i - from + 1]++;
          else
            l->bucket[start[i - from]++] = k;
        }
      }
    }
    if (pass == 0) {
      for (int j = 0; j < span; j++) start[j + 1] += start[j];
      size_t need = (size_t)start[span];
      if (need > l->bucket_cap) {
        int *b = realloc(l->bucket, (need + 64) * sizeof *b);
        if (!b) return -1;
        l->bucket = b;
        l->bucket_cap = need + 64;
      }
    }
  }
  /* the fill pass advanced each start to the next bucket's start: shift back */
  for (int j = span; j > 0; j--) start[j] = start[j - 1];
  start[0] = 0;
  return 0;
}

/* Nearest hit along unit vec from origin over candidates list[0..count), or -1. */
static mjtNum lidar_cast(const mjModel *m, const mjData *d, const sim_lidar_t *l,
                         const mjtNum origin[3], const mjtNum vec[3], const int *list, int count) {
  mjtNum best = -1;
  for (int k = 0; k < count; k++) {
    int g = l->cand[list ? list[k] : k];
    mjtNum rb = m->geom_rbound[g];
    if (rb > 0) { /* cheap sphere test first: skip geoms the ray passes by or lies behind */
      mjtNum rel[3];
      mju_sub3(rel, d->geom_xpos + 3 * g, origin);
      mjtNum along = mju_dot3(rel, vec);
      mjtNum dist2 = mju_dot3(rel, rel) - along * along;
      if (dist2 > rb * rb) continue;
      if (along + rb < 0) continue;
      if (best >= 0 && along - rb > best) continue;
    }
    mjtNum x;
    int type = m->geom_type[g];
    if (type == mjGEOM_MESH) {
      x = mj_rayMesh(m, d, g, origin, vec);
    } else if (type == mjGEOM_HFIELD) {
      x = mj_rayHfield(m, d, g, origin, vec);
    } else {
      x = mju_rayGeom(d->geom_xpos + 3 * g, d->geom_xmat + 9 * g, m->geom_size + 3 * g, origin, vec,
                      type);
    }
    if (x >= 0 && (best < 0 || x < best)) best = x;
  }
  return best;
}

static double lidar_range(const sim_lidar_t *l, mjtNum x) {
  if (x < 0 || x < l->cfg.range_min_m || x > l->cfg.range_max_m) return INFINITY;
  return x;
}

/* The unit ray at cos c, sin s of its angle [1] in the scan plane spanned by ax, ay. */
static void ray_dir(const mjtNum ax[3], const mjtNum ay[3], double c, double s, mjtNum vec[3]) {
  for (int i = 0; i < 3; i++) vec[i] = c * ax[i] + s * ay[i];
  mju_normalize3(vec);
}

double sim_lidar_ray(const mjModel *m, const mjData *d, const sim_lidar_t *l, double angle_rad) {
  mjtNum o[3], ax[3], ay[3], vec[3];
  lidar_frame(d, l, o, ax, ay);
  lidar_select(m, d, (sim_lidar_t *)l, o, ax, ay);
  ray_dir(ax, ay, cos(angle_rad), sin(angle_rad), vec);
  return lidar_range(l, lidar_cast(m, d, l, o, vec, NULL, l->ncand));
}

/* Standard normal sample from the lidar's own generator (xorshift64* + Box-Muller). */
static double lidar_gauss(sim_lidar_t *l) {
  double u[2];
  for (int i = 0; i < 2; i++) {
    l->rng ^= l->rng >> 12;
    l->rng ^= l->rng << 25;
    l->rng ^= l->rng >> 27;
    uint64_t r = l->rng * 0x2545F4914F6CDD1Dull;
    u[i] = ((double)(r >> 11) + 0.5) / 9007199254740992.0; /* (0, 1) */
  }
  return sqrt(-2.0 * log(u[0])) * cos(2.0 * M_PI * u[1]);
}

/* Casts rays [from, to) of the current revolution into l->ranges_m. */
static void lidar_cast_rays(const mjModel *m, const mjData *d, sim_lidar_t *l, int from, int to) {
  if (from >= to) return;
  mjtNum o[3], ax[3], ay[3], vec[3];
  lidar_frame(d, l, o, ax, ay);
  int bucketed, few = 0;
  if (to - from <= LIDAR_FEW_RAYS) {
    few = bucketed = lidar_select_few(m, d, l, o, ax, ay, from, to) == 0;
    if (!bucketed) lidar_select(m, d, l, o, ax, ay); /* no memory: every candidate per ray */
  } else {
    lidar_select(m, d, l, o, ax, ay);
    bucketed = lidar_bucket(l, from, to) == 0;
  }
  for (int i = from; i < to; i++) {
    ray_dir(ax, ay, l->ray_cos[i], l->ray_sin[i], vec);
    const int j = i - from;
    mjtNum x = few        ? lidar_cast(m, d, l, o, vec, l->bucket + j * l->nseen, l->few_n[j])
               : bucketed ? lidar_cast(m, d, l, o, vec, l->bucket + l->bucket_start[j],
                                       l->bucket_start[j + 1] - l->bucket_start[j])
                          : lidar_cast(m, d, l, o, vec, NULL, l->ncand);
    double r = lidar_range(l, x);
    if (isfinite(r) && l->cfg.noise_std_m > 0) {
      r += l->cfg.noise_std_m * lidar_gauss(l);
      if (r < l->cfg.range_min_m || r > l->cfg.range_max_m) r = INFINITY;
    }
    l->ranges_m[i] = (float)r;
    l->quality[i] = isfinite(r) ? 47.0f : 0.0f;
  }
}

/* Casts the rays of sweep steps [from, to) (clockwise: see sim_lidar_sweep_ray): step 0 is
 * ray 0, steps 1.. are rays num_rays-1, num_rays-2, ..., a contiguous range of ray indices. */
static void lidar_cast_sweep(const mjModel *m, const mjData *d, sim_lidar_t *l, int from, int to) {
  const int n = l->cfg.num_rays;
  if (from >= to) return;
  if (from == 0) {
    lidar_cast_rays(m, d, l, 0, 1);
    from = 1;
  }
  if (from < to) lidar_cast_rays(m, d, l, n - to + 1, n - from + 1);
}

static void lidar_publish(sim_lidar_t *l, int64_t start_us) {
  size_t n = (size_t)l->cfg.num_rays;
  memcpy(l->out_ranges_m, l->ranges_m, n * sizeof(float));
  memcpy(l->out_quality, l->quality, n * sizeof(float));
  sim_lidar_scan_t *s = &l->last;
  s->utime = start_us;
  s->num_rays = l->cfg.num_rays;
  s->angle_min_rad = 0.0f;
  s->angle_increment_rad = (float)(2.0 * M_PI / l->cfg.num_rays);
  s->scan_time_s = (float)(1.0 / l->cfg.rate_hz);
  s->time_increment_s = s->scan_time_s / (float)l->cfg.num_rays;
  s->range_min_m = (float)l->cfg.range_min_m;
  s->range_max_m = (float)l->cfg.range_max_m;
}

void sim_lidar_scan_now(const mjModel *m, mjData *d, sim_lidar_t *l, int64_t now_us) {
  lidar_cast_rays(m, d, l, 0, l->cfg.num_rays);
  lidar_publish(l, now_us);
}

int sim_lidar_update(const mjModel *m, mjData *d, sim_lidar_t *l, int64_t now_us) {
  /* first call, or the sim clock went back (a reset): start a fresh revolution now */
  if (!l->started || now_us < l->rev_start_us) {
    l->started = 1;
    l->rev_start_us = now_us;
    l->next_ray = 0;
  }
  double period_us = 1e6 / l->cfg.rate_hz;
  /* sweep step k is due at rev_start + k * period / num_rays */
  double phase = (double)(now_us - l->rev_start_us) / period_us;
  int due = (int)floor(phase * l->cfg.num_rays) + 1;
  if (due > l->cfg.num_rays) due = l->cfg.num_rays;
  lidar_cast_sweep(m, d, l, l->next_ray, due);
  l->cast_from = l->next_ray;
  l->cast_to = due > l->next_ray ? due : l->next_ray;
  if (due > l->next_ray) l->next_ray = due;
  if (phase >= 1.0) {
    lidar_publish(l, l->rev_start_us);
    l->rev_start_us += (int64_t)llround(period_us);
    l->next_ray = 0;
    /* a long pause (e.g. the sim was paused) restarts the head instead of replaying scans */
    if (now_us - l->rev_start_us >= (int64_t)period_us) l->rev_start_us = now_us;
    return 1;
  }
  return 0;
}

const sim_lidar_scan_t *sim_lidar_last_scan(const sim_lidar_t *l) {
  return &l->last;
}

void sim_lidar_last_cast(const sim_lidar_t *l, int *from, int *to, int *num_rays,
                         const float **ranges_m, const float **quality) {
  *from = l->cast_from;
  *to = l->cast_to;
  *num_rays = l->cfg.num_rays;
  *ranges_m = l->ranges_m;
  *quality = l->quality;
}
