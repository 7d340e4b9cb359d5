/* The simulator's world (sim.h): sim_create builds it from the parameter file and the map
 * (scene_load.c), binds every car (car_binding.c, car_setup.c), the late boxes, the traffic
 * lights and the route driver, and places the cars (car_placement.c); sim_destroy undoes it. */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "mjcf_gen.h"
#include "sim_internal.h"

/* --script route:NAME: the route driver of car 1, which starts at the route's start unless
 * --start says otherwise. */
static int sim_bind_route(sim_t *s, const sim_config_t *cfg, char *err, size_t err_sz) {
  if (!cfg->script) return 0;
  script_t sc;
  if (script_parse(&sc, cfg->script, err, err_sz) != 0) return -1;
  if (!sc.route) return 0;
  if (cfg->cars != 1) {
    snprintf(err, err_sz, "--script '%s': a route driver drives one car (--cars 1, got %d)",
             cfg->script, cfg->cars);
    return -1;
  }
  s->route = calloc(1, sizeof *s->route);
  if (!s->route) return sim_fail(err, err_sz, "%s%s", "out of memory", "");
  if (route_driver_init(s->route, s->m, sc.route_name, sc.throttle, sc.lookahead_m, sc.lane_shift,
                        err, err_sz) != 0) {
    free(s->route);
    s->route = NULL;
    return -1;
  }
  route_driver_set_laps_perturb(s->route, sc.laps, sc.perturb, cfg->seed);
  if (!s->has_start) {
    double yaw;
    route_driver_start(s->route, &s->start.x_m, &s->start.y_m, &yaw);
    s->start.yaw_deg = yaw * (180.0 / M_PI);
    s->has_start = 1;
  }
  return 0;
}

