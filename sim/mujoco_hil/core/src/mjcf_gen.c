/* Scene MJCF generator (see mjcf_gen.h). */
#include "mjcf_gen.h"

#include <errno.h>
#include <stdio.h>
#include <string.h>

#define MG_KNUCKLE_KG 0.005 /* steering knuckle mass [kg] */

int mjcf_gen_tag_id(int car) {
  return car;
}

/* MJCF <include>/<texture> paths are relative to the scene file's directory and MuJoCo 2.2
 * refuses absolute ones; "../" at "/" stays at "/", so enough of them reach any absolute path. */
static void mjcf_gen_rel_from(const char *scene_path, const char *abs_path, char *out, size_t sz) {
  int depth = 0;
  for (const char *c = scene_path; *c; c++) depth += (*c == '/');
  out[0] = '\0';
  size_t n = 0;
  for (int i = 0; i < depth + 1 && n + 3 < sz; i++) {
    memcpy(out + n, "../", 3);
    n += 3;
  }
  out[n] = '\0';
  const char *a = abs_path;
  while (*a == '/') a++;
  size_t len = strlen(a);
  if (len > sz - n - 1) len = sz - n - 1; /* truncated: MuJoCo then names the missing file */
  memcpy(out + n, a, len);
  out[n + len] = '\0';
}

/* physics_only: leave out the car's visual-only lamps and wheel discs (drawn in the render
 * model; in the physics model they would only cost collision tests) */
