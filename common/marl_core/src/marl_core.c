/* The intersection policy's observation builder and time-to-collision shield
 * (<autodrive/marl_core.h>). Pure arithmetic: no allocation, no I/O, no state. */
#include <autodrive/marl_core.h>

#include <autodrive/angle_wrap.h>

#include <math.h>
#include <stdarg.h>
#include <stdio.h>

static int fail(char *err, size_t err_sz, const char *fmt, ...) {
  if (err != NULL && err_sz > 0) {
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(err, err_sz, fmt, ap);
    va_end(ap);
  }
  return -1;
}

static int car_ok(const adm_car_t *c) {
  return isfinite(c->x_m) && isfinite(c->y_m) && isfinite(c->yaw_rad) && isfinite(c->speed_m_s);
}

/* (wx, wy) in the frame of a car at (x, y, yaw). */
static void to_car_frame(double x, double y, double yaw, double wx, double wy, double *cx,
                         double *cy) {
  const double c = cos(yaw), s = sin(yaw), dx = wx - x, dy = wy - y;
  *cx = c * dx + s * dy;
  *cy = -s * dx + c * dy;
}

int adm_observation(const adm_car_t *self, const double *goal_xy_m, const double *waypoint_xy_m,
                    double last_steering, const adm_car_t *peers, int n_peers, float *obs,
                    int obs_len, char *err, size_t err_sz) {
  if (self == NULL || goal_xy_m == NULL || waypoint_xy_m == NULL || obs == NULL)
    return fail(err, err_sz, "observation: self, goal, waypoint and obs must not be NULL");
  if (obs_len != ADM_OBS_DIM)
    return fail(err, err_sz, "observation: obs_len %d, the layout has %d", obs_len, ADM_OBS_DIM);
  if (n_peers < 0 || (n_peers > 0 && peers == NULL))
    return fail(err, err_sz, "observation: %d peers at %p", n_peers, (const void *)peers);
  if (!car_ok(self) || !isfinite(goal_xy_m[0]) || !isfinite(goal_xy_m[1]) ||
      !isfinite(waypoint_xy_m[0]) || !isfinite(waypoint_xy_m[1]) || !isfinite(last_steering))
    return fail(err, err_sz,
                "observation: car %d: a pose, goal, waypoint or steering is not finite", self->id);
  for (int i = 0; i < obs_len; i++) obs[i] = 0.0f;
  double gx, gy, wx, wy;
  to_car_frame(self->x_m, self->y_m, self->yaw_rad, goal_xy_m[0], goal_xy_m[1], &gx, &gy);
  to_car_frame(self->x_m, self->y_m, self->yaw_rad, waypoint_xy_m[0], waypoint_xy_m[1], &wx, &wy);
  obs[0] = (float)(gx / ADM_POSITION_SCALE_M);
  obs[1] = (float)(gy / ADM_POSITION_SCALE_M);
  obs[2] = (float)(wx / ADM_WAYPOINT_SCALE_M);
  obs[3] = (float)(wy / ADM_WAYPOINT_SCALE_M);
  obs[4] = (float)(self->speed_m_s / ADM_SPEED_SCALE_M_S);
  obs[5] = (float)(last_steering < -1.0 ? -1.0 : last_steering > 1.0 ? 1.0 : last_steering);

  /* The nearest ADM_PEER_SLOTS peers in range, by insertion into a sorted short list. */
  int slot_peer[ADM_PEER_SLOTS];
  double slot_d[ADM_PEER_SLOTS];
  int used = 0;
  for (int i = 0; i < n_peers; i++) {
    const adm_car_t *p = &peers[i];
    if (p->id == self->id) continue;
    if (!car_ok(p))
      return fail(err, err_sz, "observation: peer %d: a pose or speed is not finite", p->id);
    const double d = hypot(p->x_m - self->x_m, p->y_m - self->y_m);
    if (d > ADM_PEER_RANGE_M) continue;
    int k = used < ADM_PEER_SLOTS ? used : ADM_PEER_SLOTS;
    while (k > 0 &&
           (d < slot_d[k - 1] || (d == slot_d[k - 1] && p->id < peers[slot_peer[k - 1]].id))) {
      if (k < ADM_PEER_SLOTS) {
        slot_d[k] = slot_d[k - 1];
        slot_peer[k] = slot_peer[k - 1];
      }
      k--;
    }
    if (k < ADM_PEER_SLOTS) {
      slot_d[k] = d;
      slot_peer[k] = i;
      if (used < ADM_PEER_SLOTS) used++;
    }
  }
  for (int s = 0; s < used; s++) {
    const adm_car_t *p = &peers[slot_peer[s]];
    float *o = obs + ADM_OWN_FEATURES + s * ADM_PEER_FEATURES;
    double rx, ry;
    to_car_frame(self->x_m, self->y_m, self->yaw_rad, p->x_m, p->y_m, &rx, &ry);
    const double ryaw = p->yaw_rad - self->yaw_rad;
    o[0] = 1.0f;
    o[1] = (float)(rx / ADM_POSITION_SCALE_M);
    o[2] = (float)(ry / ADM_POSITION_SCALE_M);
    o[3] = (float)cos(ryaw);
    o[4] = (float)sin(ryaw);
    o[5] = (float)(p->speed_m_s / ADM_SPEED_SCALE_M_S);
  }
  return 0;
}

