/* The window's HUD text (hud_text.h). */
#include "hud_text.h"

#include <stdarg.h>
#include <stdio.h>

#include <autodrive_channels.h>

#include "protocol.h"
#include "traffic_lights.h"

typedef struct hud_cols {
  char *t, *v;
  size_t t_sz, v_sz, t_len, v_len;
} hud_cols_t;

/* One line: its title and its value (printf). */
static void hud_line(hud_cols_t *c, const char *title, const char *fmt, ...) {
  if (c->t_len >= c->t_sz || c->v_len >= c->v_sz) return;
  int n = snprintf(c->t + c->t_len, c->t_sz - c->t_len, "%s%s", c->t_len ? "\n" : "", title);
  if (n > 0) c->t_len += (size_t)n;
  if (c->v_len) c->v[c->v_len++] = '\n';
  if (c->v_len >= c->v_sz) return;
  va_list ap;
  va_start(ap, fmt);
  n = vsnprintf(c->v + c->v_len, c->v_sz - c->v_len, fmt, ap);
  va_end(ap);
  if (n > 0) c->v_len += (size_t)n;
  if (c->t_len > c->t_sz - 1) c->t_len = c->t_sz - 1;
  if (c->v_len > c->v_sz - 1) c->v_len = c->v_sz - 1;
}

static const char *hud_mode(uint8_t mode) {
  return mode == PROTOCOL_MODE_ENGAGED    ? "ENGAGED"
         : mode == PROTOCOL_MODE_FAILSAFE ? "FAILSAFE"
                                          : "disarmed";
}

static void hud_lamps(uint8_t lights, char *out, size_t n) {
  static const char *head[4] = {"off", "low", "high", "?"};
  static const char *ind[4] = {"", ", left", ", right", ", hazard"};
  snprintf(out, n, "head %s%s%s%s", head[lights & PROTOCOL_LIGHTS_HEAD_MASK],
           ind[(lights & PROTOCOL_LIGHTS_IND_MASK) >> PROTOCOL_LIGHTS_IND_SHIFT],
           lights & PROTOCOL_LIGHTS_TAIL ? ", brake" : "",
           lights & PROTOCOL_LIGHTS_REVERSE ? ", reverse" : "");
}

static void hud_car(hud_cols_t *c, sim_t *s, int car, const hud_extra_t *x) {
  sim_truth_t t;
  sim_get_truth(s, car, &t);
  protocol_state_t st;
  nano_core_state(sim_nano(s, car), &st, (uint32_t)sim_time_us(s));
  double acc[3], gyro[3];
  sim_imu(s, car, acc, gyro);
  char name[32], lamps[64];
  snprintf(name, sizeof name, AUTODRIVE_VEHICLE_PREFIX "%d", car);
  hud_lamps(st.lights, lamps, sizeof lamps);
  hud_line(c, name, "%s", hud_mode(st.mode));
  hud_line(c, "  speed", "%.2f m/s", t.vel_body_m_s[0]);
  hud_line(c, "  throttle cmd / applied", "%+.2f / %+.2f", t.command_throttle,
           st.throttle_milli / 1000.0);
  hud_line(c, "  steering cmd / applied", "%+.2f / %+.2f", t.command_steering,
           st.steering_milli / 1000.0);
  hud_line(c, "  encoders L / R", "%ld / %ld counts", (long)st.enc_counts[0],
           (long)st.enc_counts[1]);
  hud_line(c, "  IMU accel / yaw rate", "%.1f %.1f %.1f m/s2, %+.2f rad/s", acc[0], acc[1], acc[2],
           gyro[2]);
  hud_line(c, "  battery", "%.2f V", st.battery_mv / 1000.0);
  hud_line(c, "  lamps", "%s", lamps);
  if (x->lease) {
    char holder[96];
    control_status_lcm_holder(x->lease, car, x->now_s, holder, sizeof holder);
    hud_line(c, "  control lease", "%s", holder);
  }
}

void hud_text_build(sim_t *s, double rtf, const hud_extra_t *x, char *titles, size_t titles_sz,
                    char *values, size_t values_sz) {
  hud_cols_t c = {titles, values, titles_sz, values_sz, 0, 0};
  titles[0] = values[0] = 0;
  hud_line(&c, "sim time", "%.2f s", sim_time_us(s) * 1e-6);
  hud_line(&c, "real-time factor", "%.2f", rtf);
  if (x->recording) hud_line(&c, "recording", "%s", x->recording);
  if (x->driving) hud_line(&c, "driving", "%s", x->driving);
  const int n = sim_cars(s);
  for (int car = 1; car <= n && car <= HUD_TEXT_MAX_CARS; car++) hud_car(&c, s, car, x);
  if (n > HUD_TEXT_MAX_CARS) hud_line(&c, "more cars", "%d", n - HUD_TEXT_MAX_CARS);
  const traffic_lights_t *tl = sim_traffic_lights(s);
  static const char *state[4] = {"off", "RED", "YELLOW", "GREEN"};
  for (int i = 0; i < tl->n && i < 8; i++) {
    char title[32];
    snprintf(title, sizeof title, "traffic light %d", tl->light[i].id);
    const int k = tl->light[i].state;
    hud_line(&c, title, "%s", k >= 0 && k < 4 ? state[k] : "?");
  }
}