static void mjcf_gen_car(FILE *f, const vehicle_params_t *p, int i, const char *tag_geom,
                         int physics_only) {
  const double L = p->wheelbase_m, hw = 0.5 * p->track_m, r = p->wheel_radius_m;
  const double mw = p->wheel_mass_kg, mk = MG_KNUCKLE_KG, M = p->mass_kg;
  const double mc = M - 4.0 * mw - 2.0 * mk;
  const double cx = L - p->com_to_front_m, cz = p->com_height_m;
  /* chassis CoM placed so that the whole car's CoM is where the parameters say */
  const double ccx = (M * cx - (2.0 * mw + 2.0 * mk) * L) / mc;
  const double ccz = (M * cz - (4.0 * mw + 2.0 * mk) * r) / mc;
  const double iw_spin = 0.5 * mw * r * r;
  const double iw_diam = mw * (3.0 * r * r + p->wheel_width_m * p->wheel_width_m) / 12.0;
  double izz = p->yaw_inertia_kg_m2 - mc * (ccx - cx) * (ccx - cx) - 4.0 * iw_diam;
  izz -= 2.0 * mw * (cx * cx + hw * hw) + 2.0 * (mw + mk) * ((L - cx) * (L - cx) + hw * hw);
  if (izz < 1e-5) izz = 1e-5; /* the parameters cannot be met: keep the model valid */

  fprintf(f, "  <body name=\"nigel%d/base_link\" pos=\"0 0 0.002\">\n", i);
  fprintf(f, "   <freejoint name=\"nigel%d/root\"/>\n", i);
  fprintf(f, "   <inertial pos=\"%.6g 0 %.6g\" mass=\"%.6g\" diaginertia=\"%.6g %.6g %.6g\"/>\n",
          ccx, ccz, mc, p->roll_pitch_inertia_kg_m2[0], p->roll_pitch_inertia_kg_m2[1], izz);
  fprintf(f,
          "   <geom name=\"nigel%d/chassis\" type=\"box\" size=\"%.6g %.6g %.6g\" pos=\"%.6g %.6g "
          "%.6g\" contype=\"4\" conaffinity=\"5\" condim=\"3\" friction=\"0.5 0.005 0.0001\" "
          "mass=\"0\" rgba=\"0.85 0.1 0.1 1\"/>\n",
          i, 0.5 * p->chassis_size_m[0], 0.5 * p->chassis_size_m[1], 0.5 * p->chassis_size_m[2],
          p->chassis_offset_m[0], p->chassis_offset_m[1], p->chassis_offset_m[2]);
  fprintf(f, "   <site name=\"nigel%d/imu\" pos=\"%.6g %.6g %.6g\" size=\"0.005\"/>\n", i,
          p->imu_pos_m[0], p->imu_pos_m[1], p->imu_pos_m[2]);
  fprintf(f, "   <site name=\"nigel%d/lidar\" pos=\"%.6g %.6g %.6g\" size=\"0.005\"/>\n", i,
          p->lidar_pos_m[0], p->lidar_pos_m[1], p->lidar_pos_m[2]);
  fprintf(f, "   <site name=\"nigel%d/tag_site\" pos=\"%.6g %.6g %.6g\" size=\"0.005\"/>\n", i,
          p->tag_pos_m[0], p->tag_pos_m[1], p->tag_pos_m[2]);
  /* the roof tag never collides: only the render model (cameras, the Eye) carries it */
  if (!physics_only && tag_geom) {
    fprintf(f, "   %s\n", tag_geom);
  } else if (!physics_only) { /* a plain white plate where the tag goes: top face at its height */
    fprintf(f,
            "   <geom name=\"nigel%d/tag\" type=\"box\" size=\"%.6g %.6g 0.001\" pos=\"%.6g "
            "%.6g %.6g\" contype=\"0\" conaffinity=\"0\" group=\"1\" mass=\"0\" "
            "rgba=\"1 1 1 1\"/>\n",
            i, 0.625 * p->tag_size_m, 0.625 * p->tag_size_m, p->tag_pos_m[0], p->tag_pos_m[1],
            p->tag_pos_m[2] - 0.001);
  }
  fprintf(f,
          "   <camera name=\"nigel%d/cam_front\" pos=\"%.6g %.6g %.6g\" xyaxes=\"0 -1 0 0 0 1\" "
          "fovy=\"48.67\"/>\n",
          i, p->cam_front_pos_m[0], p->cam_front_pos_m[1], p->cam_front_pos_m[2]);
  fprintf(f,
          "   <camera name=\"nigel%d/cam_rear\" pos=\"%.6g %.6g %.6g\" xyaxes=\"0 1 0 0 0 1\" "
          "fovy=\"48.67\"/>\n",
          i, p->cam_rear_pos_m[0], p->cam_rear_pos_m[1], p->cam_rear_pos_m[2]);

  /* lamps (visual only; the sim colours them from the firmware's lamp outputs): front and rear
   * faces of the chassis box */
  const double fx = p->chassis_offset_m[0] + 0.5 * p->chassis_size_m[0] + 0.002;
  const double rx = p->chassis_offset_m[0] - 0.5 * p->chassis_size_m[0] - 0.002;
  const double lz = p->chassis_offset_m[2] + 0.25 * p->chassis_size_m[2];
  const double ly = 0.35 * p->chassis_size_m[1], iy = 0.45 * p->chassis_size_m[1];
  static const struct {
    const char *name;
    int front;
    double y_sign, y_frac; /* y = sign * (ly or iy) */
  } lamp[] = {{"lamp_head_l", 1, 1, 0},  {"lamp_head_r", 1, -1, 0}, {"lamp_ind_fl", 1, 1, 1},
              {"lamp_ind_fr", 1, -1, 1}, {"lamp_tail_l", 0, 1, 0},  {"lamp_tail_r", 0, -1, 0},
              {"lamp_ind_rl", 0, 1, 1},  {"lamp_ind_rr", 0, -1, 1}, {"lamp_reverse", 0, 0, 0}};
  for (size_t k = 0; !physics_only && k < sizeof lamp / sizeof lamp[0]; k++)
    fprintf(
        f,
        "   <geom name=\"nigel%d/%s\" type=\"box\" size=\"0.002 0.008 0.005\" pos=\"%.6g %.6g "
        "%.6g\" contype=\"0\" conaffinity=\"0\" group=\"1\" mass=\"0\" rgba=\"0.2 0.2 0.2 1\"/>\n",
        i, lamp[k].name, lamp[k].front ? fx : rx, lamp[k].y_sign * (lamp[k].y_frac > 0 ? iy : ly),
        lz);

  const char *tyre_attr =
      p->tyre_model_paper
          ? "condim=\"1\" priority=\"1\""         /* normal force only, whatever the floor */
          : "condim=\"3\" friction=\"0.05 0 0\""; /* the floor's mu wins */
  static const char *names[4] = {"fl", "fr", "rl", "rr"};
  for (int w = 0; w < 4; w++) {
    const int front = w < 2;
    const double y = (w % 2 == 0) ? hw : -hw;
    const double x = front ? L : 0.0;
    if (front) {
      fprintf(f, "   <body name=\"nigel%d/knuckle_%s\" pos=\"%.6g %.6g %.6g\">\n", i, names[w], x,
              y, r);
      fprintf(f, "    <inertial pos=\"0 0 0\" mass=\"%g\" diaginertia=\"1e-6 1e-6 1e-6\"/>\n", mk);
      fprintf(f,
              "    <joint name=\"nigel%d/steer_%s\" type=\"hinge\" axis=\"0 0 1\" range=\"-0.9 "
              "0.9\" armature=\"%.6g\" damping=\"0.01\"/>\n",
              i, names[w], p->knuckle_armature_kg_m2);
      fprintf(f, "    <body name=\"nigel%d/wheel_%s\">\n", i, names[w]);
    } else {
      fprintf(f, "   <body name=\"nigel%d/wheel_%s\" pos=\"%.6g %.6g %.6g\">\n", i, names[w], x, y,
              r);
    }
    fprintf(f, "    <inertial pos=\"0 0 0\" mass=\"%.6g\" diaginertia=\"%.6g %.6g %.6g\"/>\n", mw,
            iw_diam, iw_spin, iw_diam);
    fprintf(f,
            "    <joint name=\"nigel%d/wheel_%s\" type=\"hinge\" axis=\"0 1 0\" armature=\"%.6g\" "
            "frictionloss=\"%.6g\"/>\n",
            i, names[w], front ? p->wheel_armature_kg_m2 : p->motor_armature_kg_m2,
            front ? 0.0 : p->gearbox_friction_nm);
    fprintf(f,
            "    <geom name=\"nigel%d/tyre_%s\" type=\"sphere\" size=\"%.6g\" contype=\"2\" "
            "conaffinity=\"1\" %s mass=\"0\" group=\"3\" rgba=\"0.1 0.1 0.1 1\"/>\n",
            i, names[w], r, tyre_attr);
    if (!physics_only)
      fprintf(f,
              "    <geom type=\"cylinder\" size=\"%.6g %.6g\" euler=\"1.5708 0 0\" "
              "contype=\"0\" conaffinity=\"0\" mass=\"0\" rgba=\"0.15 0.15 0.15 1\"/>\n",
              r, 0.5 * p->wheel_width_m);
    fprintf(f, front ? "    </body>\n   </body>\n" : "   </body>\n");
  }
  fprintf(f, "  </body>\n");
}

