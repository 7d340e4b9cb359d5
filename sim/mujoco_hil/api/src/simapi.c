/* The learning API (autodrive_sim_api.h) over the simulator core (sim.h): a world is a sim_t
 * with no ptys, an in-process scripted driver per car (the command path), the LIDAR cast on
 * request, an optional headless front camera, and per-car routes for the lane flag. */
#include "autodrive_sim_api.h"

#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "failsafe.h"
#include "route.h"
#include "sim.h"
#include "sim_camera.h"
#include "sim_lidar.h"
#include "sim_render.h"

/* every car's driver starts idle; ad_world_command changes what it sends */
#define API_DRIVER_SPEC "constant:throttle=0,steering=0"
#define API_JPEG_QUALITY 85 /* sim_camera encodes each frame; unused here */

struct ad_world {
  sim_t *sim;
  int ncars, lidar_rays, cam_w, cam_h;
  route_t route[AD_MAX_CARS]; /* per car; n == 0: none */
  route_t *lanes;             /* the map's lane_* numerics */
  int nlanes;
  sim_render_t *render;
  sim_camera_t *cam[AD_MAX_CARS];
};

static int api_car_ok(const ad_world_t *w, int car, char *err, size_t err_sz) {
  if (car >= 0 && car < w->ncars) return 1;
  if (err) snprintf(err, err_sz, "car %d: the world has cars 0..%d", car, w->ncars - 1);
  return 0;
}

/* The map's lanes (MJCF numerics lane_<name>: half_width_m x0 y0 x1 y1 ...). */
static int api_load_lanes(ad_world_t *w, char *err, size_t err_sz) {
  const mjModel *m = sim_model(w->sim);
  w->lanes = calloc((size_t)(m->nnumeric > 0 ? m->nnumeric : 1), sizeof *w->lanes);
  if (!w->lanes) {
    snprintf(err, err_sz, "out of memory");
    return -1;
  }
  for (int i = 0; i < m->nnumeric; i++) {
    const char *name = m->names + m->name_numericadr[i];
    if (strncmp(name, "lane_", 5) != 0 || strstr(name, ".part")) continue; /* parts: below */
    if (route_from_numeric(&w->lanes[w->nlanes], m, i, 0, err, err_sz) != 0) return -1;
    w->nlanes++;
  }
  return 0;
}

ad_world_t *ad_world_create(const ad_world_config_t *cfg, char *err, size_t err_sz) {
  if (!cfg || !cfg->map || !cfg->map[0]) {
    snprintf(err, err_sz, "world config: no map given");
    return NULL;
  }
  if (cfg->lidar_rays < 0 || cfg->lidar_rays > 100000) {
    snprintf(err, err_sz, "world config: lidar_rays %d must be 0..100000", cfg->lidar_rays);
    return NULL;
  }
  if (cfg->camera_width_px < 0 || cfg->camera_height_px < 0 ||
      (cfg->camera_width_px > 0) != (cfg->camera_height_px > 0) || cfg->camera_width_px > 4096 ||
      cfg->camera_height_px > 4096) {
    snprintf(err, err_sz, "world config: camera %d x %d px must be 0 x 0 or up to 4096 x 4096",
             cfg->camera_width_px, cfg->camera_height_px);
    return NULL;
  }
  char map[1024], params[1024];
  if (strchr(cfg->map, '/') || strstr(cfg->map, ".xml"))
    snprintf(map, sizeof map, "%s", cfg->map);
  else
    snprintf(map, sizeof map, "%s/%s.xml", AUTODRIVE_MAPS_DIR, cfg->map);
  if (cfg->params_path)
    snprintf(params, sizeof params, "%s", cfg->params_path);
  else
    snprintf(params, sizeof params, "%s/vehicle/nigel.params", AUTODRIVE_ROOT_DIR);
  const char *tmp = getenv("TMPDIR");
  sim_config_t sc;
  memset(&sc, 0, sizeof sc);
  sc.params_path = params;
  sc.map_path = map;
  sc.run_dir = cfg->run_dir ? cfg->run_dir : (tmp && tmp[0] ? tmp : "/tmp");
  sc.cars = cfg->cars;
  sc.seed = cfg->seed;
  sc.script = API_DRIVER_SPEC;
  sc.lidar = cfg->lidar_rays > 0;
  sc.lidar_on_request = 1;
  sc.lidar_rays = cfg->lidar_rays;
  sc.tyre_model = cfg->tyre_model;
  sc.host_io_period_ms = 1;
  ad_world_t *w = calloc(1, sizeof *w);
  if (!w) {
    snprintf(err, err_sz, "out of memory");
    return NULL;
  }
  w->sim = sim_create(&sc, err, err_sz);
  if (!w->sim) goto fail;
  w->ncars = cfg->cars;
  w->lidar_rays = cfg->lidar_rays;
  w->cam_w = cfg->camera_width_px;
  w->cam_h = cfg->camera_height_px;
  if (api_load_lanes(w, err, err_sz) != 0) goto fail;
  return w;
fail:
  ad_world_destroy(w);
  return NULL;
}

