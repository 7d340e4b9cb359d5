/* Traffic lights of a map (no LCM here: the program publishes and subscribes, tests call it
 * directly). Read from the map's MJCF custom numerics (contract with the map side):
 * `tl<N>_program` = "cycle_s offset_s green_s yellow_s" and `tl_conflicts` = pairs of ids that
 * must never be non-red (green or yellow) at the same time; lamp materials
 * `tl<N>_lamp_{red,yellow,green}_mat` (and lamp geoms `tl<N>_lamp_<colour>`) are lit here.
 *
 * Each light runs its fixed-time program (u = (t - offset) mod cycle: GREEN while u < green,
 * YELLOW while u < green + yellow, else RED) unless a command holds it. A command holds its
 * state for duration_s (<= 0: until the next command), then the light returns to its program.
 * A command that would make a light non-red while a conflicting light is non-red is refused.
 * A light on its program yields (shows RED) while a conflicting light is held non-red by a
 * command, so two conflicting lights are never non-red at once. */
#ifndef SIM_TRAFFIC_LIGHTS_H
#define SIM_TRAFFIC_LIGHTS_H

#include <stddef.h>
#include <stdint.h>

#include <mujoco/mujoco.h>

#ifdef __cplusplus
extern "C" {
#endif

/* States: the values of autodrive_traffic_light_state_t's constants. */
enum { TL_OFF = 0, TL_RED = 1, TL_YELLOW = 2, TL_GREEN = 3 };
#define TL_MAX_LIGHTS 64
#define TL_MAX_CONFLICTS 256
#define TL_HOLD_FOREVER INT64_MAX

typedef struct tl_light {
  int id;                                      /* N of tl<N> */
  double cycle_s, offset_s, green_s, yellow_s; /* fixed-time program [s] */
  int lamp_mat[3], lamp_geom[3];               /* red, yellow, green; -1 when absent */
  float off_rgba[3][4], off_emission[3];       /* the lamps' generated (OFF) look */
  int state;                                   /* shown now */
  int held;                                    /* 1 while a command holds the state */
  int held_state;
  int64_t hold_until_us; /* TL_HOLD_FOREVER: until the next command */
  double remaining_s;    /* until the next change [s], < 0 unknown */
  int changed;           /* state changed in the last tl_update */
  int drawn_state;       /* state the lamps show in the model, -1: none */
} tl_light_t;

typedef struct traffic_lights {
  int n;
  tl_light_t light[TL_MAX_LIGHTS];
  int nconflicts;
  int conflict[TL_MAX_CONFLICTS][2]; /* light ids */
} traffic_lights_t;

/* Reads the lights of model m (none is fine: n = 0). Returns 0, or -1 with a message naming
 * the numeric or material that is malformed or missing. */
int tl_load(traffic_lights_t *t, const mjModel *m, char *err, size_t err_sz);

/* Index of light id, or -1. */
int tl_find(const traffic_lights_t *t, int id);

/* State of a light's fixed-time program at sim time t_s; *remaining_s (if non-NULL) = time
 * until its next change [s]. */
int tl_program_state(const tl_light_t *l, double t_s, double *remaining_s);

/* Recomputes every light at sim time now_us (commands expire here). Returns how many lights
 * changed state (their `changed` flag is set). */
int tl_update(traffic_lights_t *t, int64_t now_us);

/* Commands light id to state for duration_s (<= 0: until the next command) from now_us.
 * Returns 0 when accepted (the light shows it at once: call tl_update / tl_draw), or -1 with
 * the reason in why (unknown id, bad state, or the conflicting light ids and their states). */
int tl_command(traffic_lights_t *t, int id, int state, double duration_s, int64_t now_us, char *why,
               size_t why_sz);

/* Lights the lamps in the model's materials (and lamp geoms): the lit lamp bright and
 * saturated with emission, the others in their generated dark look. Cheap when nothing
 * changed. Cameras, the Eye and the viewer all render the same model, so all see it. */
void tl_draw(traffic_lights_t *t, mjModel *m);

const char *tl_state_name(int state);

#ifdef __cplusplus
}
#endif
#endif
