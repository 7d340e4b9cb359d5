// odom_history_: the last few seconds of odometry poses, so a LIDAR scan is placed where the
// car was while it was measured (~70 ms before it arrives at 7 Hz), not where it is when the
// scan is processed. At 0.2 m/s that lag alone is 1.5-3 cm of localisation error.
#pragma once
#include <cstdint>
#include <deque>
#include <optional>

#include <autodrive/autonomy/geometry.hpp>

namespace autodrive::autonomy {

class OdomHistory {
 public:
  explicit OdomHistory(int64_t keep_us = 2000000) : keep_us_(keep_us) {}
  // Stamps must not go back; an older stamp (a restarted clock) clears the history.
  void add(int64_t utime_us, const Pose2 &odom);
  // Pose at utime_us, interpolated between the two samples around it; clamped to the oldest
  // / newest sample outside the kept span; nullopt when empty.
  std::optional<Pose2> at(int64_t utime_us) const;
  bool empty() const { return samples_.empty(); }

 private:
  struct Sample {
    int64_t utime_us;
    Pose2 pose;
  };
  int64_t keep_us_;
  std::deque<Sample> samples_;
};

}  // namespace autodrive::autonomy
