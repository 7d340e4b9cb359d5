/* Generates the scene MJCF: simulation options, the map (by <include>) and N Nigel cars built
 * from the vehicle parameters. Names per car i (1-based), used by the sim and the sensors:
 *   body nigel<i>/base_link (freejoint nigel<i>/root; origin: rear-axle centre on the ground)
 *   geom nigel<i>/chassis; tyres nigel<i>/tyre_{fl,fr,rl,rr} (spheres)
 *   joints nigel<i>/steer_{fl,fr} (hinge z), nigel<i>/wheel_{fl,fr,rl,rr} (hinge y, + forward)
 *   sites nigel<i>/imu, nigel<i>/lidar, nigel<i>/tag_site; geom nigel<i>/tag (roof plate)
 *   cameras nigel<i>/cam_front, nigel<i>/cam_rear (fovy 48.67 deg = 62.2 deg HFOV at 4:3)
 * Late boxes k = 1..: world geom scenario/late_box<k>, parked at MG_PARKED_Z_M (below the
 * floor, beyond every camera's far plane, out of every LIDAR's scan plane) until the sim moves
 * it onto the floor through its model geom_pos (the box's centre).
 * Collision bits: world contype 1 / conaffinity 6, tyres 2 / 1, chassis 4 / 5; late boxes as
 * the world. */
#ifndef SIM_MJCF_GEN_H
#define SIM_MJCF_GEN_H

#include <stddef.h>

#include "scenario.h"
#include "vehicle_params.h"

#ifdef __cplusplus
extern "C" {
#endif

/* A distractor (--distractors): world geom scenario/distractor<k>, parked at MG_PARKED_Z_M
 * like a late box until the sim puts it beside the road. */
typedef enum { MG_CONE, MG_BOX, MG_PARKED_CAR } mjcf_gen_distractor_kind_t;
typedef struct mjcf_gen_distractor {
  mjcf_gen_distractor_kind_t kind;
  double half_m[3]; /* half sizes x, y, z [m]; a cone (cylinder) has radius half_m[0] */
  double yaw_rad;
  float rgba[4];
} mjcf_gen_distractor_t;

typedef struct mjcf_gen_options {
  int cars;                        /* >= 1 */
  const char *map_path;            /* absolute path of the map MJCF */
  const char *tag_asset_xml;       /* NULL, or <texture>/<material> elements of the roof tags */
  const char *const *tag_geom_xml; /* NULL, or per car the roof tag <geom> (NULL: plain plate) */
  int late_boxes;                  /* --late-box obstacles and the map's late_obstacles */
  const scn_late_box_t *late_box;  /* their sizes (positions are set at run time) */
  const char *texture_dir;         /* NULL: the map's folder; else where its textures are */
  int physics_only; /* 1: without the cars' visual-only lamps, wheel discs and roof tags */
  int distractors;  /* --distractors */
  const mjcf_gen_distractor_t *distractor;
} mjcf_gen_options_t;

#define MG_PARKED_Z_M (-2000.0) /* late boxes wait here [m]; the far plane is at 1000 m */

/* Copies the map MJCF at map_path to out_path without its visual-only geoms (one-line <geom>
 * elements with contype="0" and conaffinity="0") and without the one-line geoms named in
 * drop_names (space-separated, or NULL): the physics model's map, as every world geom costs
 * MuJoCo 2.2 narrow-phase time each step against every car geom. Returns the number of geoms
 * left out, or -1 with a message. */
int mjcf_gen_write_physics_map(const char *map_path, const char *out_path, const char *drop_names,
                               char *err, size_t err_sz);

/* Roof tag id of car i (1-based): tag36h11 id i. */
int mjcf_gen_tag_id(int car);

/* Writes the scene to out_path. Returns 0, or -1 with a message in err. */
int mjcf_gen_write_scene(const char *out_path, const vehicle_params_t *p,
                         const mjcf_gen_options_t *o, char *err, size_t err_sz);

#ifdef __cplusplus
}
#endif
#endif
