/* Traffic lights on LCM (see traffic_lights_lcm.h). */
#include "traffic_lights_lcm.h"

#include "lcm_receive_filter.h"

#include <autodrive_channels.h>
#include <autodrive_traffic_light_command_t.h>
#include <autodrive_traffic_light_state_t.h>
#include <autodrive_v2x/v2x_auth.h>
#include <poll.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

/* The simulator signs its light states as the lights' controller (SIM.cert) and obeys only
 * commands signed by an scm, fresh on its own clock (sim time). */
#define SIM_IDENTITY "SIM"
#define MAX_MESSAGE_BYTES 512
#define REFUSAL_LOG_LINES 5 /* per 10 s of sim time, then a count */

struct traffic_lights_lcm {
  lcm_t *lcm;
  traffic_lights_t *t;
  autodrive_traffic_light_command_t_subscription_t *sub;
  int64_t now_us;      /* sim time of the poll in progress */
  int64_t next_all_us; /* next 10 Hz publication of every light */
  long commands, refused;
  v2x_signer_t *signer;
  v2x_verifier_t *verifier;
  long unverified;                       /* commands dropped by the envelope check */
  int64_t log_window_us, next_reload_us; /* sim time */
  int logged_in_window;
};

static void traffic_lights_lcm_send(traffic_lights_lcm_t *k, const tl_light_t *l, int64_t now_us) {
  autodrive_traffic_light_state_t msg;
  msg.utime = now_us;
  msg.light_id = l->id;
  msg.state = (int8_t)l->state;
  msg.time_remaining_s = (float)l->remaining_s;
  uint8_t payload[MAX_MESSAGE_BYTES], envelope[V2X_MAX_ENVELOPE_BYTES];
  msg.auth_len = 0;
  msg.auth = envelope; /* empty, but never NULL: LCM memcpy's the array, even of 0 bytes */
  const int n = autodrive_traffic_light_state_t_encode(payload, 0, sizeof payload, &msg);
  if (n <= 0) return;
  const size_t len = v2x_sign(k->signer, AUTODRIVE_CH_TRAFFIC_LIGHT_STATE, payload, (size_t)n,
                              now_us, envelope, sizeof envelope);
  msg.auth_len = (int16_t)len;
  msg.auth = envelope;
  autodrive_traffic_light_state_t_publish(k->lcm, AUTODRIVE_CH_TRAFFIC_LIGHT_STATE, &msg);
}

/* 1 when msg carries a valid scm envelope fresh at k->now_us; else counts and logs (at most
 * REFUSAL_LOG_LINES per 10 s of sim time) naming the sender and the reason. */
static int traffic_lights_lcm_verified(traffic_lights_lcm_t *k,
                                       const autodrive_traffic_light_command_t *msg) {
  if (k->now_us >= k->next_reload_us) { /* the revocation list (a stat), 4 times a second */
    char err[512];
    if (v2x_verifier_reload(k->verifier, err, sizeof err) != 0)
      fprintf(stderr, "[autodrive-sim] %s (the list held so far stays in force)\n", err);
    k->next_reload_us = k->now_us + 250000;
  }
  autodrive_traffic_light_command_t bare = *msg;
  uint8_t payload[MAX_MESSAGE_BYTES], no_auth[1] = {0};
  bare.auth_len = 0;
  bare.auth = no_auth; /* empty, but never NULL: LCM memcpy's the array, even of 0 bytes */
  const int n = autodrive_traffic_light_command_t_encode(payload, 0, sizeof payload, &bare);
  v2x_sender_t sender;
  const v2x_reason_t r =
      n <= 0 ? V2X_MALFORMED_ENVELOPE
             : v2x_verify(k->verifier, AUTODRIVE_CH_TRAFFIC_LIGHT_COMMAND, payload, (size_t)n,
                          msg->auth, (size_t)(msg->auth_len > 0 ? msg->auth_len : 0),
                          v2x_role_mask(AUTODRIVE_CH_TRAFFIC_LIGHT_COMMAND_SIGNED_BY), NULL,
                          k->now_us, (int64_t)time(NULL), &sender);
  if (r == V2X_OK) return 1;
  k->unverified++;
  if (k->now_us - k->log_window_us >= 10000000) {
    if (k->logged_in_window >= REFUSAL_LOG_LINES)
      fprintf(stderr,
              "[autodrive-sim] " AUTODRIVE_CH_TRAFFIC_LIGHT_COMMAND
              ": %ld dropped in all (unsigned, forged, stale, wrong role...)\n",
              k->unverified);
    k->log_window_us = k->now_us;
    k->logged_in_window = 0;
  }
  if (k->logged_in_window++ < REFUSAL_LOG_LINES)
    fprintf(stderr,
            "[autodrive-sim] " AUTODRIVE_CH_TRAFFIC_LIGHT_COMMAND
            " dropped at t = %.3f s: from %s%s (serial %llu): %s\n",
            k->now_us * 1e-6, sender.name[0] ? "sender " : "an unknown sender", sender.name,
            (unsigned long long)sender.serial, v2x_reason_name(r));
  return 0;
}

