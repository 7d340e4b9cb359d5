#include <autodrive_channels.h>
#include <autodrive/estimator/estimator_node.hpp>

#include <autodrive/imu_t.hpp>
#include <autodrive/odometry_t.hpp>
#include <autodrive/pose2d_t.hpp>
#include <autodrive/vehicle_state_t.hpp>
#include <lcm/lcm-cpp.hpp>
#include <spdlog/spdlog.h>
#include <autodrive/log_limiter.hpp>
#include <autodrive/v2x.hpp>

#include <cmath>

#include <autodrive_lcm/subscribe.hpp>

namespace autodrive::estimator {

bool wheel_speed_from_encoders(int32_t prev_l, int32_t prev_r, int64_t prev_nano_us, int32_t l,
                               int32_t r, int64_t nano_us, int counts_per_rev,
                               double wheel_radius_m, double *speed_m_s) {
  // The Nano clock is 32 bit: take the difference modulo 2^32.
  const uint32_t dt_us = static_cast<uint32_t>(nano_us) - static_cast<uint32_t>(prev_nano_us);
  if (dt_us == 0 || dt_us > 1000000u) return false;
  const double dl = static_cast<double>(static_cast<int64_t>(l) - prev_l);
  const double dr = static_cast<double>(static_cast<int64_t>(r) - prev_r);
  const double dist_m = 0.5 * (dl + dr) / counts_per_rev * 2.0 * M_PI * wheel_radius_m;
  *speed_m_s = dist_m / (dt_us * 1e-6);
  return true;
}

EkfParams params_from_config(const autodrive::config::Config &c) {
  EkfParams p;
  p.wheelbase_m = c.vehicle.wheelbase_m;
  p.q_pos_m = c.estimator.process_pos_std_m;
  p.q_yaw_rad = c.estimator.process_yaw_std_rad;
  p.r_speed_m_s = c.estimator.odom_speed_std_m_s;
  p.r_gyro_rad_s = c.estimator.yaw_rate_std_rad_s;
  p.history_us = c.estimator.history_ms * 1000LL;
  p.pose_gate_chi2 = c.estimator.pose_gate_chi2;
  p.pose_reacquire_us = static_cast<int64_t>(c.estimator.pose_reacquire_s * 1e6);
  return p;
}

struct EstimatorNode::Impl {
  autodrive::config::Config config;
  lcm::LCM lcm;                   // inputs (and outputs, unless a separate output bus is given)
  std::unique_ptr<lcm::LCM> out;  // replay: the outputs go to their own bus (e.g. a log file)
  Ekf odom, map;
  bool map_fixed = false;  // the map filter has a first Eye fix or its initial pose
  bool have_prev = false;
  autodrive::vehicle_state_t prev{};
  int64_t next_pub_us = 0;  // next ODOM/POSE_MAP due [us, message time]
  // Inputs that fail a check are dropped, counted and logged at a limited rate.
  autodrive::LogLimiter implausible{"implausible inputs"};
  uint64_t wheel_dropped = 0, gyro_dropped = 0, poses_future = 0, gated_logged = 0;
  static constexpr int64_t kMaxPoseAheadUs = 1000000;  // a pose may be this far ahead [us]
  // Eye poses: signed by an eye certificate (EyePoseAuth::verify); without a trust anchor
  // (no CA in the key folder) every pose is refused, said once at start.
  EyePoseAuth eye_auth;
  std::optional<autodrive::v2x::Verifier> eye_verifier;
  uint64_t poses_unauthenticated = 0;

  Impl(const autodrive::config::Config &c, const std::string &output_url, EyePoseAuth auth)
      : config(c),
        lcm(c.lcm_url),
        odom(params_from_config(c)),
        map(params_from_config(c)),
        eye_auth(auth) {
    if (!output_url.empty()) out = std::make_unique<lcm::LCM>(output_url);
    if (eye_auth == EyePoseAuth::verify) {
      eye_verifier = autodrive::v2x::Verifier::load("autodrive-runtime estimator");
      // A pose is fresh while the filter can still fuse it (its history): the Eye's poses
      // arrive up to a frame's processing after their capture stamp.
      if (eye_verifier) eye_verifier->set_window_us(params_from_config(c).history_us);
      if (!eye_verifier)
        spdlog::error("{}{}: no trust anchor, so no Eye pose will be taken (tools/keys)",
                      c.vehicle.name, AUTODRIVE_CH_POSE_EYE_SUFFIX);
    }
    if (!lcm.good()) return;
    const std::string v = c.vehicle.name;
    autodrive_lcm::subscribe<autodrive::vehicle_state_t, Impl, &Impl::on_state>(
        lcm, v + AUTODRIVE_CH_STATE_SUFFIX, this);
    autodrive_lcm::subscribe<autodrive::imu_t, Impl, &Impl::on_imu>(
        lcm, v + AUTODRIVE_CH_IMU_SUFFIX, this);
    autodrive_lcm::subscribe<autodrive::pose2d_t, Impl, &Impl::on_pose>(
        lcm, v + AUTODRIVE_CH_POSE_EYE_SUFFIX, this);
  }

