/* sim_lidar: a planar 2D LIDAR (RPLIDAR A1 class) cast with MuJoCo ray queries.
 *
 * The scanner sits at a fixed offset in a car's base body and spins at rate_hz. Each ray is
 * cast at the sim time at which the spinning head points at it (sim_lidar_update), so motion
 * during a scan distorts it like on the real device. Rays never see the car that carries the
 * scanner: every geom whose root body (mjModel.body_rootid) is the car's root is skipped, while
 * other cars stay visible (a single mj_ray bodyexclude cannot do that for a multi-body car).
 *
 * Angles: ray i points at angle_min_rad + i * angle_increment_rad, counter-clockwise from the
 * car's x (forward) axis, in the car's x-y plane (ROS LaserScan convention). Ranges below
 * range_min_m or above range_max_m, and rays that hit nothing, are +INFINITY.
 */
#ifndef SIM_LIDAR_H
#define SIM_LIDAR_H

#include <stddef.h>
#include <stdint.h>

#include <mujoco/mujoco.h>

#ifdef __cplusplus
extern "C" {
#endif

typedef struct sim_lidar_config {
  int num_rays;                /* rays per revolution (360 -> 1 deg) */
  double range_min_m;          /* closer hits read +inf (0.15 m on the A1) */
  double range_max_m;          /* farther hits read +inf (12 m on the A1) */
  double rate_hz;              /* revolutions per second (~7 Hz) */
  double mount_pos_m[3];       /* scanner origin in the base body frame [m] */
  double noise_std_m;          /* Gaussian range noise, standard deviation [m]; 0 = exact */
  uint64_t seed;               /* noise seed: same seed, same noise sequence */
  mjtByte geomgroup[mjNGROUP]; /* geom groups the rays see (1 = visible), as mjvOption */
} sim_lidar_config_t;

/* Fills cfg with the RPLIDAR A1 figures on Nigel: 360 rays, 0.15-12 m, 7 Hz, mounted at
 * lidar_pos_m of vehicle/nigel.params, no noise, seed 1, groups 0-2 visible (MuJoCo's
 * default). */
void sim_lidar_config_default(sim_lidar_config_t *cfg);

typedef struct sim_lidar sim_lidar_t;

/* One completed scan. Arrays are owned by the sim_lidar_t and stay valid until the next
 * completed scan or sim_lidar_destroy. */
typedef struct sim_lidar_scan {
  int64_t utime; /* sim time of the first ray [us] */
  int num_rays;
  float angle_min_rad;       /* 0 */
  float angle_increment_rad; /* 2 pi / num_rays */
  float time_increment_s;    /* between rays [s] */
  float scan_time_s;         /* between scans [s] */
  float range_min_m, range_max_m;
  const float *ranges_m;    /* num_rays; +INFINITY = no return */
  const float *intensities; /* num_rays; RPLIDAR-like quality 0..63, 0 = no return */
} sim_lidar_scan_t;

/* Creates a scanner on body base_body (e.g. "nigel1/base_link") of model m.
 * Returns NULL and writes a message naming the problem into err (err_len bytes) on a missing
 * body or a bad config. Caller owns the result (sim_lidar_destroy). */
sim_lidar_t *sim_lidar_create(const mjModel *m, const char *base_body,
                              const sim_lidar_config_t *cfg, char *err, size_t err_len);
void sim_lidar_destroy(sim_lidar_t *l);

/* Advances the spinning head to sim time now_us and casts every ray it passed since the last
 * call (call after mj_step / mj_forward so d->geom_xpos etc. are current; call at the physics
 * rate). Returns 1 when a revolution completed (then sim_lidar_last_scan is the new scan),
 * else 0. The first call starts the first revolution; a clock that goes back (sim reset)
 * starts a new one. */
int sim_lidar_update(const mjModel *m, mjData *d, sim_lidar_t *l, int64_t now_us);

/* Casts all rays at once at the current state (for tests, benchmarks, single shots) and
 * makes that the last scan, stamped now_us. */
void sim_lidar_scan_now(const mjModel *m, mjData *d, sim_lidar_t *l, int64_t now_us);

/* The last completed scan (num_rays == 0 before the first). Borrowed pointer. */
const sim_lidar_scan_t *sim_lidar_last_scan(const sim_lidar_t *l);

/* The head turns clockwise seen from above, like a real RPLIDAR A1: sweep step k of a
 * revolution (k = 0 .. num_rays-1, in time order) measures the ray at CW angle k * 360 /
 * num_rays deg, which a scan (REP-103, counter-clockwise) indexes as ray (num_rays - k) %
 * num_rays. The one place of that mapping. */
static inline int sim_lidar_sweep_ray(int k, int num_rays) {
  return (num_rays - k) % num_rays;
}

/* The sweep steps [from, to) the last sim_lidar_update cast (from == to: none) of num_rays per
 * revolution; step k's range is ranges_m[sim_lidar_sweep_ray(k, num_rays)] (ranges_m /
 * quality are indexed like a scan, borrowed, valid until the next update). An emulated RPLIDAR
 * streams these as they are measured, like the real device. */
void sim_lidar_last_cast(const sim_lidar_t *l, int *from, int *to, int *num_rays,
                         const float **ranges_m, const float **quality);

/* Casts one ray from the scanner at angle_rad (CCW from car x) and returns its range [m]
 * (+INFINITY if no return in range), without noise. Exposed for tests. */
double sim_lidar_ray(const mjModel *m, const mjData *d, const sim_lidar_t *l, double angle_rad);

#ifdef __cplusplus
}
#endif
#endif /* SIM_LIDAR_H */
