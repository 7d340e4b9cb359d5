/* The one "next light and sign ahead": see <autodrive/road_rules.h>. */
#include <autodrive/road_rules.h>

#include <autodrive/angle_wrap.h>

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef struct lane_geom {
  road_point_t *pts;
  double *s_m; /* arc length at each point [m] */
  int n;
  double half_width_m;
  double min_x_m, min_y_m, max_x_m, max_y_m; /* bounding box of the centre line */
  int *succ, n_succ;
  int *pred, n_pred;
  road_anchor_t *anchors;
  int n_anchors;
} lane_geom_t;

typedef struct route_geom {
  int *lanes;
  int n;
  int loop;
} route_geom_t;

struct road_net {
  lane_geom_t *lanes;
  int n_lanes;
  route_geom_t *routes;
  int n_routes;
};

/* The nearest point of a lane's centre line to (x, y): its arc length, distance and heading
 * (interpolated between the segment's ends). */
typedef struct projection {
  double s_m, dist_m, heading_rad;
} projection_t;

static projection_t project_segment(const lane_geom_t *g, int i, double x, double y) {
  const road_point_t *a = &g->pts[i], *b = &g->pts[i + 1];
  const double dx = b->x_m - a->x_m, dy = b->y_m - a->y_m, len2 = dx * dx + dy * dy;
  double u = len2 > 0 ? ((x - a->x_m) * dx + (y - a->y_m) * dy) / len2 : 0.0;
  u = u < 0 ? 0 : (u > 1 ? 1 : u);
  projection_t p;
  p.s_m = g->s_m[i] + u * (g->s_m[i + 1] - g->s_m[i]);
  p.dist_m = hypot(a->x_m + u * dx - x, a->y_m + u * dy - y);
  p.heading_rad = autodrive_angle_wrap_rad(
      a->heading_rad + u * autodrive_angle_wrap_rad(b->heading_rad - a->heading_rad));
  return p;
}

/* Nearest over the whole lane; with yaw_rad finite, only where its heading is within
 * max_dyaw_rad of yaw_rad (dist_m INFINITY when nowhere). */
static projection_t project_lane(const lane_geom_t *g, double x, double y, double yaw_rad,
                                 double max_dyaw_rad) {
  projection_t best = {0.0, INFINITY, 0.0};
  for (int i = 0; i + 1 < g->n; ++i) {
    const projection_t p = project_segment(g, i, x, y);
    if (isfinite(yaw_rad) &&
        fabs(autodrive_angle_wrap_rad(p.heading_rad - yaw_rad)) >= max_dyaw_rad)
      continue;
    if (p.dist_m < best.dist_m) best = p;
  }
  return best;
}

static void point_at(const lane_geom_t *g, double s_m, double *x, double *y) {
  int i = 0;
  while (i + 2 < g->n && g->s_m[i + 1] < s_m) ++i;
  const double ds = g->s_m[i + 1] - g->s_m[i];
  double u = ds > 0 ? (s_m - g->s_m[i]) / ds : 0.0;
  u = u < 0 ? 0 : (u > 1 ? 1 : u);
  *x = g->pts[i].x_m + u * (g->pts[i + 1].x_m - g->pts[i].x_m);
  *y = g->pts[i].y_m + u * (g->pts[i + 1].y_m - g->pts[i].y_m);
}

static void fail(char *err, size_t err_sz, const char *fmt, ...) {
  if (!err || err_sz == 0) return;
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(err, err_sz, fmt, ap);
  va_end(ap);
}

static int append_int(int **v, int *n, int x) {
  int *grown = realloc(*v, (size_t)(*n + 1) * sizeof **v);
  if (!grown) return -1;
  grown[(*n)++] = x;
  *v = grown;
  return 0;
}

static int append_anchor(lane_geom_t *g, road_anchor_t a) {
  road_anchor_t *grown = realloc(g->anchors, (size_t)(g->n_anchors + 1) * sizeof *grown);
  if (!grown) return -1;
  /* kept in order of s; an equal s goes after those already there */
  int k = g->n_anchors;
  while (k > 0 && grown[k - 1].s_m > a.s_m) {
    grown[k] = grown[k - 1];
    --k;
  }
  grown[k] = a;
  g->anchors = grown;
  ++g->n_anchors;
  return 0;
}