/* A late box (--late-box or the map's late_obstacles): a world geom with the world's collision
 * bits and surface, coloured apart from the map's boxes, parked out of sight until the sim moves
 * it in (MuJoCo 2.2 cannot add geoms at run time). A world geom, not a mocap body: world geoms
 * never collide with each other, and a parked body cost Tiny Town 2 % of a step. */
static void mjcf_gen_late_box(FILE *f, int k, const scn_late_box_t *b) {
  fprintf(f,
          "  <geom name=\"scenario/late_box%d\" type=\"box\" pos=\"0 0 %g\" euler=\"0 0 %.9g\" "
          "size=\"%.6g %.6g %.6g\" contype=\"1\" conaffinity=\"6\" "
          "friction=\"0.5 0.005 0.0001\" rgba=\"0.15 0.35 0.85 1\"/>\n",
          k, MG_PARKED_Z_M, b->yaw_rad, b->half_x_m, b->half_y_m, scn_late_box_half_z(b));
}

/* A distractor: a world geom with the world's collision bits (the cars hit it, the LIDAR and
 * the cameras see it), parked out of sight until the sim places it (distractors.c). */
static void mjcf_gen_distractor(FILE *f, int k, const mjcf_gen_distractor_t *d) {
  const float *c = d->rgba;
  if (d->kind == MG_CONE)
    fprintf(f,
            "  <geom name=\"scenario/distractor%d\" type=\"cylinder\" pos=\"0 0 %g\" "
            "size=\"%.6g %.6g\" contype=\"1\" conaffinity=\"6\" friction=\"0.5 0.005 0.0001\" "
            "rgba=\"%.3g %.3g %.3g 1\"/>\n",
            k, MG_PARKED_Z_M, d->half_m[0], d->half_m[2], c[0], c[1], c[2]);
  else
    fprintf(f,
            "  <geom name=\"scenario/distractor%d\" type=\"box\" pos=\"0 0 %g\" "
            "euler=\"0 0 %.9g\" size=\"%.6g %.6g %.6g\" contype=\"1\" conaffinity=\"6\" "
            "friction=\"0.5 0.005 0.0001\" rgba=\"%.3g %.3g %.3g 1\"/>\n",
            k, MG_PARKED_Z_M, d->yaw_rad, d->half_m[0], d->half_m[1], d->half_m[2], c[0], c[1],
            c[2]);
}

/* Whether line is a one-line <geom> named one of the names (a space-separated list). */
static int mjcf_gen_geom_named(const char *line, const char *names) {
  const char *at = strstr(line, "<geom name=\"");
  if (!names || !at) return 0;
  at += strlen("<geom name=\"");
  const char *end = strchr(at, '"');
  if (!end) return 0;
  const size_t n = (size_t)(end - at);
  for (const char *w = names; *w;) {
    while (*w == ' ') w++;
    const size_t k = strcspn(w, " ");
    if (k == n && k > 0 && strncmp(w, at, n) == 0) return 1;
    w += k;
  }
  return 0;
}

