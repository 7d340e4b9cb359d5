/* The paper's tyre model (AutoDRIVE, after Unity's WheelCollider): force = mu * Fz * f(slip)
 * per direction, f made of two cubic pieces, odd in slip:
 *   0 <= s <= s_e:   f = v_e * (1.5 t - 0.5 t^3), t = s / s_e   (f(0)=0, f(s_e)=v_e, f'(s_e)=0)
 *   s_e < s < s_a:   f = v_e + (v_a - v_e) (3 u^2 - 2 u^3), u = (s - s_e) / (s_a - s_e)
 *   s >= s_a:        f = v_a
 * Longitudinal slip s = (r w - v_x) / max(|v_x|, v_min); lateral tan(a) = v_y / max(|v_x|, v_min).
 * The floor v_min keeps the model defined at standstill (documented in README.md). */
#ifndef SIM_TYRE_H
#define SIM_TYRE_H

#ifdef __cplusplus
extern "C" {
#endif

typedef struct tyre_curve {
  double ext_slip, ext_value;   /* extremum point */
  double asym_slip, asym_value; /* asymptote point */
} tyre_curve_t;

/* f(slip) [unitless force / (mu Fz)]. */
double tyre_curve_eval(const tyre_curve_t *c, double slip);

typedef struct tyre_in {
  double v_x_m_s, v_y_m_s; /* hub velocity in the wheel's heading frame */
  double omega_r_m_s;      /* wheel spin times radius [m/s] */
  double fz_n;             /* normal load [N] */
  double mu;               /* surface friction */
  double v_min_m_s;
  double rolling_resistance;  /* [N/N] */
  double m_long_kg, m_lat_kg; /* effective masses for the no-overshoot clamp */
  double dt_s;
} tyre_in_t;

/* Forces on the wheel at the contact [N] (+x forward, +y left) from the curves. Each force is
 * also limited to what stops the slip velocity within one step (never reverses it), which keeps
 * the explicit 1 ms integration stable at low speed. */
void tyre_force(const tyre_curve_t *lon, const tyre_curve_t *lat, const tyre_in_t *in, double *fx_n,
                double *fy_n);

#ifdef __cplusplus
}
#endif
#endif
