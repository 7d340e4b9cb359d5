/* The paper's tyre model on the car (sim_internal.h): slip forces from the contacts of the
 * previous step (contacts.c), applied at each contact point of the wheel bodies. */
#include <math.h>

#include "sim_internal.h"

/* Adds to qfrc_applied the generalized force of a world-frame force f [N] acting at point p [m]
 * on body b: the sum mj_applyFT forms, taken over the dofs of b's own chain (Jacobian columns
 * from cdof about the root's subtree centre of mass, as mj_jac builds them). Through
 * xfrc_applied, MuJoCo built an nv-wide dense Jacobian per wheel: with 16 cars that was a
 * fifth of the run. Needs the kinematics of mj_step1. */
static void sim_apply_point_force(const mjModel *m, mjData *d, int b, const mjtNum p[3],
                                  const mjtNum f[3]) {
  const mjtNum *com = d->subtree_com + 3 * m->body_rootid[b];
  const mjtNum r[3] = {p[0] - com[0], p[1] - com[1], p[2] - com[2]};
  /* f . (v + w x r) = f . v + w . (r x f): one torque for every dof of the chain */
  const mjtNum tau[3] = {r[1] * f[2] - r[2] * f[1], r[2] * f[0] - r[0] * f[2],
                         r[0] * f[1] - r[1] * f[0]};
  while (b && !m->body_dofnum[b]) b = m->body_parentid[b];
  if (!b) return;
  for (int i = m->body_dofadr[b] + m->body_dofnum[b] - 1; i >= 0; i = m->dof_parentid[i]) {
    const mjtNum *cdof = d->cdof + 6 * i; /* [angular, linear] motion of dof i */
    d->qfrc_applied[i] += cdof[0] * tau[0] + cdof[1] * tau[1] + cdof[2] * tau[2] + cdof[3] * f[0] +
                          cdof[4] * f[1] + cdof[5] * f[2];
  }
}

/* World-frame linear velocity [m/s] of body b's centre of mass into out: what
 * mj_objectVelocity(mjOBJ_BODY, world frame) gives in its linear half, the same arithmetic
 * (cvel's linear part moved from the root's subtree CoM to the body's CoM, v - dif x w),
 * without its rotation bookkeeping: four wheels per car every step. */
static void sim_body_velocity(const mjModel *m, const mjData *d, int b, mjtNum out[3]) {
  const mjtNum *cvel = d->cvel + 6 * b, *w = cvel, *v = cvel + 3;
  const mjtNum *com = d->subtree_com + 3 * m->body_rootid[b], *p = d->xipos + 3 * b;
  const mjtNum dif[3] = {p[0] - com[0], p[1] - com[1], p[2] - com[2]};
  out[0] = v[0] - (dif[1] * w[2] - dif[2] * w[1]);
  out[1] = v[1] - (dif[2] * w[0] - dif[0] * w[2]);
  out[2] = v[2] - (dif[0] * w[1] - dif[1] * w[0]);
}

/* Paper tyre forces from the contacts recorded after the previous step, applied at each
 * contact point of the wheel body. sim_actuate has set the wheel and steering dofs' own
 * forces for this step; the free joint's are the tyres' alone. */
void sim_tyres(sim_t *s, sim_car_t *c) {
  const vehicle_params_t *p = &s->p;
  const mjModel *m = s->m;
  mjData *d = s->d;
  mju_zero(d->qfrc_applied + c->root_dof, 6);
  for (int w = 0; w < W_N; w++) {
    const int b = c->wheel_body[w];
    if (c->fz_n[w] <= 0.0) continue;
    const mjtNum *R = d->xmat + 9 * b;
    const double axis[3] = {R[1], R[4], R[7]}; /* wheel y axis (spin axis) in the world */
    double fwd[3], lat[3];
    mju_cross(fwd, axis, c->normal[w]);
    if (mju_normalize3(fwd) < 1e-9) continue;
    mju_cross(lat, c->normal[w], fwd);
    mjtNum v_lin[3];
    sim_body_velocity(m, d, b, v_lin);
    const double i_spin = m->body_inertia[3 * b + 1] + m->dof_armature[c->wheel_dof[w]];
    const double r = p->wheel_radius_m;
    tyre_in_t in;
    in.v_x_m_s = mju_dot3(v_lin, fwd);
    in.v_y_m_s = mju_dot3(v_lin, lat);
    in.omega_r_m_s = d->qvel[c->wheel_dof[w]] * r;
    in.fz_n = c->fz_n[w];
    in.mu = c->mu[w];
    in.v_min_m_s = p->tyre_v_min_m_s;
    in.rolling_resistance = p->tyre_rolling_resistance;
    /* no-overshoot clamp: half the reduced mass of (wheel spin, car mass on this wheel) so
     * one step never reverses the slip; the lateral mass is the wheel's load share (Fz / g),
     * so the clamp keeps the axles' cornering stiffness proportional to their load (neutral
     * steer, as the curves themselves are) */
    const double m_load = c->fz_n[w] / 9.80665;
    in.m_long_kg = 0.5 / (r * r / i_spin + 1.0 / fmax(m_load, 1e-3));
    in.m_lat_kg = 1.0 * m_load;
    in.dt_s = m->opt.timestep;
    double fx, fy;
    tyre_force(&s->lon, &s->lat, &in, &fx, &fy);
    double f[3];
    for (int k = 0; k < 3; k++) f[k] = fx * fwd[k] + fy * lat[k];
    sim_apply_point_force(m, d, b, c->contact_pos[w], f);
  }
}
