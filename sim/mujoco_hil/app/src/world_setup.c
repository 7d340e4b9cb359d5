/* Building and tearing down a run of autodrive-sim (app.h). */
#include "app.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#include <autodrive_channels.h>

#include "app_common.h"
#include "camera_fx.h"
#include "route_driver.h"

static int app_place_given_cars(sim_t *s, uint64_t seed, const scn_pose_t *pose, const int *given,
                                char *err, size_t err_sz) {
  int any = 0;
  double poses[3 * SIM_MAX_CARS];
  for (int i = 0; i < sim_cars(s); i++) {
    sim_truth_t t;
    sim_get_truth(s, i + 1, &t);
    poses[3 * i] = given[i] ? pose[i].x_m : t.pos_m[0];
    poses[3 * i + 1] = given[i] ? pose[i].y_m : t.pos_m[1];
    poses[3 * i + 2] = given[i] ? pose[i].yaw_deg * (M_PI / 180.0) : t.yaw_rad;
    any |= given[i];
  }
  for (int i = sim_cars(s); i < SIM_MAX_CARS; i++)
    if (given[i]) {
      snprintf(err, err_sz, "car %d, but --cars is %d", i + 1, sim_cars(s));
      return -1;
    }
  return any ? sim_reset(s, seed, poses, err, err_sz) : 0;
}

/* --start given once per car: car k at the k-th pose; then the scenario checks (--start,
 * --late-box). Returns 0, or -1 with the message in err. */
static int app_check_starts(app_t *a, char *err, size_t err_sz) {
  const app_options_t *o = a->opt;
  int bad_starts = o->nstarts > 1 && o->nstarts != o->cfg.cars;
  if (bad_starts)
    snprintf(err, err_sz,
             "--start given %d times for %d cars: give it once (car 1) or once per car", o->nstarts,
             o->cfg.cars);
  if (!bad_starts && o->nstarts > 1) { /* one start pose per car: car k at the k-th --start */
    double poses[3 * SIM_MAX_CARS];
    for (int k = 0; k < o->nstarts; k++) {
      poses[3 * k] = o->starts[k].x_m;
      poses[3 * k + 1] = o->starts[k].y_m;
      poses[3 * k + 2] = o->starts[k].yaw_deg * M_PI / 180.0;
    }
    char rerr[400];
    if (sim_reset(a->sim, o->cfg.seed, poses, rerr, sizeof rerr) != 0) {
      snprintf(err, err_sz, "--start: %s", rerr);
      bad_starts = 1;
    }
  }
  return bad_starts || sim_check_scenario(a->sim, err, err_sz) != 0 ? -1 : 0;
}

/* --light-rgb on the render model's lights, and --camera-jitter on each car's front camera
 * mount (drawn from --seed and the car; printed, so a dataset can record it). */
static void app_randomise_scene(app_t *a) {
  const app_options_t *o = a->opt;
  mjModel *m = sim_render_model(a->sim);
  if (o->light_rgb[0] != 1.0 || o->light_rgb[1] != 1.0 || o->light_rgb[2] != 1.0)
    cfx_set_light_rgb(m, o->light_rgb);
  if (!(o->jitter_mm > 0 || o->jitter_deg > 0)) return;
  for (int c = 1; c <= sim_cars(a->sim); c++) {
    char name[48];
    snprintf(name, sizeof name, "nigel%d/cam_front", c);
    const int id = mj_name2id(m, mjOBJ_CAMERA, name);
    if (id < 0) continue;
    const cfx_jitter_t j = cfx_jitter_draw(o->cfg.seed, c, o->jitter_mm, o->jitter_deg);
    cfx_jitter_camera(m, id, &j);
    printf(AUTODRIVE_VEHICLE_PREFIX
           "%d cam_front jitter (--camera-jitter): x %+.3f, y %+.3f, z %+.3f mm; about x %+.3f, "
           "y %+.3f, z %+.3f deg\n",
           c, 1e3 * j.pos_m[0], 1e3 * j.pos_m[1], 1e3 * j.pos_m[2], j.rot_deg[0], j.rot_deg[1],
           j.rot_deg[2]);
  }
  fflush(stdout);
}

