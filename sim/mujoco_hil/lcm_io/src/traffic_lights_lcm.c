/* Traffic lights on LCM (see traffic_lights_lcm.h). */
#include "traffic_lights_lcm.h"

#include "lcm_receive_filter.h"

#include <autodrive_channels.h>
#include <autodrive_traffic_light_command_t.h>
#include <autodrive_traffic_light_state_t.h>
#include <poll.h>
#include <stdio.h>
#include <stdlib.h>

struct traffic_lights_lcm {
  lcm_t *lcm;
  traffic_lights_t *t;
  autodrive_traffic_light_command_t_subscription_t *sub;
  int64_t now_us;      /* sim time of the poll in progress */
  int64_t next_all_us; /* next 10 Hz publication of every light */
  long commands, refused;
};

static void traffic_lights_lcm_send(traffic_lights_lcm_t *k, const tl_light_t *l, int64_t now_us) {
  autodrive_traffic_light_state_t msg;
  msg.utime = now_us;
  msg.light_id = l->id;
  msg.state = (int8_t)l->state;
  msg.time_remaining_s = (float)l->remaining_s;
  autodrive_traffic_light_state_t_publish(k->lcm, AUTODRIVE_CH_TRAFFIC_LIGHT_STATE, &msg);
}

static void traffic_lights_lcm_on_command(const lcm_recv_buf_t *rbuf, const char *channel,
                                          const autodrive_traffic_light_command_t *msg,
                                          void *user) {
  (void)rbuf;
  (void)channel;
  traffic_lights_lcm_t *k = user;
  char why[256];
  k->commands++;
  if (tl_command(k->t, msg->light_id, msg->state, msg->duration_s, k->now_us, why, sizeof why) !=
      0) {
    k->refused++;
    fprintf(stderr,
            "[autodrive-sim] " AUTODRIVE_CH_TRAFFIC_LIGHT_COMMAND " refused at t = %.3f s: %s\n",
            k->now_us * 1e-6, why);
    return;
  }
  tl_update(k->t, k->now_us); /* the light shows it now: publish its new state at once */
  for (int i = 0; i < k->t->n; i++)
    if (k->t->light[i].changed) traffic_lights_lcm_send(k, &k->t->light[i], k->now_us);
}

traffic_lights_lcm_t *traffic_lights_lcm_create(lcm_t *lcm, const char *url, traffic_lights_t *t,
                                                int filter_bus, char *err, size_t err_sz) {
  if (t->n == 0) return NULL;
  traffic_lights_lcm_t *k = calloc(1, sizeof *k);
  if (!k) {
    snprintf(err, err_sz, "out of memory");
    return NULL;
  }
  k->lcm = lcm;
  k->t = t;
  k->sub = autodrive_traffic_light_command_t_subscribe(lcm, AUTODRIVE_CH_TRAFFIC_LIGHT_COMMAND,
                                                       traffic_lights_lcm_on_command, k);
  if (!k->sub) {
    snprintf(err, err_sz, "cannot subscribe to " AUTODRIVE_CH_TRAFFIC_LIGHT_COMMAND);
    free(k);
    return NULL;
  }
  char why[256];
  /* The kernel filter keeps one channel only: a simulator that also obeys SIM_TELEPORT (or any
   * other subscription) must read the whole bus. */
  if (filter_bus && lcm_receive_filter_keep_only(lcm, url, AUTODRIVE_CH_TRAFFIC_LIGHT_COMMAND, why,
                                                 sizeof why) < 0)
    fprintf(stderr, "[autodrive-sim] %s: receiving every message on the bus instead\n", why);
  return k;
}

void traffic_lights_lcm_destroy(traffic_lights_lcm_t *k) {
  if (!k) return;
  autodrive_traffic_light_command_t_unsubscribe(k->lcm, k->sub);
  free(k);
}

void traffic_lights_lcm_poll(traffic_lights_lcm_t *k, int64_t now_us) {
  if (!k) return;
  k->now_us = now_us;
  struct pollfd p = {lcm_get_fileno(k->lcm), POLLIN, 0};
  while (poll(&p, 1, 0) > 0 && (p.revents & POLLIN))
    if (lcm_handle(k->lcm) != 0) break;
}

void traffic_lights_lcm_publish(traffic_lights_lcm_t *k, int64_t now_us) {
  if (!k) return;
  const int all = now_us >= k->next_all_us;
  if (all) k->next_all_us = now_us + TRAFFIC_LIGHTS_LCM_STATE_PERIOD_US;
  for (int i = 0; i < k->t->n; i++)
    if (all || k->t->light[i].changed) traffic_lights_lcm_send(k, &k->t->light[i], now_us);
}

long traffic_lights_lcm_commands(const traffic_lights_lcm_t *k, long *refused) {
  if (refused) *refused = k ? k->refused : 0;
  return k ? k->commands : 0;
}
