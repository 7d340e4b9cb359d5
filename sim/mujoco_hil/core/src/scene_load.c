/* The world's models (sim_internal.h): the map checked on its own, the roof tag textures, the
 * generated scene (mjcf_gen.h) and its physics twin without visual-only geoms, compiled into
 * the physics model and data and, when they differ, the render model and data. */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "mjcf_gen.h"
#include "sim_internal.h"
#include "sim_tags.h"

int sim_fail(char *err, size_t err_sz, const char *fmt, const char *a, const char *b) {
  snprintf(err, err_sz, fmt, a, b);
  return -1;
}
/* The map alone must compile: its errors then name the map file, not the generated scene. It
 * gives the terrain patches and, with late_boxes, the map's late obstacles. */
static int sim_check_map(sim_t *s, const char *path, int late_boxes, char *err, size_t err_sz) {
  if (access(path, R_OK) != 0)
    return sim_fail(err, err_sz, "map file '%s': %s", path, strerror(errno));
  char merr[1000] = "";
  mjModel *mm = mj_loadXML(path, NULL, merr, sizeof merr);
  if (!mm) return sim_fail(err, err_sz, "bad map file '%s': %s", path, merr);
  int rc = terrain_load(&s->terrain, mm, path, err, err_sz);
  if (rc == 0 && late_boxes) rc = sim_read_map_late_boxes(s, mm, path, err, err_sz);
  mj_deleteModel(mm);
  return rc;
}

/* Writes the roof tag PNGs into the scene dir and collects their MJCF snippets. */
static int sim_tag_snippets(sim_t *s, int cars, char **asset, char ***geoms, char *err,
                            size_t err_sz) {
  const size_t asz = 1024;
  *asset = calloc((size_t)cars, asz);
  *geoms = calloc((size_t)cars, sizeof(char *));
  if (!*asset || !*geoms) return sim_fail(err, err_sz, "%s%s", "out of memory", "");
  for (int i = 1; i <= cars; i++) {
    char png[700], file[64], prefix[32], a[asz];
    snprintf(file, sizeof file, "tag36h11_%d.png", mjcf_gen_tag_id(i));
    snprintf(png, sizeof png, "%s/%s", s->scene_dir, file);
    if (sim_tags_write_png(png, mjcf_gen_tag_id(i), 8, err, err_sz) != 0) return -1;
    snprintf(prefix, sizeof prefix, "nigel%d/", i);
    (*geoms)[i - 1] = malloc(1024);
    /* the tag's PNG by its absolute path: the scene's texturedir is the map's folder (its
     * textures), and the run dir may be given relative */
    char abs_png[4096];
    if (!realpath(png, abs_png))
      return sim_fail(err, err_sz, "roof tag '%s': %s", png, strerror(errno));
    if (!(*geoms)[i - 1] ||
        sim_tags_mjcf(prefix, abs_png, s->p.tag_size_m, a, sizeof a, (*geoms)[i - 1], 1024) != 0)
      return sim_fail(err, err_sz, "%s%s", "roof tag MJCF did not fit its buffer", "");
    strcat(*asset, a);
    strcat(*asset, "\n");
  }
  return 0;
}

int sim_load_model(sim_t *s, const sim_config_t *cfg, char *err, size_t err_sz) {
  char map_abs[4096];
  if (!realpath(cfg->map_path, map_abs))
    return sim_fail(err, err_sz, "map file '%s': %s", cfg->map_path, strerror(errno));
  if (sim_check_map(s, map_abs, !cfg->no_map_late_boxes, err, err_sz) != 0) return -1;
  mjcf_gen_options_t o = {cfg->cars, NULL, NULL, NULL, s->nbox, s->box, NULL, 0, 0, NULL};
  sim_draw_distractors(s, cfg);
  o.distractors = s->ndistractor;
  o.distractor = s->distractor;
  o.map_path = map_abs;
  char tex_abs[4096];
  if (cfg->texture_dir) {
    char probe[4200];
    snprintf(probe, sizeof probe, "%s/textures", cfg->texture_dir);
    if (!realpath(cfg->texture_dir, tex_abs) || access(probe, R_OK | X_OK) != 0)
      return sim_fail(err, err_sz, "--texture-dir '%s': no readable textures/ folder in it (%s)",
                      cfg->texture_dir, strerror(errno));
    strcat(tex_abs, "/");
    o.texture_dir = tex_abs;
  }
  char *asset = NULL, **geoms = NULL;
  int rc = sim_tag_snippets(s, cfg->cars, &asset, &geoms, err, err_sz);
  o.tag_asset_xml = asset;
  o.tag_geom_xml = (const char *const *)geoms;
  if (rc == 0) rc = mjcf_gen_write_scene(s->scene_path, &s->p, &o, err, err_sz);
  /* the physics scene: the same with a copy of the map without visual-only geoms */
  char map_dir[4096], phys_map[700], phys_scene[700];
  snprintf(map_dir, sizeof map_dir, "%s", map_abs);
  char *slash = strrchr(map_dir, '/');
  if (slash) slash[1] = '\0';
  snprintf(phys_map, sizeof phys_map, "%s/map_physics.xml", s->scene_dir);
  snprintf(phys_scene, sizeof phys_scene, "%s/scene_physics.xml", s->scene_dir);
  int dropped = 0;
  /* the paper tyres read the terrain's friction from s->terrain: its geoms need not collide */
  const char *drop = s->tyre_paper ? s->terrain.names : NULL;
  if (rc == 0 && (dropped = mjcf_gen_write_physics_map(map_abs, phys_map, drop, err, err_sz)) < 0)
    rc = -1;
  if (rc == 0 && dropped > 0) {
    mjcf_gen_options_t po = o;
    po.map_path = phys_map;
    po.texture_dir = map_dir;
    po.physics_only = 1;
    rc = mjcf_gen_write_scene(phys_scene, &s->p, &po, err, err_sz);
  }
  if (geoms)
    for (int i = 0; i < cfg->cars; i++) free(geoms[i]);
  free(geoms);
  free(asset);
  if (rc != 0) return -1;
  char merr[1000] = "";
  s->m = mj_loadXML(s->scene_path, NULL, merr, sizeof merr);
  if (!s->m)
    return sim_fail(err, err_sz, "generated scene '%s' does not compile: %s", s->scene_path, merr);
  if (dropped > 0) {
    mjModel *pm = mj_loadXML(phys_scene, NULL, merr, sizeof merr);
    /* the same bodies and joints (only geoms left out), or no split at all */
    if (pm && pm->nq == s->m->nq && pm->nv == s->m->nv && pm->nbody == s->m->nbody &&
        pm->nmocap == s->m->nmocap) {
      s->mv = s->m;
      s->m = pm;
      s->dv = mj_makeData(s->mv);
      if (!s->dv) return sim_fail(err, err_sz, "%s%s", "mj_makeData failed (out of memory)", "");
    } else if (pm) {
      mj_deleteModel(pm);
    }
  }
  s->d = mj_makeData(s->m);
  if (!s->d) return sim_fail(err, err_sz, "%s%s", "mj_makeData failed (out of memory)", "");
  return 0;
}
