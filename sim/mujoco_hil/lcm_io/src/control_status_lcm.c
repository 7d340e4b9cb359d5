/* <VEH>_CONTROL for the HUD (control_status_lcm.h). */
#include "control_status_lcm.h"

#include <autodrive_channels.h>
#include <autodrive_control_status_t.h>
#include <autodrive_vehicle_command_t.h>
#include <lcm/lcm.h>
#include <poll.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef struct control_car {
  control_status_lcm_t *owner;
  autodrive_control_status_t_subscription_t *sub;
  char holder[64];
  int authority;
  double heard_s; /* [s] wall of the last message, < 0 never */
} control_car_t;

struct control_status_lcm {
  lcm_t *lcm;
  int ncars;
  double now_s;
  control_car_t car[CONTROL_STATUS_LCM_MAX_CARS];
};

static void control_on_status(const lcm_recv_buf_t *rbuf, const char *channel,
                              const autodrive_control_status_t *msg, void *user) {
  (void)rbuf;
  (void)channel;
  control_car_t *k = user;
  snprintf(k->holder, sizeof k->holder, "%s", msg->holder ? msg->holder : "");
  k->authority = msg->holder_authority;
  k->heard_s = k->owner->now_s;
}

control_status_lcm_t *control_status_lcm_create(const char *url, int cars, char *err,
                                                size_t err_sz) {
  control_status_lcm_t *c = calloc(1, sizeof *c);
  if (!c || !(c->lcm = lcm_create(url))) {
    snprintf(err, err_sz, "cannot open LCM url '%s' for the control lease", url);
    free(c);
    return NULL;
  }
  c->ncars = cars < CONTROL_STATUS_LCM_MAX_CARS ? cars : CONTROL_STATUS_LCM_MAX_CARS;
  for (int i = 0; i < c->ncars; i++) {
    char ch[32];
    snprintf(ch, sizeof ch, AUTODRIVE_VEHICLE_PREFIX "%d" AUTODRIVE_CH_CONTROL_SUFFIX, i + 1);
    c->car[i].owner = c;
    c->car[i].heard_s = -1;
    c->car[i].sub = autodrive_control_status_t_subscribe(c->lcm, ch, control_on_status, &c->car[i]);
    if (!c->car[i].sub) {
      snprintf(err, err_sz, "cannot subscribe to %s", ch);
      control_status_lcm_destroy(c);
      return NULL;
    }
  }
  return c;
}

void control_status_lcm_destroy(control_status_lcm_t *c) {
  if (!c) return;
  for (int i = 0; i < c->ncars; i++)
    if (c->car[i].sub) autodrive_control_status_t_unsubscribe(c->lcm, c->car[i].sub);
  lcm_destroy(c->lcm);
  free(c);
}

void control_status_lcm_poll(control_status_lcm_t *c, double now_s) {
  if (!c) return;
  c->now_s = now_s;
  struct pollfd p = {lcm_get_fileno(c->lcm), POLLIN, 0};
  while (poll(&p, 1, 0) > 0 && (p.revents & POLLIN))
    if (lcm_handle(c->lcm) != 0) break;
}

void control_status_lcm_holder(const control_status_lcm_t *c, int car, double now_s, char *out,
                               size_t n) {
  const control_car_t *k = c && car >= 1 && car <= c->ncars ? &c->car[car - 1] : NULL;
  if (!k || k->heard_s < 0 || now_s - k->heard_s > CONTROL_STATUS_LCM_STALE_S) {
    snprintf(out, n, "- (no %s from a runtime)", AUTODRIVE_CH_CONTROL_SUFFIX + 1);
    return;
  }
  if (!k->holder[0]) {
    snprintf(out, n, "free");
    return;
  }
  snprintf(out, n, "%s (%s)", k->holder,
           k->authority == AUTODRIVE_VEHICLE_COMMAND_T_AUTHORITY_PERSON ? "person" : "machine");
}
