/* autodrive-sim --bench: one JSON line at exit (app.h): sim, wall and CPU time, the rtf, a
 * bare mj_step loop on the same model, the route driver's cross-track error, the lights. */
#include <math.h>
#include <stdio.h>
#include <time.h>

#include "app.h"
#include "route_driver.h"

/* The bare mj_step figures: from the paired blocks, else one bare loop after the run (a short
 * or paced run). */
static void bench_print_bare(const app_t *a, double sim_s, const bench_pairs_t *pairs) {
  if (pairs->n > 0) {
    bench_pairs_print_json(pairs, stdout);
    return;
  }
  const int bare_steps = (int)fmin(sim_s * 1000.0, 20000.0);
  double bare_cpu_s = 0.0;
  const double bare_s = sim_bare_mj_step_s(a->sim, bare_steps, &bare_cpu_s);
  printf(", \"bare_mj_step_rtf\": %.3f, \"bare_mj_step_rtf_cpu\": %.3f, \"bare_steps\": %d",
         bare_s > 0 ? bare_steps * 1e-3 / bare_s : 0.0,
         bare_cpu_s > 0 ? bare_steps * 1e-3 / bare_cpu_s : 0.0, bare_steps);
}

/* The overhead cameras' render times (and the cached-vs-full check), --eye-sync's waits. */
static void bench_print_cameras(const app_t *a) {
  if (a->render) { /* the render thread idle: it touches its statistics only with a frame */
    pthread_mutex_lock(&a->render->mu);
    while (a->render->queued > 0 && !a->render->failed) {
      pthread_mutex_unlock(&a->render->mu);
      const struct timespec ts = {0, 1000000};
      nanosleep(&ts, NULL);
      pthread_mutex_lock(&a->render->mu);
    }
  }
  render_stats_print_json(a->render ? &a->render->cams.stats : &a->cams.stats, stdout);
  if (a->render) pthread_mutex_unlock(&a->render->mu);
  if (a->eye_sync) {
    double waited_s = 0.0;
    long given_up = 0;
    const long waits = eye_sync_stats(a->eye_sync, &waited_s, &given_up);
    printf(", \"eye_sync_waits\": %ld, \"eye_sync_waited_s\": %.3f, \"eye_sync_give_ups\": %ld",
           waits, waited_s, given_up);
  }
}

void app_print_bench(const app_t *a, const app_run_stats_t *st, const bench_pairs_t *pairs) {
  sim_t *s = a->sim;
  const double sim_s = sim_time_us(s) * 1e-6, wall_s = st->wall_s, cpu_s = st->cpu_s;
  printf(
      "{\"cars\": %d, \"sim_s\": %.3f, \"wall_s\": %.3f, \"cpu_s\": %.3f, \"rtf\": %.3f, "
      "\"rtf_cpu\": %.3f, \"rtf_step_thread_cpu\": %.3f, \"steps\": %ld",
      sim_cars(s), sim_s, wall_s, cpu_s, wall_s > 0 ? sim_s / wall_s : 0.0,
      cpu_s > 0 ? sim_s / cpu_s : 0.0, st->step_cpu_s > 0 ? sim_s / st->step_cpu_s : 0.0,
      st->steps);
  bench_print_bare(a, sim_s, pairs);
  const route_driver_t *route = sim_route(s);
  if (route) {
    double rms, max;
    const long n = route_driver_stats(route, &rms, &max);
    printf(
        ", \"route\": \"%s\", \"route_done\": %s, \"route_length_m\": %.3f, "
        "\"route_samples\": %ld, \"route_cross_track_rms_m\": %.5f, "
        "\"route_cross_track_max_m\": %.5f",
        route->name, route->st.done ? "true" : "false", route->path.length_m, n, rms, max);
  }
  long refused = 0;
  const long commands = traffic_lights_lcm_commands(a->lights, &refused);
  printf(
      ", \"lights\": %d, \"light_commands\": %ld, \"light_commands_refused\": %ld, "
      "\"light_commands_unverified\": %ld",
      sim_traffic_lights(s)->n, commands, refused, traffic_lights_lcm_unverified(a->lights));
  bench_print_cameras(a);
  if (a->viewer.v) viewer_window_print_bench(&a->viewer, stdout); /* its drawing stopped */
  printf("}\n");
}