/* The world itself: LCM, the truth log, the sim, its start poses and light level. */
static int app_build_world(app_t *a, char *err, size_t err_sz) {
  const app_options_t *o = a->opt;
  if (!(a->lcm = lcm_create(o->url))) {
    fprintf(stderr,
            "autodrive-sim: cannot open LCM url '%s' (udpm:// needs a multicast route, e.g. "
            "'ip route add 239.0.0.0/8 dev lo')\n",
            o->url);
    return 1;
  }
  if (o->truth_log && !(a->truth_log = fopen(o->truth_log, "wb"))) {
    fprintf(stderr, "autodrive-sim: --truth-log '%s': %s\n", o->truth_log, strerror(errno));
    return 1;
  }
  if (!(a->sim = sim_create(&o->cfg, err, err_sz))) {
    fprintf(stderr, "autodrive-sim: %s\n", err);
    return 1;
  }
  if (app_check_starts(a, err, err_sz) != 0) { /* a bad --start / --late-box value */
    fprintf(stderr, "autodrive-sim: %s\n", err);
    return 2;
  }
  if (app_place_given_cars(a->sim, o->cfg.seed, o->car_start, o->car_start_given, err, err_sz) !=
      0) {
    fprintf(stderr, "autodrive-sim: --car-start: %s\n", err);
    return 2;
  }
  if (o->light_level >= 0 && cfx_set_light_level(sim_render_model(a->sim), o->light_level) != 0) {
    fprintf(stderr,
            "autodrive-sim: --light-level %g: the map '%s' is dark (level 0): nothing "
            "to scale\n",
            o->light_level, o->cfg.map_path);
    return 2;
  }
  app_randomise_scene(a);
  return -1;
}

/* The cameras: on the render thread in real time, --rtf and --lockstep-client; on the stepping
 * thread in free --lockstep and --lockstep-frames (repeatable runs). */
static int app_build_cameras(app_t *a, char *err, size_t err_sz) {
  static render_thread_t render; /* static: zeroed, and large (its cameras) */
  const app_options_t *o = a->opt;
  const int threaded =
      (o->cameras || o->eye) && !(o->lockstep && (o->frame_sync || !o->client_sync));
  render.cameras = o->cameras;
  render.eye = o->eye;
  render.eye_render = o->eye_render;
  render.noise = o->camera_noise;
  render.blur_px = o->camera_blur;
  render.exposure_ev = o->camera_exposure;
  render.scale = o->camera_scale;
  render.seed = o->cfg.seed;
  if (threaded
          ? render_thread_start(&render, a->sim, a->lcm, err, err_sz) != 0
          : cameras_open(&a->cams, a->sim, o->cameras, o->eye, o->eye_render, err, err_sz) != 0) {
    fprintf(stderr, "autodrive-sim: %s\n", err);
    return 1;
  }
  if (threaded) a->render = &render;
  cameras_set_effects(&a->cams, o->camera_noise, o->camera_blur, o->camera_exposure, o->cfg.seed);
  cameras_set_render_scale(&a->cams, o->camera_scale);
  a->camera_scale = o->camera_scale;
  a->cam_period_us = (int64_t)llround(1e6 / o->camera_fps);
  return -1;
}