static int copy_lane(lane_geom_t *g, const road_lane_t *in) {
  g->n = in->n_points;
  g->half_width_m = in->half_width_m;
  g->pts = malloc((size_t)g->n * sizeof *g->pts);
  g->s_m = malloc((size_t)g->n * sizeof *g->s_m);
  if (!g->pts || !g->s_m) return -1;
  memcpy(g->pts, in->points, (size_t)g->n * sizeof *g->pts);
  g->s_m[0] = 0.0;
  g->min_x_m = g->max_x_m = g->pts[0].x_m;
  g->min_y_m = g->max_y_m = g->pts[0].y_m;
  for (int i = 1; i < g->n; ++i) {
    g->min_x_m = fmin(g->min_x_m, g->pts[i].x_m);
    g->max_x_m = fmax(g->max_x_m, g->pts[i].x_m);
    g->min_y_m = fmin(g->min_y_m, g->pts[i].y_m);
    g->max_y_m = fmax(g->max_y_m, g->pts[i].y_m);
  }
  for (int i = 1; i < g->n; ++i)
    g->s_m[i] =
        g->s_m[i - 1] + hypot(g->pts[i].x_m - g->pts[i - 1].x_m, g->pts[i].y_m - g->pts[i - 1].y_m);
  return 0;
}

/* Lane b follows lane a where a's end meets b's start. */
static int join_lanes(road_net_t *net) {
  for (int a = 0; a < net->n_lanes; ++a)
    for (int b = 0; b < net->n_lanes; ++b) {
      if (a == b) continue;
      lane_geom_t *ga = &net->lanes[a], *gb = &net->lanes[b];
      const road_point_t *end = &ga->pts[ga->n - 1], *start = &gb->pts[0];
      if (hypot(end->x_m - start->x_m, end->y_m - start->y_m) < ROAD_JOIN_M &&
          fabs(autodrive_angle_wrap_rad(end->heading_rad - start->heading_rad)) < ROAD_JOIN_RAD) {
        if (append_int(&ga->succ, &ga->n_succ, b) || append_int(&gb->pred, &gb->n_pred, a))
          return -1;
      }
    }
  return 0;
}

/* Puts anchor on every lane passing within reach_m of (x, y) in the direction heading_rad
 * (own_lane >= 0: its lane's direction there). A sign at a pose (own_lane < 0) goes on the
 * nearest such lane and its twins (within ROAD_JOIN_M more). */
static int attach(road_net_t *net, road_anchor_t anchor, double x, double y, double heading_rad,
                  int own_lane, double reach_m) {
  if (own_lane >= 0) heading_rad = project_lane(&net->lanes[own_lane], x, y, NAN, 0.0).heading_rad;
  double dmin = INFINITY;
  for (int pass = 0; pass < 2; ++pass)
    for (int k = 0; k < net->n_lanes; ++k) {
      const projection_t p = project_lane(&net->lanes[k], x, y, NAN, 0.0);
      if (!(p.dist_m < reach_m) ||
          fabs(autodrive_angle_wrap_rad(p.heading_rad - heading_rad)) >= ROAD_JOIN_RAD)
        continue;
      if (pass == 0) {
        if (p.dist_m < dmin) dmin = p.dist_m;
        continue;
      }
      if (own_lane < 0 && !(p.dist_m < dmin + ROAD_JOIN_M)) continue;
      anchor.s_m = p.s_m;
      if (append_anchor(&net->lanes[k], anchor)) return -1;
    }
  return 0;
}

static int place_anchors(road_net_t *net, const road_light_t *lights, int n_lights,
                         const road_sign_t *signs, int n_signs) {
  for (int i = 0; i < n_lights; ++i) {
    const road_anchor_t a = {ROAD_LIGHT, lights[i].id, i, 0.0, -1.0};
    if (attach(net, a, lights[i].x_m, lights[i].y_m, 0.0, lights[i].lane, ROAD_JOIN_M)) return -1;
  }
  for (int i = 0; i < n_signs; ++i) {
    const road_sign_t *sg = &signs[i];
    const road_anchor_t a = {ROAD_SIGN, sg->id, i, 0.0,
                             sg->speed_limit_m_s > 0 ? sg->speed_limit_m_s : -1.0};
    int rc;
    if (sg->lane >= 0) { /* beside its lane: at its projection on the lane's centre line */
      const lane_geom_t *g = &net->lanes[sg->lane];
      double x, y;
      point_at(g, project_lane(g, sg->x_m, sg->y_m, NAN, 0.0).s_m, &x, &y);
      rc = attach(net, a, x, y, 0.0, sg->lane, ROAD_JOIN_M);
    } else { /* at a pose: its face points against its traffic */
      rc = attach(net, a, sg->x_m, sg->y_m,
                  autodrive_angle_wrap_rad(sg->yaw_rad + 3.14159265358979323846), -1,
                  ROAD_POSE_SIGN_REACH_M);
    }
    if (rc) return -1;
  }
  return 0;
}