int adm_route_waypoint(const double *route_xy_m, int n_points, double x_m, double y_m,
                       double lookahead_m, int *hint_index, double *waypoint_xy_m,
                       double *remaining_m, char *err, size_t err_sz) {
  if (route_xy_m == NULL || hint_index == NULL || waypoint_xy_m == NULL || remaining_m == NULL)
    return fail(err, err_sz,
                "route waypoint: route, hint, waypoint and remaining must not be NULL");
  if (n_points < 2)
    return fail(err, err_sz, "route waypoint: a route needs >= 2 points, got %d", n_points);
  if (!isfinite(x_m) || !isfinite(y_m) || !isfinite(lookahead_m) || lookahead_m < 0.0)
    return fail(err, err_sz, "route waypoint: position (%g, %g) or lookahead %g m is bad", x_m, y_m,
                lookahead_m);
  const int back = 3, ahead = 40; /* search window around the hint [points] */
  int lo = 0, hi = n_points - 1;
  if (*hint_index >= 0 && *hint_index < n_points) {
    lo = *hint_index - back < 0 ? 0 : *hint_index - back;
    hi = *hint_index + ahead >= n_points ? n_points - 1 : *hint_index + ahead;
  }
  int best = lo;
  double best_d2 = INFINITY;
  for (int i = lo; i <= hi; i++) {
    const double dx = route_xy_m[2 * i] - x_m, dy = route_xy_m[2 * i + 1] - y_m;
    const double d2 = dx * dx + dy * dy;
    if (d2 < best_d2) {
      best_d2 = d2;
      best = i;
    }
  }
  *hint_index = best;
  double remaining = 0.0;
  for (int i = best; i + 1 < n_points; i++)
    remaining += hypot(route_xy_m[2 * i + 2] - route_xy_m[2 * i],
                       route_xy_m[2 * i + 3] - route_xy_m[2 * i + 1]);
  *remaining_m = remaining;
  /* march lookahead_m along the polyline from the nearest point */
  double left = lookahead_m;
  int i = best;
  waypoint_xy_m[0] = route_xy_m[2 * (n_points - 1)];
  waypoint_xy_m[1] = route_xy_m[2 * (n_points - 1) + 1];
  for (; i + 1 < n_points; i++) {
    const double ax = route_xy_m[2 * i], ay = route_xy_m[2 * i + 1];
    const double bx = route_xy_m[2 * i + 2], by = route_xy_m[2 * i + 3];
    const double seg = hypot(bx - ax, by - ay);
    if (seg >= left && seg > 0.0) {
      waypoint_xy_m[0] = ax + (bx - ax) * left / seg;
      waypoint_xy_m[1] = ay + (by - ay) * left / seg;
      break;
    }
    left -= seg;
  }
  return 0;
}

void adm_shield_defaults(adm_shield_config_t *cfg) {
  if (cfg == NULL) return;
  *cfg = (adm_shield_config_t){
      .horizon_s = 2.5,
      .dt_s = 0.05,
      .steer_hold_s = 0.3,
      .margin_m = 0.03,
      .emergency_s = 0.6,
      .brake_throttle = 0.0,
      .back_throttle = -0.5,
      .back_check_s = 1.0,
      .lane_horizon_s = 0.6,
      .lane_margin_m = 0.03,
      .lane_lookahead_m = 0.35,
      .lane_gain = 2.5,
  };
}

