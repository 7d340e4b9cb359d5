// State estimator component: <VEH>_STATE (encoders, applied steering) + <VEH>_IMU (gyro z)
// + <VEH>_POSE_EYE -> <VEH>_ODOM (odometry only, continuous) and <VEH>_POSE_MAP (with the
// Eye, in the map frame). Publishes at each STATE, at most at estimator.rate_hz.
// Its only clock is the messages' stamps (wall or SIM_CLOCK time, given by the bridge's
// autodrive::clock::Clock), so an LCM log replayed through file:// gives the outputs of the run
// again.
#pragma once

#include <atomic>
#include <memory>
#include <string>
#include <cstdint>

#include <autodrive/core/config.hpp>
#include <autodrive/estimator/ekf.hpp>

namespace autodrive::estimator {

// Converts two encoder samples to the mean rear-wheel speed [m/s]; dt from the Nano clock
// (a u32 microsecond counter that wraps). Returns false if dt is not usable.
bool wheel_speed_from_encoders(int32_t prev_l, int32_t prev_r, int64_t prev_nano_us, int32_t l,
                               int32_t r, int64_t nano_us, int counts_per_rev,
                               double wheel_radius_m, double *speed_m_s);

EkfParams params_from_config(const autodrive::config::Config &c);

// Whose Eye poses the estimator takes: only those signed by an eye-role certificate, fresh on
// the car's clock (the last STATE's stamp: SIM_CLOCK time in HIL) and with a counter above
// that Eye's last (live); or every pose of a recorded log, checked when it was recorded
// (replay: the stored logs predate signed poses).
enum class EyePoseAuth { verify, trust_recorded_log };

// Inputs the estimator refused (each also logged at a limited rate, naming the channel).
struct InputStats {
  uint64_t poses_gated = 0;             // <VEH>_POSE_EYE poses rejected by the Mahalanobis gate
  uint64_t reacquired = 0;              // re-placements after a long gap (map filter)
  uint64_t wheel_dropped = 0;           // <VEH>_STATE encoder speed or steering out of range
  uint64_t gyro_dropped = 0;            // <VEH>_IMU gyro z out of range
  uint64_t poses_future = 0;            // <VEH>_POSE_EYE stamped > 1 s ahead of the last STATE
  uint64_t poses_unauthenticated = 0;   // <VEH>_POSE_EYE refused by the signature check
  std::string poses_refused_by_reason;  // "unsigned=3, forged signature=1" ("" when none)
};

class EstimatorNode {
 public:
  // Inputs from config.lcm_url; outputs there too, or to output_url if given (replay).
  explicit EstimatorNode(const autodrive::config::Config &config,
                         const std::string &output_url = "",
                         EyePoseAuth eye_auth = EyePoseAuth::verify);
  ~EstimatorNode();
  std::string init_error() const;
  void run(const std::atomic<bool> &stop);
  // Feeds every message of a file:// input (the config's lcm_url) through the estimator, as
  // fast as it goes; returns the number of messages handled.
  long replay();
  InputStats input_stats() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace autodrive::estimator
