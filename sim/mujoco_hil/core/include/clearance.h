/* Does a footprint fit on the map? A simple, conservative check of an upright prism (an
 * oriented rectangle in x-y between two heights: a car, a box) against the map's static
 * geoms, used to validate --start and --late-box before the run:
 *   - floor: an upward plane with a drawn size bounds the map; every corner must lie on one;
 *   - walls: vertical planes are half-spaces in MuJoCo; every corner must be in front;
 *   - obstacles: any other static geom (world body or welded to it; not mocap) that the given
 *     collision bits would touch and that reaches into the prism's height band must not
 *     overlap it in x-y (boxes standing upright exactly, other shapes by their bounding box).
 * Not exact for tilted shapes (their bounding box is larger): it may refuse a pose that only
 * grazes one, never accept an overlap. */
#ifndef SIM_CLEARANCE_H
#define SIM_CLEARANCE_H

#include <stddef.h>

#include <mujoco/mujoco.h>

#ifdef __cplusplus
extern "C" {
#endif

typedef struct clearance_prism {
  double centre_m[2];    /* x, y in the world [m] */
  double yaw_rad;        /* direction of its own x axis [rad] */
  double half_m[2];      /* half lengths along its own x and y [m] */
  double z_lo_m, z_hi_m; /* height band in the world [m] */
} clearance_prism_t;

/* 1 when the two prisms overlap (touching faces do not). */
int clearance_prisms_overlap(const clearance_prism_t *a, const clearance_prism_t *b);

/* 0 when p fits (see above), or -1 with what is in the way in err ("overlaps geom 'box_a'",
 * "is outside the floor 'floor' ...", "is behind the wall plane 'wall_n'"). d needs the
 * kinematics of the model (mj_forward or mj_kinematics). */
int clearance_check_on_map(const mjModel *m, const mjData *d, const clearance_prism_t *p,
                           int contype, int conaffinity, char *err, size_t err_sz);

#ifdef __cplusplus
}
#endif
#endif
