/* The stop request of autodrive-sim (app_common.h). */
#include <signal.h>
#include <string.h>

#include "app_common.h"

static volatile sig_atomic_t app_stop = 0;

static void app_on_signal(int sig) {
  (void)sig;
  app_stop = 1;
}

void app_stop_install(void) {
  struct sigaction sa;
  memset(&sa, 0, sizeof sa);
  sa.sa_handler = app_on_signal;
  sigaction(SIGINT, &sa, NULL);
  sigaction(SIGTERM, &sa, NULL);
  signal(SIGPIPE, SIG_IGN);
}

int app_stop_requested(void) {
  return app_stop;
}
