// Planar EKF for Nigel (no I/O). State [x_m, y_m, yaw_rad, v_m_s, yaw_rate_rad_s] with a
// constant-velocity process model. Measurements: wheel-odometry speed with the Ackermann yaw
// rate from the applied steering angle, IMU gyro yaw rate, and absolute poses (Eye/IPS).
// Late measurements: every measurement in the last `history_us` is kept with the state after
// it; one that arrives out of order is inserted at its own time and the ones after it are
// replayed, so a 100 ms-old Eye pose corrects the state as of 100 ms ago. Older than the
// history -> dropped and counted. Missing measurements simply let the covariance grow.
// Poses are gated: one whose squared Mahalanobis distance to the estimate exceeds
// pose_gate_chi2 is rejected and counted (a forged or wrong pose cannot move the estimate).
// The first fix passes (the covariance before it is huge). Re-acquisition: when no pose was
// accepted for pose_reacquire_us, a run of rejected poses (reacquire_poses of them over
// reacquire_span_us) whose innovation (pose - estimate) stays the same, i.e. that move as the
// odometry says the car moves, re-places the car. While the real Eye keeps being accepted this
// never happens; a forged pose held still while the car drives never qualifies. (Limit: with
// the car standing still and the real Eye gone, a steady forged stream is indistinguishable
// from a real re-acquisition; it is logged.)
#pragma once

#include <autodrive_vehicle.h>
#include <Eigen/Dense>

#include <cstdint>
#include <deque>

namespace autodrive::estimator {

using Vec5 = Eigen::Matrix<double, 5, 1>;
using Mat5 = Eigen::Matrix<double, 5, 5>;

struct EkfParams {
  double wheelbase_m = AUTODRIVE_VEHICLE_WHEELBASE_M;
  double q_pos_m = 0.01;                // position random walk [m/sqrt(s)]
  double q_yaw_rad = 0.01;              // heading random walk [rad/sqrt(s)]
  double q_accel_m_s2 = 1.0;            // speed change [m/s/sqrt(s)]
  double q_yaw_accel_rad_s2 = 2.0;      // yaw-rate change [rad/s/sqrt(s)]
  double r_speed_m_s = 0.02;            // wheel-speed noise [m/s]
  double r_ackermann_rad_s = 0.1;       // Ackermann yaw-rate noise (slip, steering lag) [rad/s]
  double r_gyro_rad_s = 0.02;           // gyro z noise [rad/s]
  int64_t history_us = 1000000;         // how late a measurement may be [us]
  double pose_gate_chi2 = 16.3;         // squared Mahalanobis distance, 3 dof (99.9 %)
  int64_t pose_reacquire_us = 5000000;  // no accepted pose for this long -> may re-acquire [us]
  int reacquire_poses = 5;              // consistent gated poses needed to re-acquire
  int64_t reacquire_span_us = 1000000;  // ... spanning at least this long [us]
  double reacquire_drift_per_s = 0.05;  // odometry drift allowed within the run [m/s, rad/s]
};

struct Estimate {
  int64_t t_us = 0;
  Vec5 x = Vec5::Zero();
  Mat5 P = Mat5::Identity();
};

struct EkfStats {
  uint64_t fused = 0;       // measurements applied
  uint64_t replays = 0;     // late measurements inserted in the past and replayed
  uint64_t too_old = 0;     // dropped: older than the history window
  uint64_t rejected = 0;    // dropped: non-finite values
  uint64_t gated = 0;       // poses dropped by the Mahalanobis gate
  uint64_t reacquired = 0;  // times a run of consistent poses re-placed the car
};

class Ekf {
 public:
  explicit Ekf(EkfParams p = {});
  // Sets the state at t_us (pose with the given variances, zero speed).
  void reset(int64_t t_us, double x_m, double y_m, double yaw_rad, double pos_var_m2,
             double yaw_var_rad2);
  bool initialised() const { return init_; }

  void add_wheel(int64_t t_us, double speed_m_s, double steering_rad);
  void add_gyro(int64_t t_us, double yaw_rate_rad_s);
  // Absolute pose in the filter's frame, covariance x, y, yaw [m^2, rad^2].
  void add_pose(int64_t t_us, double x_m, double y_m, double yaw_rad, const Eigen::Matrix3d &cov);

  // The latest estimate, predicted forward to t_us (no change to the filter).
  Estimate estimate_at(int64_t t_us) const;
  const Estimate &latest() const { return cur_; }
  const EkfStats &stats() const { return stats_; }
  // The squared Mahalanobis distance of a pose to the estimate at t_us (no change).
  double pose_distance2(int64_t t_us, double x_m, double y_m, double yaw_rad,
                        const Eigen::Matrix3d &cov) const;

 private:
  enum class Kind { wheel, gyro, pose };
  struct Event {
    int64_t t_us;
    Kind kind;
    Eigen::Matrix<double, 3, 1> z;  // wheel: speed, steering; gyro: rate; pose: x y yaw
    Eigen::Matrix3d R;              // pose covariance
    Estimate after;                 // the state right after this event
    bool gated = false;             // pose: rejected by the gate (after = predicted state)
  };
  enum class Outcome { fused, gated, dropped };
  Outcome add(Event e);
  void reacquire(int64_t t_us);
  void apply(Event &e, const Estimate &before) const;
  static void predict(Estimate &s, int64_t t_us, const EkfParams &p);
  template <int M>
  static void update(Estimate &s, const Eigen::Matrix<double, M, 1> &innov,
                     const Eigen::Matrix<double, M, 5> &H, const Eigen::Matrix<double, M, M> &R);

  EkfParams p_;
  bool init_ = false;
  Estimate base_;             // state before the oldest kept event
  Estimate cur_;              // state after the newest event
  std::deque<Event> events_;  // time-ordered
  EkfStats stats_;
  int64_t last_pose_us_ = 0;  // time of the last accepted pose (0: none yet)
  struct Candidate {
    int64_t t_us;
    Eigen::Vector3d innov;  // pose - estimate
    Eigen::Matrix3d cov;
  };
  std::deque<Candidate> candidates_;  // a run of gated poses with a steady innovation
};

}  // namespace autodrive::estimator