/* The two footprint circles' centres of a car at (x, y, yaw). */
static void circles(const adm_shield_config_t *cfg, double x, double y, double yaw, double cx[2],
                    double cy[2]) {
  const double c = cos(yaw), s = sin(yaw), q = 0.25 * cfg->chassis_length_m;
  for (int k = 0; k < 2; k++) {
    const double along = cfg->chassis_offset_m + (k == 0 ? q : -q);
    cx[k] = x + c * along;
    cy[k] = y + s * along;
  }
}

static double footprint_distance(const adm_shield_config_t *cfg, double ax, double ay, double ayaw,
                                 double bx, double by, double byaw) {
  double acx[2], acy[2], bcx[2], bcy[2];
  circles(cfg, ax, ay, ayaw, acx, acy);
  circles(cfg, bx, by, byaw, bcx, bcy);
  double best = INFINITY;
  for (int i = 0; i < 2; i++)
    for (int j = 0; j < 2; j++) {
      const double d = hypot(acx[i] - bcx[j], acy[i] - bcy[j]);
      best = d < best ? d : best;
    }
  return best;
}

static int standing(const adm_car_t *c) {
  return fabs(c->speed_m_s) < ADM_STOPPED_M_S;
}

/* Self stands in the way of a standing peer that goes first (the lower id): the peer's bare
 * footprint, driven at top speed straight on or at either full lock (its route may turn: batch
 * seed 1000000106, a ring of four standing cars where the first one's way was a turn), touches
 * self's within emergency_s. */
static int blocks_a_first_peer(const adm_shield_config_t *cfg, const adm_car_t *self,
                               const adm_car_t *peers, int n_peers) {
  /* standing, or backing already: a car that had to stand to count as backing stopped after
   * each 0.2 s of it (batch seed 1000000088: 1 cm/s on average) */
  if (self->speed_m_s > ADM_STOPPED_M_S) return 0;
  const double half_len = 0.25 * cfg->chassis_length_m, half_w = 0.5 * cfg->chassis_width_m;
  const double touch = 2.0 * sqrt(half_len * half_len + half_w * half_w);
  const double yaw_rate = cfg->top_speed_m_s * tan(cfg->steer_limit_rad) / cfg->wheelbase_m;
  for (int i = 0; i < n_peers; i++) {
    const adm_car_t *p = &peers[i];
    if (p->id == self->id || p->id > self->id || !standing(p)) continue;
    for (int turn = -1; turn <= 1; turn++) {
      double qx = p->x_m, qy = p->y_m, qyaw = p->yaw_rad;
      for (double t = cfg->dt_s; t < cfg->emergency_s + 1e-9; t += cfg->dt_s) {
        qyaw += turn * yaw_rate * cfg->dt_s;
        qx += cfg->top_speed_m_s * cos(qyaw) * cfg->dt_s;
        qy += cfg->top_speed_m_s * sin(qyaw) * cfg->dt_s;
        if (footprint_distance(cfg, qx, qy, qyaw, self->x_m, self->y_m, self->yaw_rad) < touch)
          return 1;
      }
    }
  }
  return 0;
}

/* Self's way straight back at back_throttle keeps contact (footprints plus margin) with no car
 * for back_check_s, each peer keeping its heading and speed. */
static int way_back_clear(const adm_shield_config_t *cfg, const adm_car_t *self,
                          const adm_car_t *peers, int n_peers, double contact) {
  const double v = cfg->back_throttle * cfg->top_speed_m_s; /* < 0 */
  const double graze_m = 0.005;
  for (double t = cfg->dt_s; t < cfg->back_check_s + 1e-9; t += cfg->dt_s) {
    const double px = self->x_m + v * t * cos(self->yaw_rad);
    const double py = self->y_m + v * t * sin(self->yaw_rad);
    const int last = t + cfg->dt_s > cfg->back_check_s + 1e-9;
    for (int i = 0; i < n_peers; i++) {
      const adm_car_t *p = &peers[i];
      if (p->id == self->id) continue;
      const double qx = p->x_m + p->speed_m_s * cos(p->yaw_rad) * t;
      const double qy = p->y_m + p->speed_m_s * sin(p->yaw_rad) * t;
      const double now =
          footprint_distance(cfg, self->x_m, self->y_m, self->yaw_rad, qx, qy, p->yaw_rad);
      const double d = footprint_distance(cfg, px, py, self->yaw_rad, qx, qy, p->yaw_rad);
      /* closer than the margin, and closing by more than graze_m: sliding past a corner at a
       * near constant distance is not closing (batch seed 1000000088: a 0.2 mm dip kept a car
       * from backing out of a standing pair for 30 s). But the way must open by its end, else
       * checks 0.1 s apart could each allow a few mm more. */
      if (d < contact && d < now - (last ? 0.0 : graze_m)) return 0;
    }
  }
  return 1;
}

