/* Paper tyre model (see tyre.h). */
#include "tyre.h"

#include <math.h>

double tyre_curve_eval(const tyre_curve_t *c, double slip) {
  const double s = fabs(slip);
  double f;
  if (s <= c->ext_slip) {
    const double t = s / c->ext_slip;
    f = c->ext_value * (1.5 * t - 0.5 * t * t * t);
  } else if (s < c->asym_slip) {
    const double u = (s - c->ext_slip) / (c->asym_slip - c->ext_slip);
    f = c->ext_value + (c->asym_value - c->ext_value) * (3.0 * u * u - 2.0 * u * u * u);
  } else {
    f = c->asym_value;
  }
  return slip < 0.0 ? -f : f;
}

static double tyre_clamp(double f, double limit) {
  if (f > limit) return limit;
  if (f < -limit) return -limit;
  return f;
}

void tyre_force(const tyre_curve_t *lon, const tyre_curve_t *lat, const tyre_in_t *in, double *fx_n,
                double *fy_n) {
  *fx_n = 0.0;
  *fy_n = 0.0;
  if (in->fz_n <= 0.0) return;
  const double denom = fmax(fabs(in->v_x_m_s), in->v_min_m_s);
  const double slip_v = in->omega_r_m_s - in->v_x_m_s; /* contact patch slip [m/s] */
  const double s_long = slip_v / denom;
  const double tan_a = in->v_y_m_s / denom;
  const double grip = in->mu * in->fz_n;
  double fx = grip * tyre_curve_eval(lon, s_long);
  double fy = -grip * tyre_curve_eval(lat, tan_a);
  /* combined slip: keep the resultant inside the friction circle */
  /* forces are a few newtons: sqrt cannot overflow, and hypot costs a libm call per wheel */
  const double mag = sqrt(fx * fx + fy * fy), cap = grip * fmax(lon->ext_value, lat->ext_value);
  if (mag > cap) {
    fx *= cap / mag;
    fy *= cap / mag;
  }
  fx = tyre_clamp(fx, in->m_long_kg * fabs(slip_v) / in->dt_s);
  fy = tyre_clamp(fy, in->m_lat_kg * fabs(in->v_y_m_s) / in->dt_s);
  /* rolling resistance opposes the hub's motion, fading in over v_min */
  fx -= in->rolling_resistance * in->fz_n * tanh(in->v_x_m_s / in->v_min_m_s);
  *fx_n = fx;
  *fy_n = fy;
}
