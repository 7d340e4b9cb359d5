#include <autodrive/autonomy/odom_history.hpp>

#include <algorithm>

namespace autodrive::autonomy {

void OdomHistory::add(int64_t utime_us, const Pose2 &odom) {
  if (!samples_.empty() && utime_us < samples_.back().utime_us) samples_.clear();
  samples_.push_back({utime_us, odom});
  while (samples_.size() > 2 && samples_.front().utime_us < utime_us - keep_us_)
    samples_.pop_front();
}

std::optional<Pose2> OdomHistory::at(int64_t utime_us) const {
  if (samples_.empty()) return std::nullopt;
  if (utime_us <= samples_.front().utime_us) return samples_.front().pose;
  if (utime_us >= samples_.back().utime_us) return samples_.back().pose;
  const auto hi = std::lower_bound(samples_.begin(), samples_.end(), utime_us,
                                   [](const Sample &s, int64_t t) { return s.utime_us < t; });
  const auto lo = hi - 1;
  const double f = static_cast<double>(utime_us - lo->utime_us) /
                   static_cast<double>(std::max<int64_t>(1, hi->utime_us - lo->utime_us));
  // Interpolate the relative motion, so the heading wraps correctly.
  const Pose2 d = pose_between(lo->pose, hi->pose);
  return pose_compose(lo->pose, {f * d.x_m, f * d.y_m, f * d.yaw_rad});
}

}  // namespace autodrive::autonomy