void ad_world_destroy(ad_world_t *w) {
  if (!w) return;
  for (int i = 0; i < AD_MAX_CARS; i++) {
    sim_camera_destroy(w->cam[i]);
    route_free(&w->route[i]);
  }
  if (w->render) sim_render_destroy(w->render);
  for (int i = 0; i < w->nlanes; i++) route_free(&w->lanes[i]);
  free(w->lanes);
  sim_destroy(w->sim);
  free(w);
}

int ad_world_cars(const ad_world_t *w) {
  return w->ncars;
}

double ad_world_time_s(const ad_world_t *w) {
  return (double)sim_time_us(w->sim) * 1e-6;
}

int ad_world_reset(ad_world_t *w, uint64_t seed, const double *poses_xy_yaw, char *err,
                   size_t err_sz) {
  return sim_reset(w->sim, seed, poses_xy_yaw, err, err_sz);
}

int ad_world_command(ad_world_t *w, int car, double throttle, double steering, char *err,
                     size_t err_sz) {
  if (!api_car_ok(w, car, err, err_sz)) return -1;
  if (sim_drive(w->sim, car + 1, throttle, steering) != 0) {
    snprintf(err, err_sz, "car %d command: throttle %g, steering %g must be in [-1, 1]", car,
             throttle, steering);
    return -1;
  }
  return 0;
}

int ad_world_step(ad_world_t *w, int period_ms, char *err, size_t err_sz) {
  if (period_ms < 1 || period_ms > 60000) {
    snprintf(err, err_sz, "step period %d ms must be 1..60000", period_ms);
    return -1;
  }
  for (int k = 0; k < period_ms; k++) {
    if (k == period_ms - 1) sim_want_accel(w->sim); /* observations read the IMU after it */
    if (sim_step(w->sim, err, err_sz) != 0) return -1;
  }
  return 0;
}

int ad_worlds_step(ad_world_t *const *worlds, int k, int period_ms, char *err, size_t err_sz) {
  for (int i = 0; i < k; i++) {
    if (ad_world_step(worlds[i], period_ms, err, err_sz) != 0) {
      char why[512];
      snprintf(why, sizeof why, "%s", err);
      snprintf(err, err_sz, "world %d: %s", i, why);
      return -1;
    }
  }
  return 0;
}

/* A threaded batch step: workers take the next world from a shared counter. */
typedef struct api_batch {
  ad_world_t *const *worlds;
  int k, period_ms, next, failed; /* failed: lowest failing world, or k */
  pthread_mutex_t mu;
  char err[1024];
} api_batch_t;

