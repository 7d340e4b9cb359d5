#include <autodrive/estimator/ekf.hpp>

#include <autodrive/angles.hpp>

#include <algorithm>
#include <cmath>

namespace autodrive::estimator {

Ekf::Ekf(EkfParams p) : p_(p) {
  // Until reset or a pose arrives: at the origin with a huge pose uncertainty, so the first
  // Eye pose places the car.
  base_.P = Mat5::Identity();
  base_.P(0, 0) = base_.P(1, 1) = 1e4;
  base_.P(2, 2) = 10.0;
  cur_ = base_;
}

void Ekf::reset(int64_t t_us, double x_m, double y_m, double yaw_rad, double pos_var_m2,
                double yaw_var_rad2) {
  events_.clear();
  base_ = Estimate{};
  base_.t_us = t_us;
  base_.x << x_m, y_m, autodrive::angle_wrap_rad(yaw_rad), 0.0, 0.0;
  base_.P = Mat5::Zero();
  base_.P(0, 0) = base_.P(1, 1) = pos_var_m2;
  base_.P(2, 2) = yaw_var_rad2;
  base_.P(3, 3) = 0.01;
  base_.P(4, 4) = 0.01;
  cur_ = base_;
  init_ = true;
}

void Ekf::predict(Estimate &s, int64_t t_us, const EkfParams &p) {
  const double dt = (t_us - s.t_us) * 1e-6;
  if (dt <= 0) return;
  const double yaw = s.x(2), v = s.x(3), w = s.x(4);
  // Constant speed and yaw rate; midpoint heading for the position step.
  const double ym = yaw + 0.5 * w * dt;
  s.x(0) += v * std::cos(ym) * dt;
  s.x(1) += v * std::sin(ym) * dt;
  s.x(2) = autodrive::angle_wrap_rad(yaw + w * dt);
  Mat5 F = Mat5::Identity();
  F(0, 2) = -v * std::sin(ym) * dt;
  F(0, 3) = std::cos(ym) * dt;
  F(0, 4) = -0.5 * v * std::sin(ym) * dt * dt;
  F(1, 2) = v * std::cos(ym) * dt;
  F(1, 3) = std::sin(ym) * dt;
  F(1, 4) = 0.5 * v * std::cos(ym) * dt * dt;
  F(2, 4) = dt;
  Vec5 q;
  q << p.q_pos_m * p.q_pos_m, p.q_pos_m * p.q_pos_m, p.q_yaw_rad * p.q_yaw_rad,
      p.q_accel_m_s2 * p.q_accel_m_s2, p.q_yaw_accel_rad_s2 * p.q_yaw_accel_rad_s2;
  s.P = F * s.P * F.transpose();
  s.P.diagonal() += q * dt;
  s.t_us = t_us;
}

template <int M>
void Ekf::update(Estimate &s, const Eigen::Matrix<double, M, 1> &innov,
                 const Eigen::Matrix<double, M, 5> &H, const Eigen::Matrix<double, M, M> &R) {
  const Eigen::Matrix<double, M, M> S = H * s.P * H.transpose() + R;
  const Eigen::Matrix<double, 5, M> K = s.P * H.transpose() * S.inverse();
  s.x += K * innov;
  s.x(2) = autodrive::angle_wrap_rad(s.x(2));
  // Joseph form keeps P symmetric positive definite.
  const Mat5 I_KH = Mat5::Identity() - K * H;
  s.P = I_KH * s.P * I_KH.transpose() + K * R * K.transpose();
}

void Ekf::apply(Event &e, const Estimate &before) const {
  Estimate s = before;
  predict(s, e.t_us, p_);
  switch (e.kind) {
    case Kind::wheel: {
      // Speed, and the Ackermann yaw rate v tan(delta) / L as a second, looser measurement.
      const double v = e.z(0);
      Eigen::Matrix<double, 2, 5> H = Eigen::Matrix<double, 2, 5>::Zero();
      H(0, 3) = 1.0;
      const double k = std::tan(e.z(1)) / p_.wheelbase_m;
      H(1, 3) = k;
      H(1, 4) = -1.0;
      // Pseudo-measurement 0 = v k - w, linear in the state.
      Eigen::Matrix<double, 2, 1> innov;
      innov << v - s.x(3), 0.0 - (s.x(3) * k - s.x(4));
      Eigen::Matrix2d R = Eigen::Matrix2d::Zero();
      R(0, 0) = p_.r_speed_m_s * p_.r_speed_m_s;
      R(1, 1) = p_.r_ackermann_rad_s * p_.r_ackermann_rad_s;
      update<2>(s, innov, H, R);
      break;
    }
    case Kind::gyro: {
      Eigen::Matrix<double, 1, 5> H = Eigen::Matrix<double, 1, 5>::Zero();
      H(0, 4) = 1.0;
      Eigen::Matrix<double, 1, 1> innov, R;
      innov << e.z(0) - s.x(4);
      R << p_.r_gyro_rad_s * p_.r_gyro_rad_s;
      update<1>(s, innov, H, R);
      break;
    }
    case Kind::pose: {
      Eigen::Matrix<double, 3, 5> H = Eigen::Matrix<double, 3, 5>::Zero();
      H(0, 0) = H(1, 1) = H(2, 2) = 1.0;
      Eigen::Matrix<double, 3, 1> innov;
      innov << e.z(0) - s.x(0), e.z(1) - s.x(1), autodrive::angle_wrap_rad(e.z(2) - s.x(2));
      const Eigen::Matrix3d S = s.P.topLeftCorner<3, 3>() + e.R;
      e.gated = !(innov.dot(S.ldlt().solve(innov)) <= p_.pose_gate_chi2);
      if (!e.gated) update<3>(s, innov, H, e.R);
      break;
    }
  }
  e.after = s;
}

Ekf::Outcome Ekf::add(Event e) {
  if (!e.z.allFinite() || !e.R.allFinite()) {
    ++stats_.rejected;
    return Outcome::dropped;
  }
  if (!init_) {
    // Nothing to anchor the pose yet: start at this measurement's time.
    base_.t_us = e.t_us;
    cur_ = base_;
    init_ = true;
  }
  if (e.t_us < base_.t_us) {
    ++stats_.too_old;
    return Outcome::dropped;
  }
  bool gated = false;
  if (events_.empty() || e.t_us >= events_.back().t_us) {
    apply(e, cur_);
    cur_ = e.after;
    gated = e.gated;
    events_.push_back(std::move(e));
  } else {
    // Late: insert at its time and replay everything after it.
    ++stats_.replays;
    auto it = events_.begin();
    while (it != events_.end() && it->t_us <= e.t_us) ++it;
    it = events_.insert(it, std::move(e));
    for (auto j = it; j != events_.end(); ++j)
      apply(*j, j == events_.begin() ? base_ : (j - 1)->after);
    gated = it->gated;
    cur_ = events_.back().after;
  }
  // Forget what is older than the history window.
  while (!events_.empty() && events_.front().t_us < cur_.t_us - p_.history_us) {
    base_ = events_.front().after;
    events_.pop_front();
  }
  if (gated) {
    ++stats_.gated;
    return Outcome::gated;
  }
  ++stats_.fused;
  return Outcome::fused;
}

void Ekf::reacquire(int64_t t_us) {
  // Forget the pose (keep speed and yaw rate): the next pose places the car, as at start.
  Estimate s = estimate_at(std::max(t_us, cur_.t_us));
  s.P.row(0).setZero();
  s.P.row(1).setZero();
  s.P.row(2).setZero();
  s.P.col(0).setZero();
  s.P.col(1).setZero();
  s.P.col(2).setZero();
  s.P(0, 0) = s.P(1, 1) = 1e4;
  s.P(2, 2) = 10.0;
  events_.clear();
  base_ = cur_ = s;
  candidates_.clear();
  ++stats_.reacquired;
}

void Ekf::add_wheel(int64_t t_us, double speed_m_s, double steering_rad) {
  Event e{t_us, Kind::wheel, {speed_m_s, steering_rad, 0.0}, Eigen::Matrix3d::Zero(), {}, false};
  add(std::move(e));
}

void Ekf::add_gyro(int64_t t_us, double yaw_rate_rad_s) {
  Event e{t_us, Kind::gyro, {yaw_rate_rad_s, 0.0, 0.0}, Eigen::Matrix3d::Zero(), {}, false};
  add(std::move(e));
}

void Ekf::add_pose(int64_t t_us, double x_m, double y_m, double yaw_rad,
                   const Eigen::Matrix3d &cov) {
  const Outcome o = add(Event{t_us, Kind::pose, {x_m, y_m, yaw_rad}, cov, {}, false});
  if (o == Outcome::fused) {
    last_pose_us_ = std::max(last_pose_us_, t_us);
    candidates_.clear();
    return;
  }
  if (o != Outcome::gated || t_us - last_pose_us_ < p_.pose_reacquire_us) return;
  // Long without an accepted pose: is this one of a run that moves as the odometry says the
  // car moves (a constant offset: the odometry's drift), for at least reacquire_span_us? Then
  // re-place the car on it. A forged pose held still while the car drives is not.
  const Estimate s = estimate_at(t_us);
  const Eigen::Vector3d innov(x_m - s.x(0), y_m - s.x(1),
                              autodrive::angle_wrap_rad(yaw_rad - s.x(2)));
  if (!candidates_.empty()) {
    const Candidate &first = candidates_.front();
    Eigen::Vector3d d = innov - first.innov;
    d(2) = autodrive::angle_wrap_rad(d(2));
    const double span_s = (t_us - first.t_us) * 1e-6;
    const double drift = p_.reacquire_drift_per_s * span_s;  // odometry drift allowance
    Eigen::Matrix3d S = cov + first.cov;
    S.diagonal() += Eigen::Vector3d(drift * drift, drift * drift, drift * drift);
    if (!(d.dot(S.ldlt().solve(d)) <= p_.pose_gate_chi2)) candidates_.clear();
  }
  candidates_.push_back({t_us, innov, cov});
  if (static_cast<int>(candidates_.size()) < p_.reacquire_poses ||
      t_us - candidates_.front().t_us < p_.reacquire_span_us)
    return;
  reacquire(t_us);
  add(Event{t_us, Kind::pose, {x_m, y_m, yaw_rad}, cov, {}, false});
  last_pose_us_ = t_us;
}

double Ekf::pose_distance2(int64_t t_us, double x_m, double y_m, double yaw_rad,
                           const Eigen::Matrix3d &cov) const {
  const Estimate s = estimate_at(t_us);
  const Eigen::Vector3d innov(x_m - s.x(0), y_m - s.x(1),
                              autodrive::angle_wrap_rad(yaw_rad - s.x(2)));
  const Eigen::Matrix3d S = s.P.topLeftCorner<3, 3>() + cov;
  return innov.dot(S.ldlt().solve(innov));
}

Estimate Ekf::estimate_at(int64_t t_us) const {
  Estimate s = cur_;
  predict(s, t_us, p_);
  return s;
}

}  // namespace autodrive::estimator