/* The map's traffic lights and --allow-teleport on LCM, the window, the publish queue. */
static int app_build_links(app_t *a, char *err, size_t err_sz) {
  const app_options_t *o = a->opt;
  /* the map's traffic lights on LCM (none: NULL, nothing subscribed or published); the bus
   * filtered to their commands and --eye-sync's EYE_FRAME_DONE (subscribed below) */
  a->lights =
      traffic_lights_lcm_create(a->lcm, o->url, sim_traffic_lights(a->sim), !o->allow_teleport,
                                o->eye_sync ? AUTODRIVE_CH_EYE_FRAME_DONE : NULL, err, err_sz);
  if (!a->lights && err[0]) {
    fprintf(stderr, "autodrive-sim: %s\n", err);
    return 1;
  }
  if (o->allow_teleport && !(a->teleport = teleport_lcm_create(a->lcm, a->sim, err, err_sz))) {
    fprintf(stderr, "autodrive-sim: %s\n", err);
    return 1;
  }
  if (a->teleport) printf("teleport: obeying " AUTODRIVE_CH_SIM_TELEPORT " (--allow-teleport)\n");
  if (o->eye_sync && !(a->eye_sync = eye_sync_create(a->lcm, o->eye_sync_wait_s, err, err_sz))) {
    fprintf(stderr, "autodrive-sim: %s\n", err);
    return 1;
  }
  if (viewer_window_open(&a->viewer, a->sim, o->view, o->view_w, o->view_h, o->cfg.map_path, o->url,
                         o->cfg.open_ptys, o->hud_log, o->gamepad,
                         (viewer_window_look_t){o->view_scale, o->view_quality, o->bench,
                                                o->view_nice, o->camera_scale},
                         err, err_sz) != 0) {
    fprintf(stderr, "autodrive-sim: --view: %s\n", err);
    return 1;
  }
  if ((o->video || o->record_dir) &&
      run_recorder_start(&a->recorder, a->sim, o->video_camera, o->video, o->record_dir, o->url,
                         err, err_sz) != 0) {
    fprintf(stderr, "autodrive-sim: %s\n", err);
    return 1;
  }
  if (!(a->pubq = publish_queue_create(a->lcm, err, err_sz))) {
    fprintf(stderr, "autodrive-sim: %s\n", err);
    return 1;
  }
  return -1;
}

int app_build(app_t *a, const app_options_t *o) {
  memset(a, 0, sizeof *a);
  a->opt = o;
  char err[2048] = "";
  int rc = app_build_world(a, err, sizeof err);
  if (rc >= 0) return rc;
  app_stop_install();
  if ((rc = app_build_cameras(a, err, sizeof err)) >= 0) return rc;
  return app_build_links(a, err, sizeof err);
}

void app_print_setup(const app_t *a) {
  const app_options_t *o = a->opt;
  const sim_t *s = a->sim;
  for (int c = 1; c <= sim_cars(s); c++) {
    if (sim_nano_link(s, c)[0])
      printf(AUTODRIVE_VEHICLE_PREFIX "%d nano: %s\n", c, sim_nano_link(s, c));
    if (sim_lidar_link(s, c)[0])
      printf(AUTODRIVE_VEHICLE_PREFIX "%d lidar: %s\n", c, sim_lidar_link(s, c));
  }
  printf("map: %s, cars: %d, mode: %s, lcm: %s\n", o->cfg.map_path, o->cfg.cars,
         app_options_mode(o), o->url);
  const route_driver_t *route = sim_route(s);
  if (route)
    printf(
        "route %s: %s, %d points, %.2f m, lane half width %.3f m, throttle %.2f, lookahead "
        "%.2f m\n",
        route->name, route->path.loop ? "loop" : "open", route->path.n, route->path.length_m,
        route->half_width_m, route->speed, route->lookahead_m);
  traffic_lights_t *lights = sim_traffic_lights(a->sim);
  if (lights->n)
    printf("traffic lights: %d (%d conflicting pairs) on " AUTODRIVE_CH_TRAFFIC_LIGHT_STATE "\n",
           lights->n, lights->nconflicts);
  if (o->cfg.start)
    printf(AUTODRIVE_VEHICLE_DEFAULT " start (--start): x %.3f, y %.3f m, yaw %.1f deg\n",
           o->starts[0].x_m, o->starts[0].y_m, o->starts[0].yaw_deg);
  fflush(stdout);
}

void app_close(app_t *a) {
  if (a->pubq) publish_queue_destroy(a->pubq);
  traffic_lights_lcm_destroy(a->lights);
  teleport_lcm_destroy(a->teleport);
  eye_sync_destroy(a->eye_sync);
  run_recorder_stop(&a->recorder, NULL, 0);
  viewer_window_close(&a->viewer);
  if (a->render) render_thread_stop(a->render);
  cameras_close(&a->cams);
  sim_destroy(a->sim); /* removes the ptys' symlinks */
  if (a->truth_log) fclose(a->truth_log);
  if (a->lcm) lcm_destroy(a->lcm);
}