/* Distance [m] from (x, y) to the route's polyline, over the segments near hint. */
static double route_distance(const adm_lane_t *lane, double x, double y) {
  const int back = 5, ahead = 40; /* search window around the hint [points] */
  int lo = 0, hi = lane->n_points - 1;
  if (lane->hint_index >= 0 && lane->hint_index < lane->n_points) {
    lo = lane->hint_index - back < 0 ? 0 : lane->hint_index - back;
    hi = lane->hint_index + ahead >= lane->n_points ? lane->n_points - 1 : lane->hint_index + ahead;
  }
  double best = INFINITY;
  for (int i = lo; i < hi; i++) {
    const double ax = lane->route_xy_m[2 * i], ay = lane->route_xy_m[2 * i + 1];
    const double dx = lane->route_xy_m[2 * i + 2] - ax, dy = lane->route_xy_m[2 * i + 3] - ay;
    const double len2 = dx * dx + dy * dy;
    double u = len2 > 0.0 ? ((x - ax) * dx + (y - ay) * dy) / len2 : 0.0;
    u = u < 0.0 ? 0.0 : u > 1.0 ? 1.0 : u;
    const double d = hypot(x - ax - u * dx, y - ay - u * dy);
    best = d < best ? d : best;
  }
  return best;
}

/* How far [m] the chassis box's farthest corner of a car at (x, y, yaw) is past the bound. */
static double lane_excess(const adm_shield_config_t *cfg, const adm_lane_t *lane, double x,
                          double y, double yaw) {
  const double c = cos(yaw), s = sin(yaw), bound = lane->half_width_m + cfg->lane_margin_m;
  double worst = -INFINITY;
  for (int k = 0; k < 4; k++) {
    const double along = cfg->chassis_offset_m + (k < 2 ? 0.5 : -0.5) * cfg->chassis_length_m;
    const double side = (k % 2 == 0 ? 0.5 : -0.5) * cfg->chassis_width_m;
    const double e = route_distance(lane, x + c * along - s * side, y + s * along + c * side);
    worst = e > worst ? e : worst;
  }
  return worst - bound;
}

/* Self driven at v_m_s with the wheels slewing from lane->steering_now to steering (both
 * normalised) for lane_horizon_s: 1 if a chassis corner gets past the bound and farther out
 * than now (a car already outside may still come back in). */
static int leaves_lane(const adm_shield_config_t *cfg, const adm_lane_t *lane,
                       const adm_car_t *self, double v_m_s, double steering) {
  const double now = lane_excess(cfg, lane, self->x_m, self->y_m, self->yaw_rad);
  const double allowed = (now > 0.0 ? now : 0.0) + 1e-3; /* 1 mm: rounding */
  const double target = fmax(-1.0, fmin(1.0, steering)) * cfg->steer_limit_rad;
  double delta = fmax(-1.0, fmin(1.0, lane->steering_now)) * cfg->steer_limit_rad;
  const double slew = cfg->steer_rate_rad_s > 0.0 ? cfg->steer_rate_rad_s * cfg->dt_s : INFINITY;
  double px = self->x_m, py = self->y_m, pyaw = self->yaw_rad;
  for (double t = cfg->dt_s; t < cfg->lane_horizon_s + 1e-9; t += cfg->dt_s) {
    delta += fmax(-slew, fmin(slew, target - delta));
    pyaw += v_m_s * tan(delta) / cfg->wheelbase_m * cfg->dt_s;
    px += v_m_s * cos(pyaw) * cfg->dt_s;
    py += v_m_s * sin(pyaw) * cfg->dt_s;
    if (lane_excess(cfg, lane, px, py, pyaw) > allowed) return 1;
  }
  return 0;
}

/* The lane follower's steering (normalised): gain x the bearing of the route point
 * lane_lookahead_m ahead of the nearest one. */
static double follow_lane(const adm_shield_config_t *cfg, const adm_lane_t *lane,
                          const adm_car_t *self) {
  int hint = lane->hint_index;
  double aim[2], remaining;
  if (adm_route_waypoint(lane->route_xy_m, lane->n_points, self->x_m, self->y_m,
                         cfg->lane_lookahead_m, &hint, aim, &remaining, NULL, 0) != 0)
    return 0.0;
  double bearing = atan2(aim[1] - self->y_m, aim[0] - self->x_m) - self->yaw_rad;
  bearing = autodrive_angle_wrap_rad(bearing);
  return fmax(-1.0, fmin(1.0, cfg->lane_gain * bearing));
}