  void on_state(const autodrive::vehicle_state_t *m) {
    if (!odom.initialised()) odom.reset(m->utime, 0, 0, 0, 1e-9, 1e-9);
    if (!map_fixed && config.estimator.has_initial_pose_map) {
      // Placed at a known pose: the map filter starts there, as sure as its placer says.
      const auto &p = config.estimator.initial_pose_map;
      map.reset(m->utime, p[0], p[1], p[2], std::pow(config.estimator.initial_pos_std_m, 2),
                std::pow(config.estimator.initial_yaw_std_rad, 2));
      map_fixed = true;
    }
    if (have_prev) {
      double v = 0;
      if (wheel_speed_from_encoders(prev.encoder_counts[0], prev.encoder_counts[1],
                                    prev.nano_time_us, m->encoder_counts[0], m->encoder_counts[1],
                                    m->nano_time_us, config.vehicle.encoder_counts_per_rev,
                                    config.vehicle.wheel_radius_m, &v)) {
        if (std::abs(v) > config.estimator.max_speed_m_s ||
            std::abs(m->steering_angle_rad) > 2.0 * config.vehicle.steering_limit_rad) {
          ++wheel_dropped;
          implausible.event(config.vehicle.name + AUTODRIVE_CH_STATE_SUFFIX,
                            fmt::format("encoder speed {:.3g} m/s or steering {:.3g} rad is "
                                        "implausible (limits {} m/s, {:.3g} rad): dropped",
                                        v, m->steering_angle_rad, config.estimator.max_speed_m_s,
                                        2.0 * config.vehicle.steering_limit_rad));
        } else {
          odom.add_wheel(m->utime, v, m->steering_angle_rad);
          map.add_wheel(m->utime, v, m->steering_angle_rad);
        }
      }
    }
    prev = *m;
    have_prev = true;
    // Publish on the STATE stream, at most at rate_hz on average (a quarter period of slack
    // so receive-time jitter does not skip messages).
    const int64_t period_us = static_cast<int64_t>(1e6 / config.estimator.rate_hz);
    if (next_pub_us == 0 || m->utime >= next_pub_us - period_us / 4) {
      next_pub_us = (next_pub_us == 0 ? m->utime : next_pub_us) + period_us;
      // fell behind (or just caught up): the next one a period on, so that a STATE of the same
      // stamp (the sim clock's 10 ms ticks) never publishes this stamp twice (tf's
      // TF_REPEATED_DATA: 218 of 2054 ODOM stamps were repeats before)
      if (next_pub_us <= m->utime) next_pub_us = m->utime + period_us;
      publish(odom.estimate_at(m->utime), "odom", AUTODRIVE_CH_ODOM_SUFFIX);
      if (map_fixed)  // never a map pose the car has no fix for (the origin, say)
        publish(map.estimate_at(m->utime), "map", AUTODRIVE_CH_POSE_MAP_SUFFIX);
    }
  }

  void on_imu(const autodrive::imu_t *m) {
    if (!config.estimator.use_imu) return;
    const double w = m->angular_velocity_rad_s[2];
    if (!(std::abs(w) <= config.estimator.max_yaw_rate_rad_s)) {
      ++gyro_dropped;
      implausible.event(config.vehicle.name + AUTODRIVE_CH_IMU_SUFFIX,
                        fmt::format("gyro z {:.3g} rad/s is implausible (limit {} rad/s): dropped",
                                    w, config.estimator.max_yaw_rate_rad_s));
      return;
    }
    odom.add_gyro(m->utime, m->angular_velocity_rad_s[2]);
    map.add_gyro(m->utime, m->angular_velocity_rad_s[2]);
  }

