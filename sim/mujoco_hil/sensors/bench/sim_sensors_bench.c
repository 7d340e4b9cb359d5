/* sim-sensors-bench: medians of the sensor costs the sim pays per frame or scan, printed as
 * progress on stderr and one JSON object as the last stdout line (for tools/bench sim). */
#include <getopt.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include <autodrive_vehicle.h>

#include "sim_camera.h"
#include "sim_jpeg.h"
#include "sim_lidar.h"
#include "sim_render.h"

static double now_us(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return ts.tv_sec * 1e6 + ts.tv_nsec / 1e3;
}

/* CPU time of the whole process (llvmpipe's worker threads included) [us]: unlike wall time it
 * does not grow when other jobs share the cores */
static double cpu_us(void) {
  struct timespec ts;
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return ts.tv_sec * 1e6 + ts.tv_nsec / 1e3;
}

static int cmp_double(const void *a, const void *b) {
  double x = *(const double *)a, y = *(const double *)b;
  return (x > y) - (x < y);
}

static double median(double *v, int n) {
  qsort(v, (size_t)n, sizeof *v, cmp_double);
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

/* A Parking-School-sized scene: 6 x 5 m walled floor, 39 construction boxes, 4 cars of ~10
 * geoms each with a front camera; car 1 carries the LIDAR. */
static int write_scene(const char *path, const char *map) {
  FILE *f = fopen(path, "w");
  if (!f) return -1;
  if (map) { /* a real map (copied next to us as map.xml: MuJoCo includes relative to the
              * main file), with the 4 bench cars added in a second worldbody */
    fprintf(f, "<mujoco model=\"sim_sensors_bench\">\n<include file=\"map.xml\"/>\n<worldbody>\n");
  } else
    fprintf(
        f,
        "<mujoco model=\"sim_sensors_bench\">\n<compiler angle=\"degree\"/>\n"
        "<statistic extent=\"8\" center=\"0 0 0.5\"/>\n<visual><map znear=\"0.005\"/></visual>\n"
        "<asset><texture name=\"grid\" type=\"2d\" builtin=\"checker\" width=\"256\" "
        "height=\"256\" rgb1=\"0.3 0.3 0.3\" rgb2=\"0.4 0.4 0.4\"/>\n<material name=\"floor\" "
        "texture=\"grid\" texrepeat=\"12 10\"/></asset>\n<worldbody>\n"
        "<light pos=\"0 0 4\" dir=\"0 0 -1\" directional=\"true\"/>\n"
        "<geom type=\"plane\" size=\"3 2.5 0.1\" material=\"floor\"/>\n"
        "<geom type=\"box\" pos=\"3 0 0.25\" size=\"0.05 2.5 0.25\"/>\n"
        "<geom type=\"box\" pos=\"-3 0 0.25\" size=\"0.05 2.5 0.25\"/>\n"
        "<geom type=\"box\" pos=\"0 2.5 0.25\" size=\"3 0.05 0.25\"/>\n"
        "<geom type=\"box\" pos=\"0 -2.5 0.25\" size=\"3 0.05 0.25\"/>\n");
  for (int i = 0; i < (map ? 0 : 40); i++) {
    double x = -2.6 + 0.65 * (i % 9), y = -2.0 + 1.0 * (i / 9);
    if (map || (fabs(x) < 0.5 && fabs(y) < 0.5)) continue;
    fprintf(f,
            "<geom type=\"box\" pos=\"%.2f %.2f 0.1\" size=\"0.1 0.1 0.1\" euler=\"0 0 %d\" "
            "rgba=\"0.9 0.5 0.1 1\"/>\n",
            x, y, 17 * i);
  }
  for (int c = 1; c <= 4; c++) {
    fprintf(f,
            "<body name=\"nigel%d\" pos=\"%.2f %.2f 0.05\" quat=\"%.6f 0 0 %.6f\"><freejoint/>\n"
            "<geom type=\"box\" size=\"0.12 0.08 0.04\" rgba=\"0.8 0.8 0.8 1\"/>\n"
            "<geom type=\"cylinder\" pos=\"%g 0 0.16\" size=\"0.035 0.02\"/>\n"
            "<camera name=\"nigel%d_cam_front\" pos=\"0.15 0 0.1\" xyaxes=\"0 -1 0 0 0 1\" "
            "fovy=\"48.67\"/>\n",
            c, -1.0 + 0.6 * c, 0.3 * (c % 2), cos(M_PI / 4 * c), sin(M_PI / 4 * c),
            AUTODRIVE_VEHICLE_LIDAR_POS_M_X, c);
    for (int w = 0; w < 4; w++)
      fprintf(f,
              "<body pos=\"%.3f %.3f 0\"><joint type=\"hinge\" axis=\"0 1 0\"/>"
              "<geom type=\"sphere\" size=\"%g\"/></body>\n",
              w < 2 ? 0.07 : -0.07, (w % 2 ? 0.5 : -0.5) * AUTODRIVE_VEHICLE_TRACK_M,
              AUTODRIVE_VEHICLE_WHEEL_RADIUS_M);
    fprintf(f, "</body>\n");
  }
  fprintf(f, "</worldbody>\n</mujoco>\n");
  return fclose(f);
}

static int copy_file(const char *from, const char *to) {
  FILE *a = fopen(from, "rb"), *b = a ? fopen(to, "wb") : NULL;
  int rc = (a && b) ? 0 : -1;
  char buf[65536];
  size_t n;
  while (rc == 0 && (n = fread(buf, 1, sizeof buf, a)) > 0)
    if (fwrite(buf, 1, n, b) != n) rc = -1;
  if (a) fclose(a);
  if (b && fclose(b) != 0) rc = -1;
  return rc;
}

static void usage(FILE *out) {
  fprintf(out,
          "usage: sim-sensors-bench [--scans N] [--frames N] [--width PX] [--height PX]\n"
          "                         [--backend auto|egl|osmesa] [--map FILE]\n"
          "Measures, on a built-in Parking-School-sized scene (4 cars, 39 boxes, 68 geoms):\n"
          "  lidar_scan_us        median time of one full 360-ray scan [us]\n"
          "  lidar_scan_cpu_us    the same in process CPU time (insensitive to other jobs) [us]\n"
          "  lidar_step_us        median cost of sim_lidar_update per 1 kHz physics step [us]\n"
          "  camera_fps_640x480   frames/s of one camera: render + readPixels + flip (median)\n"
          "  camera_cpu_us        process CPU time per frame, llvmpipe threads included [us]\n"
          "  jpeg_encode_us       median JPEG encode of one frame (quality 85) [us]\n"
          "  camera_jpeg_fps      frames/s including the JPEG encode (median)\n"
          "--map FILE uses an MJCF map (e.g. maps/driving_school.xml) with the 4\n"
          "bench cars added near the origin instead of the built-in scene.\n"
          "Progress goes to stderr; the last stdout line is one JSON object.\n"
          "Defaults: --scans 300 --frames 200 --width 640 --height 480 --backend auto\n");
}

typedef struct bench_args {
  int scans, frames, w, h;
  sim_render_backend_t backend;
  char *map; /* realpath of --map, or NULL for the built-in scene */
} bench_args_t;

/* Returns -1 to run, else the exit status (0 after --help, 2 for a bad option). */
static int parse_args(int argc, char **argv, bench_args_t *a) {
  *a = (bench_args_t){300, 200, 640, 480, SIM_RENDER_AUTO, NULL};
  static const struct option opts[] = {
      {"scans", required_argument, 0, 's'},   {"frames", required_argument, 0, 'f'},
      {"width", required_argument, 0, 'w'},   {"height", required_argument, 0, 'H'},
      {"backend", required_argument, 0, 'b'}, {"map", required_argument, 0, 'm'},
      {"help", no_argument, 0, 'h'},          {0, 0, 0, 0}};
  int o;
  while ((o = getopt_long(argc, argv, "h", opts, NULL)) != -1) {
    switch (o) {
      case 's': a->scans = atoi(optarg); break;
      case 'f': a->frames = atoi(optarg); break;
      case 'w': a->w = atoi(optarg); break;
      case 'H': a->h = atoi(optarg); break;
      case 'b':
        if (!strcmp(optarg, "auto"))
          a->backend = SIM_RENDER_AUTO;
        else if (!strcmp(optarg, "egl"))
          a->backend = SIM_RENDER_EGL;
        else if (!strcmp(optarg, "osmesa"))
          a->backend = SIM_RENDER_OSMESA;
        else {
          fprintf(stderr, "sim-sensors-bench: --backend '%s' is not auto, egl or osmesa\n", optarg);
          return 2;
        }
        break;
      case 'm':
        a->map = realpath(optarg, NULL);
        if (!a->map) {
          fprintf(stderr, "sim-sensors-bench: --map '%s': no such file\n", optarg);
          return 2;
        }
        break;
      case 'h': usage(stdout); return 0;
      default: usage(stderr); return 2;
    }
  }
  if (a->scans < 1 || a->frames < 1 || a->w < 16 || a->h < 16 || a->w > 4096 || a->h > 4096) {
    fprintf(stderr, "sim-sensors-bench: --scans/--frames must be >= 1 and the size 16..4096 px\n");
    return 2;
  }
  return -1;
}

/* The bench scene (the built-in one, or map with the bench cars), compiled; NULL on error. */
static mjModel *load_scene(const char *map) {
  char dir[] = "/tmp/sim_sensors_bench_XXXXXX", path[64], map_copy[64];
  if (!mkdtemp(dir)) {
    fprintf(stderr, "sim-sensors-bench: cannot make a temp dir in /tmp\n");
    return NULL;
  }
  snprintf(path, sizeof path, "%s/scene.xml", dir);
  snprintf(map_copy, sizeof map_copy, "%s/map.xml", dir);
  if (map && copy_file(map, map_copy) != 0) {
    fprintf(stderr, "sim-sensors-bench: cannot read map %s\n", map);
    rmdir(dir);
    return NULL;
  }
  if (write_scene(path, map) != 0) {
    fprintf(stderr, "sim-sensors-bench: cannot write the scene file %s\n", path);
    return NULL;
  }
  char err[1000] = "";
  mjModel *m = mj_loadXML(path, NULL, err, sizeof err);
  unlink(path);
  unlink(map_copy);
  rmdir(dir);
  if (!m)
    fprintf(stderr, "sim-sensors-bench: scene%s%s does not load: %s\n", map ? " with map " : "",
            map ? map : "", err);
  return m;
}

int main(int argc, char **argv) {
  bench_args_t args;
  const int rc = parse_args(argc, argv, &args);
  if (rc >= 0) return rc;
  const int scans = args.scans, frames = args.frames, w = args.w, h = args.h;
  char *map = args.map;
  mjModel *m = load_scene(map);
  if (!m) return 1;
  char err[1000] = "";
  mjData *d = mj_makeData(m);
  mj_forward(m, d);
  fprintf(stderr, "scene: %d geoms, %d bodies\n", m->ngeom, m->nbody);

  /* LIDAR: full scans, then the spinning update as the sim calls it at 1 kHz */
  sim_lidar_config_t cfg;
  sim_lidar_config_default(&cfg);
  sim_lidar_t *l = sim_lidar_create(m, "nigel1", &cfg, err, sizeof err);
  if (!l) {
    fprintf(stderr, "sim-sensors-bench: %s\n", err);
    return 1;
  }
  size_t nt = (size_t)(scans > frames ? scans : frames) + 2000;
  double *t = calloc(nt, sizeof *t), *tc = calloc(nt, sizeof *tc);
  for (int i = 0; i < scans; i++) {
    double t0 = now_us(), c0 = cpu_us();
    sim_lidar_scan_now(m, d, l, 0);
    t[i] = now_us() - t0;
    tc[i] = cpu_us() - c0;
  }
  double lidar_scan_us = median(t, scans), lidar_scan_cpu_us = median(tc, scans);
  fprintf(stderr, "lidar: %d scans, median %.1f us per 360-ray scan\n", scans, lidar_scan_us);
  int steps = 2000;
  for (int i = 0; i < steps; i++) {
    double t0 = now_us();
    sim_lidar_update(m, d, l, (int64_t)i * 1000);
    t[i] = now_us() - t0;
  }
  double lidar_step_us = median(t, steps);
  fprintf(stderr, "lidar: median %.2f us per 1 ms physics step (7 Hz spin)\n", lidar_step_us);

  /* camera */
  sim_render_t *r = sim_render_create(m, w, h, args.backend, err, sizeof err);
  if (!r) {
    fprintf(stderr, "sim-sensors-bench: %s\n", err);
    return 1;
  }
  int cam = mj_name2id(m, mjOBJ_CAMERA, "nigel1_cam_front");
  uint8_t *rgb = malloc((size_t)w * h * 3);
  for (int i = 0; i < 5; i++) sim_render_camera(r, m, d, cam, w, h, rgb); /* warm-up */
  for (int i = 0; i < frames; i++) {
    double t0 = now_us(), c0 = cpu_us();
    sim_render_camera(r, m, d, cam, w, h, rgb);
    t[i] = now_us() - t0;
    tc[i] = cpu_us() - c0;
  }
  double render_us = median(t, frames), render_cpu_us = median(tc, frames);
  fprintf(stderr, "camera (%s): %d frames %dx%d, median %.0f us -> %.1f fps, %.0f us CPU\n",
          sim_render_backend_name(r), frames, w, h, render_us, 1e6 / render_us, render_cpu_us);
  sim_jpeg_t *j = sim_jpeg_create(85);
  const uint8_t *jpg;
  size_t jpg_len = 0;
  for (int i = 0; i < frames; i++) {
    double t0 = now_us();
    sim_jpeg_encode(j, rgb, w, h, &jpg, &jpg_len);
    t[i] = now_us() - t0;
  }
  double jpeg_us = median(t, frames);
  fprintf(stderr, "jpeg: median %.0f us, %zu bytes\n", jpeg_us, jpg_len);

  printf(
      "{\"lidar_scan_us\": %.1f, \"lidar_scan_cpu_us\": %.1f, \"lidar_step_us\": %.2f, "
      "\"camera_fps_%dx%d\": %.1f, \"camera_cpu_us\": %.0f, \"jpeg_encode_us\": %.0f, "
      "\"camera_jpeg_fps\": %.1f, \"jpeg_bytes\": %zu, \"render_backend\": \"%s\"}\n",
      lidar_scan_us, lidar_scan_cpu_us, lidar_step_us, w, h, 1e6 / render_us, render_cpu_us,
      jpeg_us, 1e6 / (render_us + jpeg_us), jpg_len, sim_render_backend_name(r));
  sim_jpeg_destroy(j);
  free(rgb);
  free(t);
  free(tc);
  sim_render_destroy(r);
  sim_lidar_destroy(l);
  free(map);
  mj_deleteData(d);
  mj_deleteModel(m);
  return 0;
}
