/* autodrive-sim: the MuJoCo 2.2 HIL simulator of Nigel. See --help and README.md. */
#include "app.h"
#include "options.h"

int main(int argc, char **argv) {
  static app_options_t opt; /* static: large, and the world's config points into it */
  int rc = app_options_parse(&opt, argc, argv);
  if (rc >= 0) return rc;
  static app_t app; /* static: large (its cameras) */
  rc = app_build(&app, &opt);
  if (rc < 0) {
    app_print_setup(&app);
    app_run_stats_t stats;
    rc = app_run(&app, &stats);
  }
  app_close(&app);
  return rc;
}
