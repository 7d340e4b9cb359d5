/* Footprint checks against the map's static geoms (see clearance.h). */
#include "clearance.h"

#include <math.h>
#include <stdio.h>

/* |cos| between a geom's z axis and the world's above which it is upright [-] */
#define CLEARANCE_UPRIGHT_COS 0.999
#define CLEARANCE_VERTICAL_NZ 0.1 /* |normal z| below this: a wall plane [-] */
#define CLEARANCE_EPS_M 1e-9      /* overlaps smaller than this are touching [m] */

/* Projection radius of prism p on the unit direction n [m]. */
static double clearance_radius(const clearance_prism_t *p, const double n[2]) {
  const double c = cos(p->yaw_rad), s = sin(p->yaw_rad);
  return p->half_m[0] * fabs(c * n[0] + s * n[1]) + p->half_m[1] * fabs(-s * n[0] + c * n[1]);
}

int clearance_prisms_overlap(const clearance_prism_t *a, const clearance_prism_t *b) {
  if (a->z_hi_m <= b->z_lo_m + CLEARANCE_EPS_M || b->z_hi_m <= a->z_lo_m + CLEARANCE_EPS_M)
    return 0;
  const double d[2] = {b->centre_m[0] - a->centre_m[0], b->centre_m[1] - a->centre_m[1]};
  const double yaw[2] = {a->yaw_rad, b->yaw_rad};
  for (int k = 0; k < 4; k++) { /* separating axes: both rectangles' x and y */
    const double t = yaw[k / 2] + (k % 2) * 0.5 * M_PI;
    const double n[2] = {cos(t), sin(t)};
    if (fabs(d[0] * n[0] + d[1] * n[1]) >=
        clearance_radius(a, n) + clearance_radius(b, n) - CLEARANCE_EPS_M)
      return 0;
  }
  return 1;
}

static void clearance_corners(const clearance_prism_t *p, double out[4][2]) {
  const double c = cos(p->yaw_rad), s = sin(p->yaw_rad);
  for (int k = 0; k < 4; k++) {
    const double a = (k & 1 ? 1 : -1) * p->half_m[0], b = (k & 2 ? 1 : -1) * p->half_m[1];
    out[k][0] = p->centre_m[0] + c * a - s * b;
    out[k][1] = p->centre_m[1] + s * a + c * b;
  }
}

static void clearance_name(const mjModel *m, int g, char *out, size_t sz) {
  const char *n = mj_id2name(m, mjOBJ_GEOM, g);
  if (n && *n)
    snprintf(out, sz, "'%s'", n);
  else
    snprintf(out, sz, "#%d (unnamed)", g);
}

/* An upright prism bounding static geom g (exact for upright boxes). */
static void clearance_geom_prism(const mjModel *m, const mjData *d, int g, clearance_prism_t *p) {
  const mjtNum *R = d->geom_xmat + 9 * g, *pos = d->geom_xpos + 3 * g, *sz = m->geom_size + 3 * g;
  double ext[3];
  p->yaw_rad = 0.0;
  switch (m->geom_type[g]) {
    case mjGEOM_BOX:
      if (fabs(R[8]) > CLEARANCE_UPRIGHT_COS) { /* upright: its own x-y rectangle */
        p->yaw_rad = atan2(R[3], R[0]);
        ext[0] = sz[0], ext[1] = sz[1], ext[2] = sz[2];
      } else {
        for (int k = 0; k < 3; k++)
          ext[k] = fabs(R[3 * k]) * sz[0] + fabs(R[3 * k + 1]) * sz[1] + fabs(R[3 * k + 2]) * sz[2];
      }
      break;
    case mjGEOM_SPHERE: ext[0] = ext[1] = ext[2] = sz[0]; break;
    case mjGEOM_CYLINDER:
    case mjGEOM_CAPSULE:
      for (int k = 0; k < 3; k++) { /* along the axis: half length; across: the radius */
        const double a = fabs(R[3 * k + 2]);
        ext[k] = a * sz[1] +
                 sz[0] * (m->geom_type[g] == mjGEOM_CAPSULE ? 1.0 : sqrt(fmax(0.0, 1.0 - a * a)));
      }
      break;
    case mjGEOM_ELLIPSOID:
      for (int k = 0; k < 3; k++)
        ext[k] = sqrt(pow(R[3 * k] * sz[0], 2) + pow(R[3 * k + 1] * sz[1], 2) +
                      pow(R[3 * k + 2] * sz[2], 2));
      break;
    default: /* meshes, height fields: the bounding sphere */
      ext[0] = ext[1] = ext[2] = m->geom_rbound[g];
  }
  p->centre_m[0] = pos[0];
  p->centre_m[1] = pos[1];
  p->half_m[0] = ext[0];
  p->half_m[1] = ext[1];
  p->z_lo_m = pos[2] - ext[2];
  p->z_hi_m = pos[2] + ext[2];
}