static void *api_batch_worker(void *arg) {
  api_batch_t *b = arg;
  for (;;) {
    pthread_mutex_lock(&b->mu);
    const int i = b->failed < b->k ? b->k : b->next++;
    pthread_mutex_unlock(&b->mu);
    if (i >= b->k) return NULL;
    char err[1024];
    if (ad_world_step(b->worlds[i], b->period_ms, err, sizeof err) != 0) {
      pthread_mutex_lock(&b->mu);
      if (i < b->failed) {
        b->failed = i;
        snprintf(b->err, sizeof b->err, "%s", err);
      }
      pthread_mutex_unlock(&b->mu);
    }
  }
}

int ad_worlds_step_threads(ad_world_t *const *worlds, int k, int period_ms, int threads, char *err,
                           size_t err_sz) {
  if (threads < 1 || threads > AD_MAX_THREADS) {
    snprintf(err, err_sz, "batch step: %d threads, must be 1..%d", threads, AD_MAX_THREADS);
    return -1;
  }
  if (threads > k) threads = k;
  if (threads <= 1) return ad_worlds_step(worlds, k, period_ms, err, err_sz);
  api_batch_t b = {.worlds = worlds, .k = k, .period_ms = period_ms, .next = 0, .failed = k};
  pthread_mutex_init(&b.mu, NULL);
  pthread_t t[AD_MAX_THREADS];
  int started = 0;
  for (; started < threads - 1; started++)
    if (pthread_create(&t[started], NULL, api_batch_worker, &b) != 0) break; /* fewer is fine */
  api_batch_worker(&b);
  for (int i = 0; i < started; i++) pthread_join(t[i], NULL);
  pthread_mutex_destroy(&b.mu);
  if (b.failed < k) {
    snprintf(err, err_sz, "world %d: %s", b.failed, b.err);
    return -1;
  }
  return 0;
}

/* The route the lane flag judges: car's own, else the nearest of the map's lanes. */
static void api_route_fields(const ad_world_t *w, int car, ad_obs_t *o) {
  const double x = o->pos_m[0], y = o->pos_m[1];
  const route_t *r = &w->route[car];
  if (r->n > 0) {
    route_where_t at;
    route_locate(r, x, y, o->yaw_rad, &at);
    o->has_route = 1;
    o->route_lateral_m = at.lateral_m;
    o->route_heading_err_rad = at.heading_err_rad;
    o->route_progress_m = at.progress_m;
    o->route_length_m = r->length_m;
    o->route_half_width_m = r->half_width_m;
    o->off_lane = fabs(at.lateral_m) > r->half_width_m;
    return;
  }
  o->off_lane = 0;
  if (w->nlanes == 0) return;
  o->off_lane = 1;
  for (int i = 0; i < w->nlanes && o->off_lane; i++) {
    route_where_t at;
    route_locate(&w->lanes[i], x, y, o->yaw_rad, &at);
    if (fabs(at.lateral_m) <= w->lanes[i].half_width_m) o->off_lane = 0;
  }
}

int ad_world_observe(const ad_world_t *w, int car, ad_obs_t *o) {
  if (!api_car_ok(w, car, NULL, 0)) return -1;
  sim_truth_t t;
  sim_get_truth(w->sim, car + 1, &t);
  memset(o, 0, sizeof *o);
  o->time_s = ad_world_time_s(w);
  memcpy(o->pos_m, t.pos_m, sizeof o->pos_m);
  memcpy(o->quat_wxyz, t.quat_wxyz, sizeof o->quat_wxyz);
  o->yaw_rad = t.yaw_rad;
  memcpy(o->vel_body_m_s, t.vel_body_m_s, sizeof o->vel_body_m_s);
  memcpy(o->gyro_body_rad_s, t.gyro_body_rad_s, sizeof o->gyro_body_rad_s);
  o->steering_rad = t.steering_rad;
  memcpy(o->wheel_speed_rad_s, t.wheel_speed_rad_s, sizeof o->wheel_speed_rad_s);
  sim_imu(w->sim, car + 1, o->imu_accel_m_s2, o->imu_gyro_rad_s);
  o->in_collision = t.in_collision;
  o->nano_engaged = failsafe_may_drive(&sim_nano(w->sim, car + 1)->failsafe);
  api_route_fields(w, car, o);
  return 0;
}

