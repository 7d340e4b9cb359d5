/* SIM_TELEPORT on LCM (see teleport_lcm.h). */
#include "teleport_lcm.h"

#include <autodrive_channels.h>
#include <autodrive_pose2d_t.h>
#include <poll.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

struct teleport_lcm {
  lcm_t *lcm;
  sim_t *s;
  autodrive_pose2d_t_subscription_t *sub;
  long done, refused;
};

static void teleport_on_request(const lcm_recv_buf_t *rbuf, const char *channel,
                                const autodrive_pose2d_t *msg, void *user) {
  (void)rbuf;
  (void)channel;
  teleport_lcm_t *k = user;
  const size_t n = strlen(AUTODRIVE_VEHICLE_PREFIX);
  char *end = NULL;
  const long car = strncmp(msg->vehicle, AUTODRIVE_VEHICLE_PREFIX, n) == 0
                       ? strtol(msg->vehicle + n, &end, 10)
                       : -1;
  char err[640] = "";
  if (car < 1 || !end || *end != '\0') {
    snprintf(err, sizeof err, "vehicle '%s' is not " AUTODRIVE_VEHICLE_PREFIX "<i>", msg->vehicle);
  } else if (sim_teleport(k->s, (int)car, msg->x_m, msg->y_m, msg->yaw_rad, err, sizeof err) == 0) {
    k->done++;
    printf("[autodrive-sim] " AUTODRIVE_CH_SIM_TELEPORT
           ": %s to x %.3f, y %.3f m, yaw %.3f rad "
           "at t = %.3f s\n",
           msg->vehicle, msg->x_m, msg->y_m, msg->yaw_rad, sim_time_us(k->s) * 1e-6);
    fflush(stdout);
    return;
  }
  k->refused++;
  fprintf(stderr, "[autodrive-sim] " AUTODRIVE_CH_SIM_TELEPORT " refused at t = %.3f s: %s: %s\n",
          sim_time_us(k->s) * 1e-6, msg->vehicle, err);
}

teleport_lcm_t *teleport_lcm_create(lcm_t *lcm, sim_t *s, char *err, size_t err_sz) {
  teleport_lcm_t *k = calloc(1, sizeof *k);
  if (!k) {
    snprintf(err, err_sz, "out of memory");
    return NULL;
  }
  k->lcm = lcm;
  k->s = s;
  k->sub = autodrive_pose2d_t_subscribe(lcm, AUTODRIVE_CH_SIM_TELEPORT, teleport_on_request, k);
  if (!k->sub) {
    snprintf(err, err_sz, "cannot subscribe to " AUTODRIVE_CH_SIM_TELEPORT);
    free(k);
    return NULL;
  }
  return k;
}

void teleport_lcm_destroy(teleport_lcm_t *k) {
  if (!k) return;
  autodrive_pose2d_t_unsubscribe(k->lcm, k->sub);
  free(k);
}

void teleport_lcm_poll(teleport_lcm_t *k) {
  if (!k) return;
  struct pollfd p = {lcm_get_fileno(k->lcm), POLLIN, 0};
  while (poll(&p, 1, 0) > 0 && (p.revents & POLLIN))
    if (lcm_handle(k->lcm) != 0) break;
}

long teleport_lcm_count(const teleport_lcm_t *k, long *refused) {
  if (refused) *refused = k ? k->refused : 0;
  return k ? k->done : 0;
}
