// amcl_: Monte Carlo localisation on a saved map (Thrun, Burgard, Fox, ch. 8) with
// KLD-adaptive sampling (Fox 2003): after each sensor update the particle set is resampled to
// as many particles as the KL-distance bound needs for the bins it occupies. Odometry motion
// model fed by the EKF's odom-frame pose; likelihood-field sensor model.
#pragma once

#include <autodrive_vehicle.h>
#include <cstdint>
#include <random>
#include <vector>

#include <Eigen/Core>

#include <autodrive/autonomy/grid_map.hpp>

namespace autodrive::autonomy {

struct AmclConfig {
  int min_particles = 300;
  int max_particles = 5000;
  double kld_err = 0.02;  // KL bound epsilon
  double kld_z = 2.326;   // upper 1 - delta quantile of N(0,1) (delta = 0.01)
  double bin_xy_m = 0.05, bin_yaw_rad = 0.0873;  // KLD histogram bins
  // Odometry motion noise (Thrun's alpha1..4): rot<-rot, rot<-trans [rad/m], trans<-trans,
  // trans<-rot [m/rad].
  double alpha_rot_rot = 0.2, alpha_rot_trans = 0.2, alpha_trans_trans = 0.1,
         alpha_trans_rot = 0.05;
  // Likelihood field
  double sigma_hit_m = 0.04;
  double z_hit = 0.9, z_rand = 0.1;
  double max_field_dist_m = 0.5;
  int beams = 60;            // rays used per update, evenly spread over the scan
  double beam_weight = 0.4;  // exponent on each ray's likelihood (rays are not independent)
  double update_min_dist_m = 0.02, update_min_angle_rad = 0.03;  // filter update trigger
  Pose2 lidar_in_base{AUTODRIVE_VEHICLE_LIDAR_POS_M_X, AUTODRIVE_VEHICLE_LIDAR_POS_M_Y, 0.0};
  uint32_t seed = 1;
};

struct Particle {
  Pose2 pose;
  double weight = 1.0;
};

class Amcl {
 public:
  Amcl(const GridMap &map, const AmclConfig &cfg);
  // Particles drawn around a guess (standard deviations [m], [m], [rad]).
  void init_gaussian(const Pose2 &mean, double sigma_x_m, double sigma_y_m, double sigma_yaw_rad);
  // Feed the EKF odom-frame pose and the scan taken there. The filter updates when the car
  // has moved enough since the last update, or always when force is true. Returns true if it
  // updated.
  bool update(const Pose2 &odom_pose, const Scan &scan, bool force = false);

  Pose2 estimate() const { return mean_; }
  Eigen::Matrix3d covariance() const { return cov_; }  // x, y, yaw [m^2, rad^2]
  const std::vector<Particle> &particles() const { return particles_; }
  // Log-likelihood of a scan from a pose (sum over the used rays), exposed for tests.
  double scan_log_likelihood(const Pose2 &pose, const std::vector<Eigen::Vector2d> &pts) const;

 private:
  void motion_update(const Pose2 &odom_from, const Pose2 &odom_to);
  void sensor_update(const Scan &scan);
  void kld_resample();
  void compute_estimate();

  const GridMap &map_;
  AmclConfig cfg_;
  std::vector<float> field_m_;  // distance to the nearest occupied cell [m]
  std::vector<Particle> particles_;
  std::mt19937 rng_;
  bool have_odom_ = false;
  Pose2 last_odom_, last_update_odom_;
  Pose2 mean_;
  Eigen::Matrix3d cov_ = Eigen::Matrix3d::Identity();
};

}  // namespace autodrive::autonomy