int adm_shield(const adm_shield_config_t *cfg, const adm_car_t *self, const adm_command_t *intended,
               const adm_car_t *peers, int n_peers, const adm_lane_t *lane,
               adm_shield_result_t *out, char *err, size_t err_sz) {
  if (cfg == NULL || self == NULL || intended == NULL || out == NULL)
    return fail(err, err_sz, "shield: cfg, self, intended and out must not be NULL");
  if (n_peers < 0 || (n_peers > 0 && peers == NULL))
    return fail(err, err_sz, "shield: %d peers at %p", n_peers, (const void *)peers);
  if (!(cfg->horizon_s > 0.0) || !(cfg->dt_s > 0.0) || cfg->dt_s > cfg->horizon_s ||
      !(cfg->chassis_length_m > 0.0) || !(cfg->chassis_width_m > 0.0) ||
      !(cfg->wheelbase_m > 0.0) || !(cfg->top_speed_m_s > 0.0) || !(cfg->steer_limit_rad > 0.0) ||
      !(cfg->margin_m >= 0.0) || !(cfg->pose_error_m >= 0.0) || !(cfg->steer_hold_s >= 0.0) ||
      !isfinite(cfg->brake_throttle))
    return fail(err, err_sz,
                "shield: config needs horizon_s >= dt_s > 0, chassis, wheelbase, steering limit "
                "and top speed > 0, margin, pose error and steer_hold >= 0");
  if (!car_ok(self) || !isfinite(intended->throttle) || !isfinite(intended->steering))
    return fail(err, err_sz, "shield: car %d: its pose, speed or command is not finite", self->id);
  for (int i = 0; i < n_peers; i++)
    if (!car_ok(&peers[i]))
      return fail(err, err_sz, "shield: peer %d: a pose or speed is not finite", peers[i].id);
  if (lane != NULL && (lane->route_xy_m == NULL || lane->n_points < 2 ||
                       !(lane->half_width_m > 0.0) || !isfinite(lane->steering_now) ||
                       !(cfg->lane_horizon_s > 0.0) || !(cfg->lane_margin_m >= 0.0) ||
                       !(cfg->lane_lookahead_m > 0.0) || !(cfg->steer_rate_rad_s >= 0.0)))
    return fail(err, err_sz,
                "shield: car %d: the lane needs a route of >= 2 points, half width > 0 and a "
                "finite steering; the config lane horizon and lookahead > 0, margin and steering "
                "rate >= 0",
                self->id);

  out->command = *intended;
  out->intervened = 0;
  out->peer_id = -1;
  out->ttc_s = cfg->horizon_s;
  out->steered = 0;

  const double half_len = 0.25 * cfg->chassis_length_m, half_w = 0.5 * cfg->chassis_width_m;
  const double radius =
      sqrt(half_len * half_len + half_w * half_w) + cfg->pose_error_m + cfg->margin_m;
  const double contact = 2.0 * radius;
  const double v_self = intended->throttle > 0.0
                            ? fmax(self->speed_m_s, intended->throttle * cfg->top_speed_m_s)
                            : self->speed_m_s;
  int lane_brake = 0;
  /* The lane term (seeds 1000000009 .. 1000000165 of the batch: a car alone, its discrete
   * steering and the servo's slew weaving its chassis into a traffic light's pole at the start
   * of a right turn). Predicted at the driving speed even while standing, so that the wheels
   * are never set to a lock that would leave the lane at the start. */
  if (lane != NULL) {
    const double v_lane = fmax(fabs(v_self), cfg->top_speed_m_s * fmax(intended->throttle, 0.0));
    if (v_lane > 0.0 && leaves_lane(cfg, lane, self, v_lane, intended->steering)) {
      out->command.steering = follow_lane(cfg, lane, self);
      out->steered = 1;
      out->intervened = 1;
      lane_brake = leaves_lane(cfg, lane, self, v_lane, out->command.steering);
    }
  }
  const double steer = fmax(-1.0, fmin(1.0, out->command.steering)) * cfg->steer_limit_rad;
  const int steps = (int)ceil(cfg->horizon_s / cfg->dt_s);

  /* the footprints (grown by the pose error) without the margin */
  const double touch = 2.0 * (radius - cfg->margin_m);
  double best_t = INFINITY;
  int best_peer = -1;
  for (int i = 0; i < n_peers; i++) {
    const adm_car_t *p = &peers[i];
    if (p->id == self->id) continue;
    /* Right of way, the same seen from either car: each projects the other onto its own
     * heading; the car that has the other farther ahead of it gives way (equal within 5 cm:
     * the lower id goes first). */
    const double ahead_of_self =
        (p->x_m - self->x_m) * cos(self->yaw_rad) + (p->y_m - self->y_m) * sin(self->yaw_rad);
    const double ahead_of_peer =
        (self->x_m - p->x_m) * cos(p->yaw_rad) + (self->y_m - p->y_m) * sin(p->yaw_rad);
    /* Both standing (waiting): the lower id goes, so that no ring of cars, each giving way to
     * the next, waits for ever. */
    const int both_stopped =
        fabs(self->speed_m_s) < ADM_STOPPED_M_S && fabs(p->speed_m_s) < ADM_STOPPED_M_S;
    const int peer_first =
        both_stopped ? p->id < self->id
                     : ahead_of_self > ahead_of_peer + 0.05 ||
                           (fabs(ahead_of_self - ahead_of_peer) <= 0.05 && p->id < self->id);
    /* A standing peer that goes first will start: self, standing too, does not start into its
     * way straight on (batch seed 1000000187: a car backed out of a first car's way, drove in
     * again as soon as it was out, and the first car never got to go). */
    const int peer_starts = both_stopped && peer_first;
    /* Self's path under two steerings: the intended one, and straight on. The steering servo
     * slews (~1 rad/s): a car still turning the other way follows neither exactly, but between
     * them it stays near the straight path for the first few tenths of a second (batch seed
     * 1000000001: a right-of-way car commanded full right kept its heading for 0.5 s and met a
     * waiting car that the turning prediction missed). */
    for (int hyp = 0; hyp < 2; hyp++) {
      const double steer_h = hyp == 0 ? steer : 0.0;
      if (hyp == 1 && steer == 0.0) break;
      double px = self->x_m, py = self->y_m, pyaw = self->yaw_rad;
      for (int k = 1; k <= steps; k++) {
        const double t = k * cfg->dt_s;
        if (t >= best_t) break;
        /* self: kinematic bicycle, the steering while t <= steer_hold_s */
        if (t <= cfg->steer_hold_s + 1e-9)
          pyaw += v_self * tan(steer_h) / cfg->wheelbase_m * cfg->dt_s;
        px += v_self * cos(pyaw) * cfg->dt_s;
        py += v_self * sin(pyaw) * cfg->dt_s;
        const double qx = p->x_m + p->speed_m_s * cos(p->yaw_rad) * t;
        const double qy = p->y_m + p->speed_m_s * sin(p->yaw_rad) * t;
        double d = footprint_distance(cfg, px, py, pyaw, qx, qy, p->yaw_rad);
        if (peer_starts) {
          const double sx = p->x_m + cfg->top_speed_m_s * cos(p->yaw_rad) * t;
          const double sy = p->y_m + cfg->top_speed_m_s * sin(p->yaw_rad) * t;
          d = fmin(d, footprint_distance(cfg, px, py, pyaw, sx, sy, p->yaw_rad));
        }
        /* giving way: any contact with the margin; with the right of way: only a touch of the
         * bare footprints within emergency_s (so that two cars never both wait for ever) */
        const int brake = peer_first ? d < contact : (d < touch && t < cfg->emergency_s);
        if (!brake) continue;
        /* a peer behind self at contact would run into self: its own shield's job */
        double rx, ry;
        to_car_frame(px, py, pyaw, qx, qy, &rx, &ry);
        if (rx < -0.5 * cfg->chassis_length_m) break;
        best_t = t;
        best_peer = p->id;
        break;
      }
    }
  }
  if (lane_brake && best_peer < 0) {
    out->command.throttle = cfg->brake_throttle;
    return 0;
  }
  if (best_peer >= 0 && cfg->back_throttle < 0.0 &&
      blocks_a_first_peer(cfg, self, peers, n_peers) &&
      way_back_clear(cfg, self, peers, n_peers, contact)) {
    out->command.throttle = cfg->back_throttle;
    out->command.steering = 0.0;
    out->intervened = 1;
    out->peer_id = best_peer;
    out->ttc_s = best_t;
  } else if (best_peer >= 0) {
    out->command.throttle = cfg->brake_throttle;
    out->intervened = 1;
    out->peer_id = best_peer;
    out->ttc_s = best_t;
  }
  return 0;
}
