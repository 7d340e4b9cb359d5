/* Scenario option parsing (see scenario.h). */
#include "scenario.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define SCN_MAX_FIELDS 8

/* Splits text at commas into at most SCN_MAX_FIELDS numbers (empty fields are errors).
 * Returns the count, or -1 with a message in err. */
static int scn_numbers(const char *opt, const char *text, double *out, char *err, size_t err_sz) {
  if (!text || !*text) {
    snprintf(err, err_sz, "%s: missing value", opt);
    return -1;
  }
  int n = 0;
  const char *p = text;
  for (;;) {
    const char *comma = strchr(p, ',');
    const size_t len = comma ? (size_t)(comma - p) : strlen(p);
    char field[64];
    if (n == SCN_MAX_FIELDS || len >= sizeof field) {
      snprintf(err, err_sz, "%s '%s': too many or too long fields", opt, text);
      return -1;
    }
    memcpy(field, p, len);
    field[len] = '\0';
    char *end;
    errno = 0;
    const double v = strtod(field, &end);
    if (len == 0 || end == field || *end || errno || !isfinite(v)) {
      snprintf(err, err_sz, "%s '%s': field %d '%s' is not a number", opt, text, n + 1, field);
      return -1;
    }
    out[n++] = v;
    if (!comma) return n;
    p = comma + 1;
  }
}

static int scn_in(const char *opt, const char *text, const char *what, double v, double lo,
                  double hi, char *err, size_t err_sz) {
  if (v >= lo && v <= hi) return 0;
  snprintf(err, err_sz, "%s '%s': %s %g is outside [%g, %g]", opt, text, what, v, lo, hi);
  return -1;
}

int scn_parse_start(const char *text, scn_pose_t *out, char *err, size_t err_sz) {
  static const char *opt = "--start";
  double v[SCN_MAX_FIELDS];
  const int n = scn_numbers(opt, text, v, err, err_sz);
  if (n < 0) return -1;
  if (n != 3) {
    snprintf(err, err_sz,
             "%s '%s': expected X,Y,YAW_DEG (x, y [m] of the rear-axle centre, yaw [deg]), "
             "e.g. --start -1,0.6,90; got %d number(s)",
             opt, text, n);
    return -1;
  }
  if (scn_in(opt, text, "x [m]", v[0], -SCN_COORD_MAX_M, SCN_COORD_MAX_M, err, err_sz) ||
      scn_in(opt, text, "y [m]", v[1], -SCN_COORD_MAX_M, SCN_COORD_MAX_M, err, err_sz) ||
      scn_in(opt, text, "yaw [deg]", v[2], -360.0, 360.0, err, err_sz))
    return -1;
  out->x_m = v[0];
  out->y_m = v[1];
  out->yaw_deg = v[2];
  return 0;
}

int scn_parse_late_box(const char *text, scn_late_box_t *out, char *err, size_t err_sz) {
  static const char *opt = "--late-box";
  double v[SCN_MAX_FIELDS];
  const int n = scn_numbers(opt, text, v, err, err_sz);
  if (n < 0) return -1;
  if (n != 3 && n != 5 && n != 6) {
    snprintf(err, err_sz,
             "%s '%s': expected X,Y,T[,SX,SY[,R]] (centre x, y [m], appearance sim time T [s], "
             "optional half sizes SX, SY [m], optional distance R [m] NIGEL1 must come within "
             "first), e.g. --late-box 0.5,0.6,10; got %d number(s)",
             opt, text, n);
    return -1;
  }
  out->half_x_m = out->half_y_m = SCN_LATE_BOX_HALF_DEFAULT_M;
  out->near_m = 0.0;
  out->yaw_rad = out->half_z_m = out->stay_s = 0.0;
  out->name[0] = '\0';
  if (n >= 5) {
    out->half_x_m = v[3];
    out->half_y_m = v[4];
  }
  if (n == 6) {
    out->near_m = v[5];
    if (scn_in(opt, text, "R [m]", v[5], 0.01, SCN_COORD_MAX_M, err, err_sz)) return -1;
  }
  if (scn_in(opt, text, "x [m]", v[0], -SCN_COORD_MAX_M, SCN_COORD_MAX_M, err, err_sz) ||
      scn_in(opt, text, "y [m]", v[1], -SCN_COORD_MAX_M, SCN_COORD_MAX_M, err, err_sz) ||
      scn_in(opt, text, "T [s]", v[2], 0.0, 1e6, err, err_sz) ||
      scn_in(opt, text, "SX [m]", out->half_x_m, SCN_LATE_BOX_HALF_MIN_M, SCN_LATE_BOX_HALF_MAX_M,
             err, err_sz) ||
      scn_in(opt, text, "SY [m]", out->half_y_m, SCN_LATE_BOX_HALF_MIN_M, SCN_LATE_BOX_HALF_MAX_M,
             err, err_sz))
    return -1;
  out->x_m = v[0];
  out->y_m = v[1];
  out->t_s = v[2];
  return 0;
}