static int check_input(const road_lane_t *lanes, int n_lanes, const road_light_t *lights,
                       int n_lights, const road_sign_t *signs, int n_signs,
                       const road_route_t *routes, int n_routes, char *err, size_t err_sz) {
  for (int i = 0; i < n_lanes; ++i)
    if (lanes[i].n_points < 2 || !lanes[i].points) {
      fail(err, err_sz, "lane %d: %d centre-line points (needs >= 2)", i, lanes[i].n_points);
      return -1;
    }
  for (int i = 0; i < n_lights; ++i)
    if (lights[i].lane < 0 || lights[i].lane >= n_lanes) {
      fail(err, err_sz, "light %d: lane index %d out of range (%d lanes)", lights[i].id,
           lights[i].lane, n_lanes);
      return -1;
    }
  for (int i = 0; i < n_signs; ++i)
    if (signs[i].lane < -1 || signs[i].lane >= n_lanes) {
      fail(err, err_sz, "sign %d: lane index %d out of range (%d lanes)", signs[i].id,
           signs[i].lane, n_lanes);
      return -1;
    }
  for (int r = 0; r < n_routes; ++r)
    for (int k = 0; k < routes[r].n_lanes; ++k)
      if (routes[r].lanes[k] < 0 || routes[r].lanes[k] >= n_lanes) {
        fail(err, err_sz, "route %d: lane index %d out of range (%d lanes)", r, routes[r].lanes[k],
             n_lanes);
        return -1;
      }
  return 0;
}

road_net_t *road_net_create(const road_lane_t *lanes, int n_lanes, const road_light_t *lights,
                            int n_lights, const road_sign_t *signs, int n_signs,
                            const road_route_t *routes, int n_routes, char *err, size_t err_sz) {
  if (check_input(lanes, n_lanes, lights, n_lights, signs, n_signs, routes, n_routes, err, err_sz))
    return NULL;
  road_net_t *net = calloc(1, sizeof *net);
  if (!net) goto no_memory;
  net->lanes = calloc((size_t)(n_lanes > 0 ? n_lanes : 1), sizeof *net->lanes);
  net->routes = calloc((size_t)(n_routes > 0 ? n_routes : 1), sizeof *net->routes);
  if (!net->lanes || !net->routes) goto no_memory;
  net->n_lanes = n_lanes;
  net->n_routes = n_routes;
  for (int i = 0; i < n_lanes; ++i)
    if (copy_lane(&net->lanes[i], &lanes[i])) goto no_memory;
  for (int r = 0; r < n_routes; ++r) {
    route_geom_t *rt = &net->routes[r];
    rt->n = routes[r].n_lanes;
    rt->loop = routes[r].loop;
    rt->lanes = malloc((size_t)(rt->n > 0 ? rt->n : 1) * sizeof *rt->lanes);
    if (!rt->lanes) goto no_memory;
    if (rt->n > 0) memcpy(rt->lanes, routes[r].lanes, (size_t)rt->n * sizeof *rt->lanes);
  }
  if (join_lanes(net) || place_anchors(net, lights, n_lights, signs, n_signs)) goto no_memory;
  return net;
no_memory:
  fail(err, err_sz, "road_net_create: out of memory");
  road_net_destroy(net);
  return NULL;
}

void road_net_destroy(road_net_t *net) {
  if (!net) return;
  for (int i = 0; net->lanes && i < net->n_lanes; ++i) {
    lane_geom_t *g = &net->lanes[i];
    free(g->pts);
    free(g->s_m);
    free(g->succ);
    free(g->pred);
    free(g->anchors);
  }
  for (int r = 0; net->routes && r < net->n_routes; ++r) free(net->routes[r].lanes);
  free(net->lanes);
  free(net->routes);
  free(net);
}

int road_lane_count(const road_net_t *net) {
  return net->n_lanes;
}

double road_lane_length_m(const road_net_t *net, int lane) {
  const lane_geom_t *g = &net->lanes[lane];
  return g->s_m[g->n - 1];
}

int road_lane_successors(const road_net_t *net, int lane, const int **out) {
  *out = net->lanes[lane].succ;
  return net->lanes[lane].n_succ;
}

int road_lane_anchors(const road_net_t *net, int lane, const road_anchor_t **out) {
  *out = net->lanes[lane].anchors;
  return net->lanes[lane].n_anchors;
}

static int on_route(const road_net_t *net, int route, int lane) {
  if (route < 0 || route >= net->n_routes) return 0;
  for (int k = 0; k < net->routes[route].n; ++k)
    if (net->routes[route].lanes[k] == lane) return 1;
  return 0;
}

