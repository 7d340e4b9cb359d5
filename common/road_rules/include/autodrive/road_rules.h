/* The one "next light and sign ahead" of the project (the Smart City Manager, its advisory
 * stand-in and the city driver; Python through cffi). From a map's lanes (the sidecar JSON's
 * sampled centre lines, in driving order), its lights (each at its stop line), its signs and its
 * named routes, it
 *  - joins the lanes (a lane whose start lies within ROAD_JOIN_M of another's end, heading
 *    within ROAD_JOIN_RAD, follows it);
 *  - places each light and sign on lanes by arc length: a light at its stop line on every lane
 *    passing within ROAD_JOIN_M of the line's centre in its lane's direction (the lanes of one
 *    approach share their start: its light governs them all); a sign beside a lane at its
 *    projection on that lane, and likewise on the lanes passing there; a sign at a pose on the
 *    nearest lane (within ROAD_POSE_SIGN_REACH_M) heading against its face, and that lane's
 *    twins;
 *  - places a car on a lane (nearest centre line within the lane's half width + 5 cm and 60 deg
 *    of its heading; its route's lanes first, then its last lane and that lane's successors);
 *  - walks ahead from (lane, s, route): the route's next lane, else the one successor (at a fork
 *    without a route the walk stops: what lies beyond depends on the turn), to the next light
 *    and the next sign, with their distances along the lanes [m] from the car's base_link;
 *  - says the speed limit in force: the last speed-limit sign behind the car on its road (a
 *    limit holds from its sign to the next junction, a lane end where lanes fork or merge).
 * Plain C11, libm only, no I/O: unit-testable, built for the car (aarch64) too. */
#ifndef AUTODRIVE_ROAD_RULES_H
#define AUTODRIVE_ROAD_RULES_H

#include <stddef.h>

#ifdef __cplusplus
extern "C" {
#endif

#define ROAD_JOIN_M 0.03   /* lane ends this close join; an anchor this close is on a lane [m] */
#define ROAD_JOIN_RAD 0.35 /* and their headings differ by less than this [rad] */
#define ROAD_MAX_HEADING_RAD \
  1.0471975511965976               /* a car further off a lane's heading is not on it (60 deg) */
#define ROAD_LANE_MARGIN_M 0.05    /* a car this far beyond a lane's half width is not on it [m] */
#define ROAD_POSE_SIGN_REACH_M 0.6 /* a sign at a pose belongs to a lane this close [m] */
#define ROAD_HORIZON_M 12.0        /* how far ahead a walk looks by default [m] */

/* CFFI-BEGIN */
typedef struct road_point {
  double x_m, y_m, heading_rad;
} road_point_t;

typedef struct road_lane {
  const road_point_t *points; /* centre line in driving order, >= 2 points (copied) */
  int n_points;
  double half_width_m;
} road_lane_t;

typedef struct road_light {
  int id;
  int lane;        /* index of its stop line's lane */
  double x_m, y_m; /* its stop line's centre */
} road_light_t;

typedef struct road_sign {
  int id;
  int lane;                 /* index of the lane it stands beside; -1: a sign at a pose */
  double x_m, y_m, yaw_rad; /* where it stands, the way its face points */
  double speed_limit_m_s;   /* > 0: a speed-limit sign's limit; else none */
} road_sign_t;

typedef struct road_route {
  const int *lanes; /* lane indices in driving order (copied) */
  int n_lanes;
  int loop; /* 1: the first lane follows the last */
} road_route_t;

#define ROAD_LIGHT 0
#define ROAD_SIGN 1

/* A light or a sign on a lane, s_m along it. */
typedef struct road_anchor {
  int kind;               /* ROAD_LIGHT or ROAD_SIGN */
  int id;                 /* the light's or the sign's id */
  int index;              /* its index in the lights or the signs given */
  double s_m;             /* arc length along the lane [m] */
  double speed_limit_m_s; /* a speed-limit sign's, else -1 */
} road_anchor_t;

/* Where a car is: lane index, arc length along it [m], distance to its centre line [m]. */
typedef struct road_place {
  int lane;
  double s_m;
  double offset_m;
} road_place_t;

/* What lies ahead: ids -1 and distances < 0 when none. */
typedef struct road_ahead {
  int light_id;
  int light_index;
  double stop_line_distance_m;
  int sign_id;
  int sign_index;
  double sign_distance_m;
  double speed_limit_m_s; /* in force at the car, < 0 when none */
} road_ahead_t;

typedef struct road_net road_net_t;

/* Builds the network (everything given is copied). NULL, with a message naming the element,
 * for bad input (a lane with < 2 points, an index out of range, no memory). Free with
 * road_net_destroy. */
road_net_t *road_net_create(const road_lane_t *lanes, int n_lanes, const road_light_t *lights,
                            int n_lights, const road_sign_t *signs, int n_signs,
                            const road_route_t *routes, int n_routes, char *err, size_t err_sz);
void road_net_destroy(road_net_t *net);

int road_lane_count(const road_net_t *net);
/* Arc length of a lane's centre line [m]. */
double road_lane_length_m(const road_net_t *net, int lane);
/* The lanes that follow a lane (count; *out borrowed from net). */
int road_lane_successors(const road_net_t *net, int lane, const int **out);
/* The lights and signs on a lane, in order of s (count; *out borrowed from net). */
int road_lane_anchors(const road_net_t *net, int lane, const road_anchor_t **out);

/* Places a car at (x, y, yaw) [m, m, rad]. route: index of its named route or -1; last_lane:
 * the lane it was on or -1. Returns 1 and fills *out, or 0 when it is on no lane. */
int road_place_car(const road_net_t *net, double x_m, double y_m, double yaw_rad, int route,
                   int last_lane, road_place_t *out);
/* The lane after lane on route (-1: none), else the lane's one successor, else -1. */
int road_next_lane(const road_net_t *net, int lane, int route);
/* The next light and sign within horizon_m [m] ahead of place, walking along route (or -1). */
road_ahead_t road_walk_ahead(const road_net_t *net, const road_place_t *place, int route,
                             double horizon_m);
/* The speed limit in force at place [m/s], < 0 when none. */
double road_speed_limit_m_s(const road_net_t *net, const road_place_t *place);
/* CFFI-END */

#ifdef __cplusplus
}
#endif
#endif