/* Is point c on the drawn area of upward plane g? */
static int clearance_on_plane(const mjModel *m, const mjData *d, int g, const double c[2]) {
  const mjtNum *R = d->geom_xmat + 9 * g, *pos = d->geom_xpos + 3 * g, *sz = m->geom_size + 3 * g;
  const double r[2] = {c[0] - pos[0], c[1] - pos[1]};
  const double lx = r[0] * R[0] + r[1] * R[3], ly = r[0] * R[1] + r[1] * R[4];
  return fabs(lx) <= sz[0] + CLEARANCE_EPS_M && fabs(ly) <= sz[1] + CLEARANCE_EPS_M;
}

int clearance_check_on_map(const mjModel *m, const mjData *d, const clearance_prism_t *p,
                           int contype, int conaffinity, char *err, size_t err_sz) {
  double corner[4][2];
  clearance_corners(p, corner);
  char name[96];
  int floors = 0, first_floor = -1, corner_on[4] = {0, 0, 0, 0};
  for (int g = 0; g < m->ngeom; g++) {
    const int b = m->geom_bodyid[g];
    if (m->body_weldid[b] != 0 || m->body_mocapid[b] >= 0) continue; /* not static */
    const mjtNum *R = d->geom_xmat + 9 * g, *pos = d->geom_xpos + 3 * g;
    const int touches = (contype & m->geom_conaffinity[g]) || (m->geom_contype[g] & conaffinity);
    if (m->geom_type[g] == mjGEOM_PLANE) {
      const double n[3] = {R[2], R[5], R[8]}; /* plane normal: its z axis */
      if (n[2] > CLEARANCE_UPRIGHT_COS && m->geom_size[3 * g] > 0 && m->geom_size[3 * g + 1] > 0) {
        floors++;
        if (first_floor < 0) first_floor = g;
        for (int k = 0; k < 4; k++) corner_on[k] |= clearance_on_plane(m, d, g, corner[k]);
      } else if (fabs(n[2]) < CLEARANCE_VERTICAL_NZ && touches) {
        for (int k = 0; k < 4; k++)
          if ((corner[k][0] - pos[0]) * n[0] + (corner[k][1] - pos[1]) * n[1] < -CLEARANCE_EPS_M) {
            clearance_name(m, g, name, sizeof name);
            snprintf(err, err_sz, "is behind the wall plane %s (corner at %.3f, %.3f m)", name,
                     corner[k][0], corner[k][1]);
            return -1;
          }
      }
      continue;
    }
    if (!touches) continue;
    clearance_prism_t q;
    clearance_geom_prism(m, d, g, &q);
    if (clearance_prisms_overlap(p, &q)) {
      clearance_name(m, g, name, sizeof name);
      snprintf(err, err_sz, "overlaps geom %s (around %.3f, %.3f m)", name, q.centre_m[0],
               q.centre_m[1]);
      return -1;
    }
  }
  for (int k = 0; floors > 0 && k < 4; k++)
    if (!corner_on[k]) {
      clearance_name(m, first_floor, name, sizeof name);
      const mjtNum *sz = m->geom_size + 3 * first_floor, *pos = d->geom_xpos + 3 * first_floor;
      snprintf(err, err_sz,
               "is outside the floor %s (corner at %.3f, %.3f m; the floor spans %.3g x %.3g m "
               "around %.3g, %.3g m)",
               name, corner[k][0], corner[k][1], 2 * sz[0], 2 * sz[1], pos[0], pos[1]);
      return -1;
    }
  return 0;
}
