/* Table-driven loader of the vehicle parameter file (see vehicle_params.h). */
#include "vehicle_params.h"

#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef struct vehicle_params_key {
  const char *name;
  size_t offset; /* into vehicle_params_t */
  int count;     /* numbers expected; 0 = the tyre model word */
  int positive;  /* 1: every value must be > 0 */
} vehicle_params_key_t;

#define K(field, n, pos) \
  { #field, offsetof(vehicle_params_t, field), n, pos }
static const vehicle_params_key_t vehicle_params_keys[] = {
    K(mass_kg, 1, 1),
    K(yaw_inertia_kg_m2, 1, 1),
    K(roll_pitch_inertia_kg_m2, 2, 1),
    K(wheelbase_m, 1, 1),
    K(track_m, 1, 1),
    K(wheel_radius_m, 1, 1),
    K(wheel_width_m, 1, 1),
    K(wheel_mass_kg, 1, 1),
    K(com_to_front_m, 1, 1),
    K(com_height_m, 1, 0),
    K(chassis_size_m, 3, 1),
    K(chassis_offset_m, 3, 0),
    K(knuckle_armature_kg_m2, 1, 1),
    K(wheel_armature_kg_m2, 1, 0),
    K(motor_stall_torque_nm, 1, 1),
    K(motor_noload_speed_rad_s, 1, 1),
    K(motor_nominal_v, 1, 1),
    K(motor_armature_kg_m2, 1, 0),
    K(gearbox_friction_nm, 1, 0),
    K(brake_hold_torque_nm, 1, 0),
    K(steer_limit_rad, 1, 1),
    K(steer_rate_rad_s, 1, 1),
    K(servo_center_us, 1, 1),
    K(servo_us_per_full, 1, 1),
    K(steer_kp_nm_rad, 1, 1),
    K(steer_kv_nms_rad, 1, 0),
    {"tyre_model", 0, 0, 0},
    K(long_extremum, 2, 1),
    K(long_asymptote, 2, 1),
    K(lat_extremum, 2, 1),
    K(lat_asymptote, 2, 1),
    K(tyre_v_min_m_s, 1, 1),
    K(tyre_rolling_resistance, 1, 0),
    K(imu_pos_m, 3, 0),
    K(accel_noise_m_s2, 1, 0),
    K(gyro_noise_rad_s, 1, 0),
    K(mag_noise_ut, 1, 0),
    K(accel_bias_m_s2, 1, 0),
    K(gyro_bias_rad_s, 1, 0),
    K(mag_field_ut, 3, 0),
    K(battery_v, 1, 1),
    K(battery_noise_v, 1, 0),
    K(lidar_pos_m, 3, 0),
    K(tag_pos_m, 3, 0),
    K(tag_size_m, 1, 1),
    K(cam_front_pos_m, 3, 0),
    K(cam_rear_pos_m, 3, 0),
};
#undef K
#define VP_NKEYS (sizeof vehicle_params_keys / sizeof vehicle_params_keys[0])

static int vehicle_params_fail(char *err, size_t err_sz, const char *fmt, ...) {
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(err, err_sz, fmt, ap);
  va_end(ap);
  return -1;
}

static char *vehicle_params_trim(char *s) {
  while (isspace((unsigned char)*s)) s++;
  char *e = s + strlen(s);
  while (e > s && isspace((unsigned char)e[-1])) *--e = '\0';
  return s;
}

/* Cross-field checks the per-key table cannot express. */
static int vehicle_params_check(const char *path, const vehicle_params_t *p, char *err,
                                size_t err_sz) {
  if (p->com_to_front_m >= p->wheelbase_m)
    return vehicle_params_fail(err, err_sz,
                               "%s: key 'com_to_front_m': %g m is not inside the wheelbase %g m",
                               path, p->com_to_front_m, p->wheelbase_m);
  if (p->long_asymptote[0] <= p->long_extremum[0])
    return vehicle_params_fail(
        err, err_sz, "%s: key 'long_asymptote': slip must exceed the extremum slip", path);
  if (p->lat_asymptote[0] <= p->lat_extremum[0])
    return vehicle_params_fail(err, err_sz,
                               "%s: key 'lat_asymptote': slip must exceed the extremum slip", path);
  if (p->steer_limit_rad >= 1.2)
    return vehicle_params_fail(err, err_sz,
                               "%s: key 'steer_limit_rad': %g rad is beyond a real steering lock",
                               path, p->steer_limit_rad);
  if (4.0 * p->wheel_mass_kg >= p->mass_kg)
    return vehicle_params_fail(err, err_sz, "%s: key 'wheel_mass_kg': four wheels outweigh the car",
                               path);
  return 0;
}

int vehicle_params_load(const char *path, vehicle_params_t *p, char *err, size_t err_sz) {
  FILE *f = fopen(path, "r");
  if (!f) return vehicle_params_fail(err, err_sz, "%s: cannot open: %s", path, strerror(errno));
  memset(p, 0, sizeof *p);
  int seen[VP_NKEYS] = {0};
  char line[512];
  int lineno = 0;
  int rc = 0;
  while (rc == 0 && fgets(line, sizeof line, f)) {
    lineno++;
    if (!strchr(line, '\n') && !feof(f)) {
      rc = vehicle_params_fail(err, err_sz, "%s:%d: line longer than %zu characters", path, lineno,
                               sizeof line - 2);
      break;
    }
    char *hash = strchr(line, '#');
    if (hash) *hash = '\0';
    char *s = vehicle_params_trim(line);
    if (*s == '\0') continue;
    char *eq = strchr(s, '=');
    if (!eq) {
      rc = vehicle_params_fail(err, err_sz, "%s:%d: expected 'key = value', got '%s'", path, lineno,
                               s);
      break;
    }
    *eq = '\0';
    char *key = vehicle_params_trim(s), *val = vehicle_params_trim(eq + 1);
    size_t k = 0;
    while (k < VP_NKEYS && strcmp(vehicle_params_keys[k].name, key) != 0) k++;
    if (k == VP_NKEYS) {
      rc = vehicle_params_fail(err, err_sz, "%s:%d: key '%s': unknown key", path, lineno, key);
      break;
    }
    if (seen[k]) {
      rc = vehicle_params_fail(err, err_sz, "%s:%d: key '%s': given twice", path, lineno, key);
      break;
    }
    seen[k] = 1;
    if (vehicle_params_keys[k].count == 0) { /* tyre_model */
      if (strcmp(val, "paper") == 0)
        p->tyre_model_paper = 1;
      else if (strcmp(val, "mujoco") == 0)
        p->tyre_model_paper = 0;
      else
        rc = vehicle_params_fail(err, err_sz, "%s:%d: key '%s': '%s' is not 'paper' or 'mujoco'",
                                 path, lineno, key, val);
      continue;
    }
    double *dst = (double *)((char *)p + vehicle_params_keys[k].offset);
    char *cur = val;
    for (int i = 0; i < vehicle_params_keys[k].count && rc == 0; i++) {
      char *end;
      errno = 0;
      double v = strtod(cur, &end);
      if (end == cur || errno != 0 || !isfinite(v))
        rc = vehicle_params_fail(
            err, err_sz, "%s:%d: key '%s': expected %d number(s), value %d is '%s'", path, lineno,
            key, vehicle_params_keys[k].count, i + 1, *cur ? cur : "(missing)");
      else if (vehicle_params_keys[k].positive && v <= 0.0)
        rc = vehicle_params_fail(err, err_sz, "%s:%d: key '%s': must be > 0, got %g", path, lineno,
                                 key, v);
      dst[i] = v;
      cur = end;
    }
    if (rc == 0 && *vehicle_params_trim(cur) != '\0')
      rc = vehicle_params_fail(err, err_sz, "%s:%d: key '%s': unexpected trailing text '%s'", path,
                               lineno, key, vehicle_params_trim(cur));
  }
  fclose(f);
  for (size_t k = 0; rc == 0 && k < VP_NKEYS; k++)
    if (!seen[k])
      rc = vehicle_params_fail(err, err_sz, "%s: key '%s': missing", path,
                               vehicle_params_keys[k].name);
  if (rc == 0) rc = vehicle_params_check(path, p, err, err_sz);
  return rc;
}
