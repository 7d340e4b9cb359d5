#include <autodrive/autonomy/amcl.hpp>

#include <algorithm>
#include <cmath>
#include <set>
#include <tuple>

namespace autodrive::autonomy {

Amcl::Amcl(const GridMap &map, const AmclConfig &cfg)
    : map_(map), cfg_(cfg), field_m_(grid_distance_field_m(map, false)), rng_(cfg.seed) {}

void Amcl::init_gaussian(const Pose2 &mean, double sx, double sy, double syaw) {
  std::normal_distribution<double> n(0.0, 1.0);
  particles_.assign(static_cast<size_t>(cfg_.max_particles), Particle{});
  for (auto &p : particles_) {
    p.pose = {mean.x_m + sx * n(rng_), mean.y_m + sy * n(rng_),
              angle_wrap_rad(mean.yaw_rad + syaw * n(rng_))};
    p.weight = 1.0 / cfg_.max_particles;
  }
  have_odom_ = false;
  compute_estimate();
}

void Amcl::motion_update(const Pose2 &from, const Pose2 &to) {
  // Odometry as rot1, trans, rot2 (sample_motion_model_odometry).
  const double dx = to.x_m - from.x_m, dy = to.y_m - from.y_m;
  const double trans = std::hypot(dx, dy);
  double rot1 = trans < 1e-4 ? 0.0 : angle_wrap_rad(std::atan2(dy, dx) - from.yaw_rad);
  bool backwards = false;
  if (std::abs(rot1) > kPi / 2) {  // reversing: model it as negative translation
    rot1 = angle_wrap_rad(rot1 + kPi);
    backwards = true;
  }
  const double rot2 = angle_wrap_rad(to.yaw_rad - from.yaw_rad - rot1);
  const double sr1 =
      std::sqrt(cfg_.alpha_rot_rot * rot1 * rot1 + cfg_.alpha_rot_trans * trans * trans);
  const double st = std::sqrt(cfg_.alpha_trans_trans * trans * trans +
                              cfg_.alpha_trans_rot * (rot1 * rot1 + rot2 * rot2));
  const double sr2 =
      std::sqrt(cfg_.alpha_rot_rot * rot2 * rot2 + cfg_.alpha_rot_trans * trans * trans);
  std::normal_distribution<double> n(0.0, 1.0);
  for (auto &p : particles_) {
    const double r1 = rot1 + sr1 * n(rng_);
    const double t = (backwards ? -trans : trans) + st * n(rng_);
    const double r2 = rot2 + sr2 * n(rng_);
    const double h = p.pose.yaw_rad + r1;
    p.pose.x_m += t * std::cos(h);
    p.pose.y_m += t * std::sin(h);
    p.pose.yaw_rad = angle_wrap_rad(h + r2);
  }
}

double Amcl::scan_log_likelihood(const Pose2 &pose, const std::vector<Eigen::Vector2d> &pts) const {
  const double inv2s2 = 1.0 / (2.0 * cfg_.sigma_hit_m * cfg_.sigma_hit_m);
  const double rand_term = cfg_.z_rand / 12.0;  // uniform over the LIDAR's 12 m range
  double ll = 0.0;
  for (const auto &q : pts) {
    const Eigen::Vector2d w = pose_apply(pose, q);
    int cx, cy;
    double d = cfg_.max_field_dist_m;
    if (map_.world_to_cell(w.x(), w.y(), cx, cy))
      d = std::min<double>(d, field_m_[map_.index(cx, cy)]);
    ll += cfg_.beam_weight * std::log(cfg_.z_hit * std::exp(-d * d * inv2s2) + rand_term);
  }
  return ll;
}

void Amcl::sensor_update(const Scan &scan) {
  const auto all = scan_points_base(scan, cfg_.lidar_in_base);
  std::vector<Eigen::Vector2d> pts;
  const size_t step =
      std::max<size_t>(1, all.size() / static_cast<size_t>(std::max(1, cfg_.beams)));
  for (size_t i = 0; i < all.size(); i += step) pts.push_back(all[i]);
  std::vector<double> ll(particles_.size());
  double best = -1e300;
  for (size_t i = 0; i < particles_.size(); ++i) {
    ll[i] = scan_log_likelihood(particles_[i].pose, pts);
    best = std::max(best, ll[i]);
  }
  double sum = 0.0;
  for (size_t i = 0; i < particles_.size(); ++i) {
    particles_[i].weight *= std::exp(ll[i] - best);
    sum += particles_[i].weight;
  }
  if (!(sum > 0.0)) {
    for (auto &p : particles_) p.weight = 1.0 / particles_.size();
  } else {
    for (auto &p : particles_) p.weight /= sum;
  }
}

void Amcl::kld_resample() {
  std::vector<double> cdf(particles_.size());
  double acc = 0.0;
  for (size_t i = 0; i < particles_.size(); ++i) cdf[i] = (acc += particles_[i].weight);
  std::uniform_real_distribution<double> u(0.0, acc);
  std::set<std::tuple<int, int, int>> bins;
  std::vector<Particle> out;
  out.reserve(static_cast<size_t>(cfg_.max_particles));
  size_t needed = static_cast<size_t>(cfg_.min_particles);
  while (out.size() < static_cast<size_t>(cfg_.max_particles) &&
         (out.size() < needed || out.size() < static_cast<size_t>(cfg_.min_particles))) {
    const size_t i =
        static_cast<size_t>(std::lower_bound(cdf.begin(), cdf.end(), u(rng_)) - cdf.begin());
    const Particle &p = particles_[std::min(i, particles_.size() - 1)];
    out.push_back({p.pose, 1.0});
    const auto key =
        std::make_tuple(static_cast<int>(std::floor(p.pose.x_m / cfg_.bin_xy_m)),
                        static_cast<int>(std::floor(p.pose.y_m / cfg_.bin_xy_m)),
                        static_cast<int>(std::floor(p.pose.yaw_rad / cfg_.bin_yaw_rad)));
    if (bins.insert(key).second && bins.size() > 1) {
      // Wilson-Hilferty approximation of the chi-square quantile (Fox 2003, eq. 13).
      const double k1 = static_cast<double>(bins.size() - 1);
      const double a = 2.0 / (9.0 * k1);
      const double c = 1.0 - a + std::sqrt(a) * cfg_.kld_z;
      needed = static_cast<size_t>(std::ceil(k1 / (2.0 * cfg_.kld_err) * c * c * c));
    }
  }
  for (auto &p : out) p.weight = 1.0 / out.size();
  particles_.swap(out);
}

void Amcl::compute_estimate() {
  double sx = 0, sy = 0, sc = 0, ss = 0, sw = 0;
  for (const auto &p : particles_) {
    sx += p.weight * p.pose.x_m;
    sy += p.weight * p.pose.y_m;
    sc += p.weight * std::cos(p.pose.yaw_rad);
    ss += p.weight * std::sin(p.pose.yaw_rad);
    sw += p.weight;
  }
  if (!(sw > 0)) return;
  mean_ = {sx / sw, sy / sw, std::atan2(ss, sc)};
  Eigen::Matrix3d c = Eigen::Matrix3d::Zero();
  for (const auto &p : particles_) {
    const Eigen::Vector3d d(p.pose.x_m - mean_.x_m, p.pose.y_m - mean_.y_m,
                            angle_wrap_rad(p.pose.yaw_rad - mean_.yaw_rad));
    c += p.weight * d * d.transpose();
  }
  cov_ = c / sw;
}

bool Amcl::update(const Pose2 &odom_pose, const Scan &scan, bool force) {
  if (particles_.empty()) return false;
  if (!have_odom_) {
    last_odom_ = last_update_odom_ = odom_pose;
    have_odom_ = true;
    force = true;
  }
  const Pose2 moved = pose_between(last_update_odom_, odom_pose);
  if (!force && std::hypot(moved.x_m, moved.y_m) < cfg_.update_min_dist_m &&
      std::abs(moved.yaw_rad) < cfg_.update_min_angle_rad)
    return false;
  motion_update(last_update_odom_, odom_pose);
  last_update_odom_ = odom_pose;
  sensor_update(scan);
  compute_estimate();
  kld_resample();
  return true;
}

}  // namespace autodrive::autonomy