static void traffic_lights_lcm_on_command(const lcm_recv_buf_t *rbuf, const char *channel,
                                          const autodrive_traffic_light_command_t *msg,
                                          void *user) {
  (void)rbuf;
  (void)channel;
  traffic_lights_lcm_t *k = user;
  char why[256];
  if (!traffic_lights_lcm_verified(k, msg)) return;
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
                                                int filter_bus, const char *also_keep, char *err,
                                                size_t err_sz) {
  if (t->n == 0) return NULL;
  traffic_lights_lcm_t *k = calloc(1, sizeof *k);
  if (!k) {
    snprintf(err, err_sz, "out of memory");
    return NULL;
  }
  k->lcm = lcm;
  k->t = t;
  char why_key[512];
  k->signer = v2x_signer_load(NULL, SIM_IDENTITY, why_key, sizeof why_key);
  if (!k->signer) {
    snprintf(err, err_sz, "cannot sign the light states as " SIM_IDENTITY ": %s", why_key);
    free(k);
    return NULL;
  }
  k->verifier = v2x_verifier_create(NULL, why_key, sizeof why_key);
  if (!k->verifier) {
    snprintf(err, err_sz, "cannot check light commands: %s", why_key);
    v2x_signer_destroy(k->signer);
    free(k);
    return NULL;
  }
  k->sub = autodrive_traffic_light_command_t_subscribe(lcm, AUTODRIVE_CH_TRAFFIC_LIGHT_COMMAND,
                                                       traffic_lights_lcm_on_command, k);
  if (!k->sub) {
    snprintf(err, err_sz, "cannot subscribe to " AUTODRIVE_CH_TRAFFIC_LIGHT_COMMAND);
    traffic_lights_lcm_destroy(k);
    return NULL;
  }
  char why[256];
  /* The kernel filter keeps one channel only: a simulator that also obeys SIM_TELEPORT (or any
   * other subscription) must read the whole bus. */
  const char *keep[2] = {AUTODRIVE_CH_TRAFFIC_LIGHT_COMMAND, also_keep};
  if (filter_bus && lcm_receive_filter_keep(lcm, url, keep, also_keep ? 2 : 1, why, sizeof why) < 0)
    fprintf(stderr, "[autodrive-sim] %s: receiving every message on the bus instead\n", why);
  return k;
}

void traffic_lights_lcm_destroy(traffic_lights_lcm_t *k) {
  if (!k) return;
  if (k->sub) autodrive_traffic_light_command_t_unsubscribe(k->lcm, k->sub);
  v2x_signer_destroy(k->signer);
  v2x_verifier_destroy(k->verifier);
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

long traffic_lights_lcm_unverified(const traffic_lights_lcm_t *k) {
  return k ? k->unverified : 0;
}