/* The last lane and its successors. */
static int follows(const road_net_t *net, int last_lane, int lane) {
  if (last_lane < 0 || last_lane >= net->n_lanes) return 0;
  if (lane == last_lane) return 1;
  const lane_geom_t *g = &net->lanes[last_lane];
  for (int k = 0; k < g->n_succ; ++k)
    if (g->succ[k] == lane) return 1;
  return 0;
}

int road_place_car(const road_net_t *net, double x_m, double y_m, double yaw_rad, int route,
                   int last_lane, road_place_t *out) {
  long best_rank = -1;
  for (int k = 0; k < net->n_lanes; ++k) {
    const lane_geom_t *g = &net->lanes[k];
    const double reach_m = g->half_width_m + ROAD_LANE_MARGIN_M;
    if (x_m < g->min_x_m - reach_m || x_m > g->max_x_m + reach_m || y_m < g->min_y_m - reach_m ||
        y_m > g->max_y_m + reach_m)
      continue; /* too far from the whole lane */
    const projection_t p = project_lane(g, x_m, y_m, yaw_rad, ROAD_MAX_HEADING_RAD);
    if (!(p.dist_m <= reach_m)) continue;
    /* route lanes first, then the last lane and its successors, then the nearest [mm] */
    const long rank = (on_route(net, route, k) ? 0L : 2000000L) +
                      (follows(net, last_lane, k) ? 0L : 1000000L) + lround(p.dist_m * 1000.0);
    if (best_rank >= 0 && rank >= best_rank) continue;
    best_rank = rank;
    out->lane = k;
    out->s_m = p.s_m;
    out->offset_m = p.dist_m;
  }
  return best_rank >= 0;
}

int road_next_lane(const road_net_t *net, int lane, int route) {
  if (route >= 0 && route < net->n_routes) {
    const route_geom_t *r = &net->routes[route];
    for (int k = 0; k < r->n; ++k)
      if (r->lanes[k] == lane) {
        if (k + 1 < r->n) return r->lanes[k + 1];
        return r->loop ? r->lanes[0] : -1;
      }
  }
  const lane_geom_t *g = &net->lanes[lane];
  return g->n_succ == 1 ? g->succ[0] : -1;
}

road_ahead_t road_walk_ahead(const road_net_t *net, const road_place_t *place, int route,
                             double horizon_m) {
  road_ahead_t out = {-1, -1, -1.0, -1, -1, -1.0, road_speed_limit_m_s(net, place)};
  int lane = place->lane;
  double s0 = place->s_m, travelled = 0.0;
  /* each lane once: a loop's walk ends where it began */
  char *seen = calloc((size_t)net->n_lanes, 1);
  if (!seen) return out;
  while (travelled < horizon_m && (out.light_id < 0 || out.sign_id < 0)) {
    const lane_geom_t *g = &net->lanes[lane];
    for (int k = 0; k < g->n_anchors; ++k) {
      const road_anchor_t *a = &g->anchors[k];
      if (a->s_m < s0) continue;
      const double dist = travelled + a->s_m - s0;
      if (dist > horizon_m) break;
      if (a->kind == ROAD_LIGHT && out.light_id < 0) {
        out.light_id = a->id;
        out.light_index = a->index;
        out.stop_line_distance_m = dist;
      } else if (a->kind == ROAD_SIGN && out.sign_id < 0) {
        out.sign_id = a->id;
        out.sign_index = a->index;
        out.sign_distance_m = dist;
      }
    }
    travelled += g->s_m[g->n - 1] - s0;
    seen[lane] = 1;
    const int next = road_next_lane(net, lane, route);
    if (next < 0 || seen[next]) break;
    lane = next;
    s0 = 0.0;
  }
  free(seen);
  return out;
}

double road_speed_limit_m_s(const road_net_t *net, const road_place_t *place) {
  int lane = place->lane;
  double s0 = place->s_m;
  for (int step = 0; step < 64; ++step) {
    const lane_geom_t *g = &net->lanes[lane];
    for (int k = g->n_anchors - 1; k >= 0; --k) {
      const road_anchor_t *a = &g->anchors[k];
      if (a->kind == ROAD_SIGN && a->s_m <= s0 && a->speed_limit_m_s > 0) return a->speed_limit_m_s;
    }
    if (g->n_pred != 1 || net->lanes[g->pred[0]].n_succ != 1) return -1.0;
    lane = g->pred[0];
    s0 = road_lane_length_m(net, lane);
  }
  return -1.0;
}
