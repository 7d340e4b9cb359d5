/* Scenario options of autodrive-sim: the start pose of car 1 (--start X,Y,YAW_DEG) and boxes
 * that appear during the run (--late-box X,Y,T[,SX,SY[,R]]). Parsing only; where they go in the
 * world and whether they fit the map is the sim's business (sim.h, clearance.h). */
#ifndef SIM_SCENARIO_H
#define SIM_SCENARIO_H

#include <stddef.h>

#ifdef __cplusplus
extern "C" {
#endif

#define SCN_MAX_LATE_BOXES 4     /* --late-box options */
#define SCN_MAX_MAP_LATE_BOXES 8 /* the map's late_obstacles (custom numerics late_<name>) */
#define SCN_LATE_BOX_HALF_DEFAULT_M 0.06 /* default half size in x and y [m] */
#define SCN_LATE_BOX_HEIGHT_M 0.2    /* full height [m]: above the LIDAR's mount (lidar_pos_m) */
#define SCN_LATE_BOX_HALF_MIN_M 0.01 /* half size limits [m] */
#define SCN_LATE_BOX_HALF_MAX_M 1.0
#define SCN_COORD_MAX_M 1000.0 /* |x|, |y| bound before the map check [m] */

typedef struct scn_pose {
  double x_m, y_m; /* base_link (rear-axle centre) in the world [m] */
  double yaw_deg;  /* heading, counter-clockwise from world +x [deg] */
} scn_pose_t;

typedef struct scn_late_box {
  double x_m, y_m;           /* centre on the floor [m] */
  double t_s;                /* sim time at which it appears [s] */
  double half_x_m, half_y_m; /* half sizes along world x and y [m] */
  double near_m;             /* > 0: and not before NIGEL1's base_link is this close [m] */
  double yaw_rad;            /* about z (the map's late obstacles; 0 for --late-box) [rad] */
  double half_z_m;           /* half height [m]; 0: SCN_LATE_BOX_HEIGHT_M / 2 */
  char name[48];             /* the map's obstacle name; "" for a --late-box */
  double stay_s;             /* > 0: leaves again this long after it appeared [s]; 0: stays */
} scn_late_box_t;

/* Half height of a late box [m]. */
static inline double scn_late_box_half_z(const scn_late_box_t *b) {
  return b->half_z_m > 0 ? b->half_z_m : 0.5 * SCN_LATE_BOX_HEIGHT_M;
}

/* Parse "X,Y,YAW_DEG". Returns 0, or -1 with a message naming --start and text in err. */
int scn_parse_start(const char *text, scn_pose_t *out, char *err, size_t err_sz);
/* Parse "X,Y,T", "X,Y,T,SX,SY" or "X,Y,T,SX,SY,R". Returns 0, or -1 with a message naming
 * --late-box and text. */
int scn_parse_late_box(const char *text, scn_late_box_t *out, char *err, size_t err_sz);

#ifdef __cplusplus
}
#endif
#endif