sim_t *sim_create(const sim_config_t *cfg, char *err, size_t err_sz) {
  if (cfg->cars < 1 || cfg->cars > SIM_MAX_CARS) {
    snprintf(err, err_sz, "--cars %d: must be 1..%d", cfg->cars, SIM_MAX_CARS);
    return NULL;
  }
  if (cfg->late_boxes < 0 || cfg->late_boxes > SCN_MAX_LATE_BOXES) {
    snprintf(err, err_sz, "--late-box: at most %d boxes (got %d)", SCN_MAX_LATE_BOXES,
             cfg->late_boxes);
    return NULL;
  }
  if (cfg->distractors < 0 || cfg->distractors > SIM_MAX_DISTRACTORS) {
    snprintf(err, err_sz, "--distractors %d: must be 0..%d", cfg->distractors, SIM_MAX_DISTRACTORS);
    return NULL;
  }
  sim_t *s = calloc(1, sizeof *s);
  if (!s) return NULL;
  if (cfg->start) {
    s->has_start = 1;
    s->start = *cfg->start;
  }
  s->nbox = cfg->late_boxes;
  for (int k = 0; k < s->nbox; k++) s->box[k] = cfg->late_box[k];
  s->seed = cfg->seed;
  s->lidar = cfg->lidar;
  s->lidar_on_request = cfg->lidar_on_request;
  s->lidar_rays = cfg->lidar_rays;
  if (cfg->script) {
    if (strlen(cfg->script) >= sizeof s->script_spec) {
      snprintf(err, err_sz, "--script '%s': longer than %zu characters", cfg->script,
               sizeof s->script_spec - 1);
      goto fail;
    }
    snprintf(s->script_spec, sizeof s->script_spec, "%s", cfg->script);
  }
  if (vehicle_params_load(cfg->params_path, &s->p, err, err_sz) != 0) goto fail;
  if (cfg->tyre_model >= 0) s->p.tyre_model_paper = cfg->tyre_model;
  s->tyre_paper = s->p.tyre_model_paper;
  s->host_io_period_steps = cfg->host_io_period_ms > 1 ? cfg->host_io_period_ms : 1;
  if (mkdir(cfg->run_dir, 0755) != 0 && errno != EEXIST) {
    snprintf(err, err_sz, "run dir '%s': %s", cfg->run_dir, strerror(errno));
    goto fail;
  }
  /* the generated scene lives in a private dir so that parallel sims do not collide */
  snprintf(s->scene_dir, sizeof s->scene_dir, "%s/scene-XXXXXX", cfg->run_dir);
  if (!mkdtemp(s->scene_dir)) {
    snprintf(err, err_sz, "scene dir in '%s': %s", cfg->run_dir, strerror(errno));
    s->scene_dir[0] = '\0';
    goto fail;
  }
  snprintf(s->scene_path, sizeof s->scene_path, "%s/scene.xml", s->scene_dir);
  s->ntag_files = cfg->cars;
  if (sim_load_model(s, cfg, err, err_sz) != 0) goto fail;
  s->ncars = cfg->cars;
  s->car = calloc((size_t)cfg->cars, sizeof *s->car);
  s->geom_tyre = malloc(sizeof(int) * (size_t)s->m->ngeom);
  if (!s->car || !s->geom_tyre) goto fail;
  for (int g = 0; g < s->m->ngeom; g++) s->geom_tyre[g] = -1;
  const vehicle_params_t *p = &s->p;
  s->lon = (tyre_curve_t){p->long_extremum[0], p->long_extremum[1], p->long_asymptote[0],
                          p->long_asymptote[1]};
  s->lat = (tyre_curve_t){p->lat_extremum[0], p->lat_extremum[1], p->lat_asymptote[0],
                          p->lat_asymptote[1]};
  s->motor =
      (motor_model_t){p->motor_stall_torque_nm, p->motor_noload_speed_rad_s, p->motor_nominal_v};
  for (int i = 0; i < cfg->cars; i++) {
    s->car[i].index = i + 1;
    if (sim_bind_car(s, &s->car[i], err, err_sz) != 0) goto fail;
  }
  if (sim_bind_late_boxes(s, err, err_sz) != 0) goto fail;
  if (tl_load(&s->tl, s->mv ? s->mv : s->m, err, err_sz) != 0) goto fail;
  if (sim_bind_route(s, cfg, err, err_sz) != 0) goto fail;
  if (sim_place_cars(s, err, err_sz) != 0) goto fail;
  if (sim_place_distractors(s, err, err_sz) != 0) goto fail;
  mj_forward(s->m, s->d);
  for (int i = 0; i < cfg->cars; i++)
    if (sim_setup_car(s, cfg, &s->car[i], err, err_sz) != 0) goto fail;
  return s;
fail:
  sim_destroy(s);
  return NULL;
}

void sim_destroy(sim_t *s) {
  if (!s) return;
  for (int i = 0; s->car && i < s->ncars; i++) {
    if (s->car[i].has_pty) ptylink_close(&s->car[i].pty);
    sim_rplidar_destroy(s->car[i].rplidar);
    sim_lidar_destroy(s->car[i].lidar);
  }
  if (s->d) mj_deleteData(s->d);
  if (s->m) mj_deleteModel(s->m);
  if (s->dv) mj_deleteData(s->dv);
  if (s->mv) mj_deleteModel(s->mv);
  if (s->route) route_driver_free(s->route);
  free(s->route);
  if (s->scene_dir[0]) { /* the generated scene and tag textures */
    char path[700];
    snprintf(path, sizeof path, "%s/scene.xml", s->scene_dir);
    unlink(path);
    snprintf(path, sizeof path, "%s/scene_physics.xml", s->scene_dir);
    unlink(path);
    snprintf(path, sizeof path, "%s/map_physics.xml", s->scene_dir);
    unlink(path);
    for (int i = 1; i <= s->ntag_files; i++) {
      snprintf(path, sizeof path, "%s/tag36h11_%d.png", s->scene_dir, mjcf_gen_tag_id(i));
      unlink(path);
    }
    rmdir(s->scene_dir);
  }
  free(s->geom_tyre);
  free(s->car);
  free(s);
}
