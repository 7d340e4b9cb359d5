/* Scripted driver (see script.h). */
#include "script.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define SCRIPT_ARM_FRAMES 3 /* engaged=0 frames before engaging */

static int script_num(const char *spec, const char *key, const char *val, double lo, double hi,
                      double *out, char *err, size_t err_sz) {
  char *end;
  errno = 0;
  double v = strtod(val, &end);
  if (end == val || *end != '\0' || errno || !isfinite(v) || v < lo || v > hi) {
    snprintf(err, err_sz, "--script '%s': %s='%s' is not a number in [%g, %g]", spec, key, val, lo,
             hi);
    return -1;
  }
  *out = v;
  return 0;
}

int script_parse(script_t *s, const char *spec, char *err, size_t err_sz) {
  memset(s, 0, sizeof *s);
  s->stop_us = -1;
  const char *prefix = "constant:", *route = "route:";
  char buf[256];
  char *save = NULL, *tok;
  if (strncmp(spec, prefix, strlen(prefix)) == 0) {
    snprintf(buf, sizeof buf, "%s", spec + strlen(prefix));
    tok = strtok_r(buf, ",", &save);
  } else if (strncmp(spec, route, strlen(route)) == 0) {
    snprintf(buf, sizeof buf, "%s", spec + strlen(route));
    tok = strtok_r(buf, ",", &save);
    if (!tok || strchr(tok, '=') || strlen(tok) >= sizeof s->route_name) {
      snprintf(err, err_sz,
               "--script '%s': expected "
               "route:NAME[,speed=F][,start=s][,lookahead=m][,laps=N][,perturb=A][,lane_shift=K]",
               spec);
      return -1;
    }
    s->route = 1;
    snprintf(s->route_name, sizeof s->route_name, "%s", tok);
    s->throttle = SCRIPT_ROUTE_SPEED_DEFAULT;
    s->lookahead_m = SCRIPT_ROUTE_LOOKAHEAD_DEFAULT_M;
    s->laps = 1;
    tok = strtok_r(NULL, ",", &save);
  } else {
    snprintf(err, err_sz,
             "--script '%s': unknown kind (expected 'constant:key=value,...' or "
             "'route:NAME,key=value,...')",
             spec);
    return -1;
  }
  double start = 0.0, stop = -1.0;
  for (; tok; tok = strtok_r(NULL, ",", &save)) {
    char *eq = strchr(tok, '=');
    if (!eq) {
      snprintf(err, err_sz, "--script '%s': '%s' is not key=value", spec, tok);
      return -1;
    }
    *eq = '\0';
    const char *val = eq + 1;
    int rc;
    if (s->route && strcmp(tok, "speed") == 0) {
      rc = script_num(spec, tok, val, 0, 1, &s->throttle, err, err_sz);
    } else if (s->route && strcmp(tok, "lookahead") == 0) {
      rc = script_num(spec, tok, val, 0.02, 5, &s->lookahead_m, err, err_sz);
    } else if (s->route && strcmp(tok, "laps") == 0) {
      double laps = 1;
      rc = script_num(spec, tok, val, 1, 1000, &laps, err, err_sz);
      if (rc == 0 && laps != floor(laps)) {
        snprintf(err, err_sz, "--script '%s': laps='%s' is not a whole number", spec, val);
        rc = -1;
      }
      s->laps = (int)laps;
    } else if (s->route && strcmp(tok, "perturb") == 0) {
      rc = script_num(spec, tok, val, 0, 1, &s->perturb, err, err_sz);
    } else if (s->route && strcmp(tok, "lane_shift") == 0) {
      double k = 0;
      rc = script_num(spec, tok, val, -SCRIPT_ROUTE_LANE_SHIFT_MAX, SCRIPT_ROUTE_LANE_SHIFT_MAX, &k,
                      err, err_sz);
      if (rc == 0 && k != floor(k)) {
        snprintf(err, err_sz, "--script '%s': lane_shift='%s' is not a whole number", spec, val);
        rc = -1;
      }
      s->lane_shift = (int)k;
    } else if (!s->route && strcmp(tok, "throttle") == 0) {
      rc = script_num(spec, tok, val, -1, 1, &s->throttle, err, err_sz);
    } else if (!s->route && strcmp(tok, "steering") == 0) {
      rc = script_num(spec, tok, val, -1, 1, &s->steering, err, err_sz);
    } else if (strcmp(tok, "start") == 0) {
      rc = script_num(spec, tok, val, 0, 1e6, &start, err, err_sz);
    } else if (strcmp(tok, "stop_after") == 0) {
      rc = script_num(spec, tok, val, 0, 1e6, &stop, err, err_sz);
    } else {
      snprintf(err, err_sz, "--script '%s': unknown key '%s' (%s)", spec, tok,
               s->route ? "speed, start, stop_after, lookahead, laps, perturb, lane_shift"
                        : "throttle, steering, start, stop_after");
      return -1;
    }
    if (rc) return -1;
  }
  s->start_us = (int64_t)llround(start * 1e6);
  s->stop_us = stop < 0 ? -1 : (int64_t)llround(stop * 1e6);
  s->next_us = s->start_us;
  return 0;
}

size_t script_poll(script_t *s, int64_t now_us, uint8_t *out, size_t cap) {
  if (now_us < s->next_us || (s->stop_us >= 0 && now_us >= s->stop_us)) return 0;
  s->next_us += SCRIPT_PERIOD_US;
  const int engaged = s->sent >= SCRIPT_ARM_FRAMES;
  protocol_command_t c = {0};
  c.seq = s->cmd_seq++;
  c.throttle_milli = engaged ? (int16_t)lround(s->throttle * PROTOCOL_MILLI) : 0;
  c.steering_milli = engaged ? (int16_t)lround(s->steering * PROTOCOL_MILLI) : 0;
  c.flags = engaged ? PROTOCOL_CMD_ENGAGED : 0;
  uint8_t payload[PROTOCOL_LEN_COMMAND];
  protocol_command_pack(&c, payload);
  s->sent++;
  return protocol_frame_encode(PROTOCOL_ID_COMMAND, s->frame_seq++, payload, PROTOCOL_LEN_COMMAND,
                               out, cap);
}