int ad_world_lidar(ad_world_t *w, int car, float *ranges_m, int n, char *err, size_t err_sz) {
  if (!api_car_ok(w, car, err, err_sz)) return -1;
  if (w->lidar_rays == 0 || n != w->lidar_rays) {
    snprintf(err, err_sz, "car %d LIDAR: the world has %d rays per scan, the buffer %d", car,
             w->lidar_rays, n);
    return -1;
  }
  const sim_lidar_scan_t *scan = sim_lidar_scan_at_once(w->sim, car + 1);
  memcpy(ranges_m, scan->ranges_m, sizeof(float) * (size_t)n);
  return 0;
}

int ad_world_camera(ad_world_t *w, int car, uint8_t *rgb, size_t n_bytes, char *err,
                    size_t err_sz) {
  if (!api_car_ok(w, car, err, err_sz)) return -1;
  if (w->cam_w == 0 || n_bytes != (size_t)w->cam_w * (size_t)w->cam_h * 3u) {
    snprintf(err, err_sz, "car %d camera: the world renders %d x %d px, the buffer has %zu bytes",
             car, w->cam_w, w->cam_h, n_bytes);
    return -1;
  }
  /* the render model: the whole map (roads, markings, tiles), not the physics model, which
   * leaves out the visual-only geoms */
  const mjModel *m = sim_render_model(w->sim);
  if (!w->render) {
    w->render = sim_render_create(m, w->cam_w, w->cam_h, SIM_RENDER_AUTO, err, err_sz);
    if (!w->render) return -1;
  }
  if (!w->cam[car]) {
    char name[48];
    snprintf(name, sizeof name, "nigel%d/cam_front", car + 1);
    w->cam[car] = sim_camera_create(w->render, m, name, "camera_front", w->cam_w, w->cam_h,
                                    API_JPEG_QUALITY, err, err_sz);
    if (!w->cam[car]) return -1;
  }
  if (sim_camera_capture(w->cam[car], m, sim_render_data(w->sim), sim_time_us(w->sim)) != 0) {
    snprintf(err, err_sz, "car %d camera: rendering failed", car);
    return -1;
  }
  memcpy(rgb, sim_camera_rgb(w->cam[car]), n_bytes);
  return 0;
}

int ad_world_set_route(ad_world_t *w, int car, const char *name, char *err, size_t err_sz) {
  if (!api_car_ok(w, car, err, err_sz)) return -1;
  route_free(&w->route[car]);
  if (!name) return 0;
  const mjModel *m = sim_model(w->sim);
  char key[128];
  snprintf(key, sizeof key, "route_%s", name);
  int id = mj_name2id(m, mjOBJ_NUMERIC, key), is_route = 1;
  if (id < 0) {
    snprintf(key, sizeof key, "lane_%s", name);
    id = mj_name2id(m, mjOBJ_NUMERIC, key);
    is_route = 0;
  }
  if (id < 0) {
    snprintf(err, err_sz, "route '%s': the map has no numeric route_%s or lane_%s", name, name,
             name);
    return -1;
  }
  return route_from_numeric(&w->route[car], m, id, is_route, err, err_sz);
}

int ad_world_set_route_points(ad_world_t *w, int car, const double *xy, int n, double half_width_m,
                              int loop, char *err, size_t err_sz) {
  if (!api_car_ok(w, car, err, err_sz)) return -1;
  route_free(&w->route[car]);
  return route_from_points(&w->route[car], xy, n, half_width_m, loop, err, err_sz);
}

double ad_world_bare_mj_step_s(const ad_world_t *w, int steps) {
  return sim_bare_mj_step_s(w->sim, steps, NULL);
}