  void on_pose(const autodrive::pose2d_t *m) {
    Eigen::Matrix3d cov =
        Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(m->covariance);
    // A zero covariance means "not given": use the configured Eye noise.
    if (cov.diagonal().minCoeff() <= 0.0) {
      cov = Eigen::Matrix3d::Zero();
      cov(0, 0) = cov(1, 1) = std::pow(config.estimator.eye_pos_std_m, 2);
      cov(2, 2) = std::pow(config.estimator.eye_yaw_std_rad, 2);
    }
    const std::string channel = config.vehicle.name + AUTODRIVE_CH_POSE_EYE_SUFFIX;
    if (!eye_pose_authentic(channel, *m)) {
      ++poses_unauthenticated;
      return;
    }
    // A stamp far ahead of the car's own time would drag the filter's clock forward and make
    // every real measurement "too old": refused against the last STATE's stamp.
    if (have_prev && m->utime > prev.utime + kMaxPoseAheadUs) {
      ++poses_future;
      implausible.event(channel, fmt::format("pose stamped {:.3f} s ahead of the car's STATE: "
                                             "dropped",
                                             (m->utime - prev.utime) * 1e-6));
      return;
    }
    const uint64_t reacquired = map.stats().reacquired, fused = map.stats().fused;
    map.add_pose(m->utime, m->x_m, m->y_m, m->yaw_rad, cov);
    map_fixed = map_fixed || map.stats().fused > fused;
    if (map.stats().gated > gated_logged) {
      gated_logged = map.stats().gated;
      implausible.event(channel, fmt::format("pose ({:.3f}, {:.3f}) m far from the estimate "
                                             "(Mahalanobis gate): rejected, {} so far",
                                             m->x_m, m->y_m, gated_logged));
    }
    if (map.stats().reacquired > reacquired)
      spdlog::warn(
          "{}: no pose accepted for {} s; re-placed the car at ({:.3f}, {:.3f}) m on "
          "a consistent run of poses",
          channel, config.estimator.pose_reacquire_s, m->x_m, m->y_m);
  }

  // Signed by an Eye, fresh on the car's clock (the last STATE's stamp), not replayed.
  // Before the first STATE the car has no clock to judge freshness by: refused.
  bool eye_pose_authentic(const std::string &channel, const autodrive::pose2d_t &m) {
    if (eye_auth == EyePoseAuth::trust_recorded_log) return true;
    if (!eye_verifier || !have_prev) return false;
    return eye_verifier->accept(channel, m, AUTODRIVE_CH_POSE_EYE_SIGNED_BY, nullptr, prev.utime);
  }

  void publish(const Estimate &e, const char *frame, const char *suffix) {
    autodrive::odometry_t o{};
    o.utime = e.t_us;
    o.vehicle = config.vehicle.name;
    o.frame_id = frame;
    o.child_frame_id = "base_link";
    o.x_m = e.x(0);
    o.y_m = e.x(1);
    o.yaw_rad = e.x(2);
    o.vx_m_s = e.x(3);
    o.vy_m_s = 0.0;  // Ackermann, no side slip in the model
    o.yaw_rate_rad_s = e.x(4);
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) o.pose_covariance[r * 3 + c] = e.P(r, c);
    for (double &v : o.twist_covariance) v = 0.0;
    o.twist_covariance[0] = e.P(3, 3);
    o.twist_covariance[8] = e.P(4, 4);
    (out ? *out : lcm).publish(config.vehicle.name + suffix, &o);
  }
};

EstimatorNode::EstimatorNode(const autodrive::config::Config &config, const std::string &output_url,
                             EyePoseAuth eye_auth)
    : impl_(std::make_unique<Impl>(config, output_url, eye_auth)) {}
EstimatorNode::~EstimatorNode() = default;

std::string EstimatorNode::init_error() const {
  if (!impl_->config.has_estimator) return impl_->config.file + ": estimator: missing section";
  if (!impl_->lcm.good()) return "LCM URL '" + impl_->config.lcm_url + "' unusable";
  if (impl_->out && !impl_->out->good()) return "the output LCM URL is unusable";
  return "";
}

void EstimatorNode::run(const std::atomic<bool> &stop) {
  while (!stop) {
    impl_->lcm.handleTimeout(20);
    impl_->implausible.flush();
    autodrive_lcm::malformed_log().flush();
  }
  if (impl_->poses_unauthenticated)
    spdlog::info("{}{}: refused {} Eye poses ({})", impl_->config.vehicle.name,
                 AUTODRIVE_CH_POSE_EYE_SUFFIX, impl_->poses_unauthenticated,
                 impl_->eye_verifier ? impl_->eye_verifier->summary() : "no trust anchor");
}

InputStats EstimatorNode::input_stats() const {
  return {impl_->map.stats().gated,
          impl_->map.stats().reacquired,
          impl_->wheel_dropped,
          impl_->gyro_dropped,
          impl_->poses_future,
          impl_->poses_unauthenticated,
          impl_->eye_verifier ? impl_->eye_verifier->summary() : std::string()};
}

long EstimatorNode::replay() {
  // A file:// input in read mode: handle() delivers the next logged message and fails at the
  // end of the log. Time is the messages' own stamps, so a replay computes what the run did.
  long n = 0;
  while (impl_->lcm.handle() == 0) ++n;
  return n;
}

}  // namespace autodrive::estimator