int mjcf_gen_write_physics_map(const char *map_path, const char *out_path, const char *drop_names,
                               char *err, size_t err_sz) {
  FILE *in = fopen(map_path, "r");
  if (!in) {
    snprintf(err, err_sz, "map file '%s': %s", map_path, strerror(errno));
    return -1;
  }
  FILE *out = fopen(out_path, "w");
  if (!out) {
    snprintf(err, err_sz, "cannot write '%s': %s", out_path, strerror(errno));
    fclose(in);
    return -1;
  }
  char line[16384];
  int dropped = 0;
  while (fgets(line, sizeof line, in)) {
    const int whole = strchr(line, '\n') != NULL || feof(in);
    const int one_line_geom = whole && strstr(line, "<geom ") && strstr(line, "/>");
    if (one_line_geom && ((strstr(line, "contype=\"0\"") && strstr(line, "conaffinity=\"0\"")) ||
                          mjcf_gen_geom_named(line, drop_names))) {
      dropped++;
      continue;
    }
    fputs(line, out);
  }
  fclose(in);
  if (fclose(out) != 0) {
    snprintf(err, err_sz, "cannot write '%s'", out_path);
    return -1;
  }
  return dropped;
}

int mjcf_gen_write_scene(const char *out_path, const vehicle_params_t *p,
                         const mjcf_gen_options_t *o, char *err, size_t err_sz) {
  FILE *f = fopen(out_path, "w");
  if (!f) {
    snprintf(err, err_sz, "cannot write scene '%s': %s", out_path, strerror(errno));
    return -1;
  }
  char rel[4096], map_dir[4096], rel_dir[4096];
  mjcf_gen_rel_from(out_path, o->map_path, rel, sizeof rel);
  /* MuJoCo 2.2 reads an included file's textures relative to THIS file's folder: point it at
   * the map's folder (maps write file="textures/<name>.png") */
  snprintf(map_dir, sizeof map_dir, "%s", o->texture_dir ? o->texture_dir : o->map_path);
  char *slash = strrchr(map_dir, '/');
  if (slash && !o->texture_dir) slash[1] = '\0';
  mjcf_gen_rel_from(out_path, map_dir, rel_dir, sizeof rel_dir);
  const int ncon = 64 + 16 * o->cars;
  fprintf(f, "<mujoco model=\"autodrive\">\n");
  fprintf(f, " <compiler angle=\"radian\" autolimits=\"true\" texturedir=\"%s\"/>\n", rel_dir);
  /* 1 ms Euler steps: with sphere tyres the turn radius matches L/tan(delta) */
  fprintf(f, " <option timestep=\"0.001\" integrator=\"Euler\" magnetic=\"%.6g %.6g %.6g\"/>\n",
          p->mag_field_ut[0], p->mag_field_ut[1], p->mag_field_ut[2]); /* [uT] */
  fprintf(f, " <size nconmax=\"%d\" njmax=\"%d\"/>\n", ncon, 6 * ncon);
  fprintf(f,
          " <visual><global offwidth=\"1280\" offheight=\"960\"/><quality shadowsize=\"0\"/>"
          "<map znear=\"0.001\" zfar=\"100\"/></visual>\n");
  fprintf(f, " <statistic extent=\"10\" center=\"0 0 0\"/>\n");
  fprintf(f, " <include file=\"%s\"/>\n", rel);
  if (o->tag_asset_xml) fprintf(f, " <asset>\n%s\n </asset>\n", o->tag_asset_xml);
  fprintf(f, " <worldbody>\n");
  for (int i = 1; i <= o->cars; i++)
    mjcf_gen_car(f, p, i, o->tag_geom_xml ? o->tag_geom_xml[i - 1] : NULL, o->physics_only);
  for (int k = 0; k < o->late_boxes; k++) mjcf_gen_late_box(f, k + 1, &o->late_box[k]);
  for (int k = 0; k < o->distractors; k++) mjcf_gen_distractor(f, k + 1, &o->distractor[k]);
  fprintf(f, " </worldbody>\n");
  fprintf(f, " <sensor>\n");
  for (int i = 1; i <= o->cars; i++) /* the MPU-9250 at its mount: specific force, rate, field */
    fprintf(f,
            "  <accelerometer name=\"nigel%d/accel\" site=\"nigel%d/imu\"/>\n"
            "  <gyro name=\"nigel%d/gyro\" site=\"nigel%d/imu\"/>\n"
            "  <magnetometer name=\"nigel%d/mag\" site=\"nigel%d/imu\"/>\n",
            i, i, i, i, i, i);
  fprintf(f, " </sensor>\n</mujoco>\n");
  if (fclose(f) != 0) {
    snprintf(err, err_sz, "cannot write scene '%s': %s", out_path, strerror(errno));
    return -1;
  }
  return 0;
}
