/* The session's instance (sim_instance.h). */
#include "sim_instance.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <autodrive_channels.h>
#include <autodrive_instance_rule.h>

/* The port of AUTODRIVE_LCM_URL_DEFAULT ("udpm://239.255.76.67:7667?ttl=0" -> 7667). */
static int instance_default_port(void) {
  const char *colon = strrchr(AUTODRIVE_LCM_URL_DEFAULT, ':');
  return colon ? atoi(colon + 1) : 0;
}

int sim_instance_parse(const char *text) {
  if (!text || !*text) return 0;
  char *end = NULL;
  const long n = strtol(text, &end, 10);
  return (*end || n < 0 || n > AUTODRIVE_INSTANCE_MAX) ? -1 : (int)n;
}

int sim_instance_from_env(void) {
  const char *v = getenv(AUTODRIVE_INSTANCE_VARIABLE);
  const int n = sim_instance_parse(v);
  if (n < 0)
    fprintf(stderr,
            "autodrive-sim: %s='%s': expected an instance number in 0..%d (0, or unset, is the "
            "default)\n",
            AUTODRIVE_INSTANCE_VARIABLE, v, AUTODRIVE_INSTANCE_MAX);
  return n;
}

const char *sim_instance_url(int n, const char *url, char *out, size_t len) {
  static const char scheme[] = "udpm://";
  const size_t sl = sizeof scheme - 1;
  snprintf(out, len, "%s", url);
  if (n <= 0 || strncmp(url, scheme, sl) != 0) return out;
  const char *host_end = url + sl + strcspn(url + sl, ":?");
  const char *rest = host_end;
  int port = instance_default_port();
  if (*host_end == ':') {
    port = atoi(host_end + 1);
    rest = host_end + 1 + strcspn(host_end + 1, "?");
  }
  if (port != instance_default_port()) return out; /* an explicit other port: the user's */
  snprintf(out, len, "%.*s:%d%s", (int)(host_end - url), url,
           port + n * AUTODRIVE_INSTANCE_PORT_STEP, rest);
  return out;
}

const char *sim_instance_run_dir(int n, char *out, size_t len) {
  if (n > 0)
    snprintf(out, len, "%s-%d", AUTODRIVE_SIM_RUN_DIR_DEFAULT, n);
  else
    snprintf(out, len, "%s", AUTODRIVE_SIM_RUN_DIR_DEFAULT);
  return out;
}
