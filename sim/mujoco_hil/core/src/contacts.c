/* What touches what after a step (sim_internal.h): each tyre's load, surface friction, contact
 * point and normal (the paper tyres' input), and the chassis collision flag. */
#include "sim_internal.h"

/* After the step: normal load, surface friction and geometry of every tyre contact, and
 * chassis collisions. */
void sim_record_contacts(sim_t *s) {
  const mjModel *m = s->m;
  const mjData *d = s->d;
  for (int i = 0; i < s->ncars; i++) {
    sim_car_t *c = &s->car[i];
    c->in_collision = 0;
    for (int w = 0; w < W_N; w++) c->fz_n[w] = 0.0;
  }
  double best[SIM_MAX_CARS * W_N] = {0};
  for (int k = 0; k < d->ncon; k++) {
    const mjContact *con = d->contact + k;
    for (int side = 0; side < 2; side++) {
      const int g = side ? con->geom2 : con->geom1, other = side ? con->geom1 : con->geom2;
      const int t = s->geom_tyre[g];
      if (t < 0) continue;
      sim_car_t *c = &s->car[t / W_N];
      const int w = t % W_N;
      mjtNum f6[6];
      mj_contactForce(m, d, k, f6);
      const double fn = f6[0];
      c->fz_n[w] += fn;
      if (fn > best[t]) { /* the most loaded contact gives surface, point and normal */
        best[t] = fn;
        c->mu[w] = m->geom_friction[3 * other];
        if (s->tyre_paper && con->pos[2] < SIM_GROUND_CLEARANCE_M) /* on the floor */
          c->mu[w] = terrain_mu(&s->terrain, con->pos[0], con->pos[1], c->mu[w]);
        mju_copy3(c->contact_pos[w], con->pos);
        /* frame[0..2] points from geom1 to geom2: make it point from the ground to the tyre */
        for (int q = 0; q < 3; q++) c->normal[w][q] = side ? con->frame[q] : -con->frame[q];
      }
    }
  }
  for (int i = 0; i < s->ncars; i++) {
    sim_car_t *c = &s->car[i];
    for (int k = 0; k < d->ncon; k++)
      if (d->contact[k].geom1 == c->chassis_geom || d->contact[k].geom2 == c->chassis_geom)
        c->in_collision = 1;
  }
}
