/* The session's instance for the simulator (two users on one machine), read in this one place
 * for C: --instance N or the environment variable AUTODRIVE_INSTANCE (0..AUTODRIVE_INSTANCE_MAX,
 * unset: 0). Instance N > 0 moves the LCM URL on the default port to that port
 * + N * AUTODRIVE_INSTANCE_PORT_STEP and the default run dir to <run dir>-N; the rule is
 * lcm_types/channels.yaml's `instances` (C++: <autodrive/instance.hpp>; Python:
 * autodrive.core.settings.instance()). */
#ifndef SIM_APP_INSTANCE_H
#define SIM_APP_INSTANCE_H

#include <stddef.h>

/* The instance number of text (NULL or "": 0); -1 when it is no number in range. */
int sim_instance_parse(const char *text);
/* The instance of the environment, or -1 (the message, naming the variable, is on stderr). */
int sim_instance_from_env(void);
/* url moved to instance n into out (len bytes): a udpm:// URL on the default port gets the
 * instance's port; any other URL is copied unchanged. Returns out. */
const char *sim_instance_url(int n, const char *url, char *out, size_t len);
/* The default run dir of instance n into out: AUTODRIVE_SIM_RUN_DIR_DEFAULT, "-n" for n > 0. */
const char *sim_instance_run_dir(int n, char *out, size_t len);

#endif
