#include <autodrive/autonomy/pure_pursuit.hpp>

#include <autodrive/pure_pursuit.h>

#include <algorithm>
#include <cmath>

namespace autodrive::autonomy {

void PurePursuit::set_path(const Path &path) {
  path_ = path;
  segments_.clear();
  segments_xy_.clear();
  offsets_.clear();
  size_t begin = 0;
  for (size_t i = 1; i <= path.size(); ++i) {
    if (i == path.size() || path[i].direction != path[i - 1].direction) {
      // A segment owns its samples and the cusp sample that ends it.
      const size_t end = std::min(i + 1, path.size());
      Path seg(path.begin() + static_cast<long>(begin), path.begin() + static_cast<long>(end));
      for (auto &p : seg) p.direction = path[begin].direction;
      if (seg.size() >= 2) {
        segments_.push_back(seg);
        offsets_.push_back(begin);
        std::vector<double> xy;
        for (const auto &p : seg) xy.insert(xy.end(), {p.pose.x_m, p.pose.y_m});
        segments_xy_.push_back(std::move(xy));
      }
      begin = i;
    }
  }
  seg_ = 0;
  seg_offset_ = offsets_.empty() ? 0 : offsets_[0];
  nearest_ = 0;
  speed_m_s_ = 0.0;
  pause_left_s_ = 0.0;
  stalled_s_ = boost_ = 0.0;
  done_ = segments_.empty();
}

TrackerCommand PurePursuit::step(const Pose2 &pose, double dt_s, double measured_speed_m_s) {
  TrackerCommand cmd;
  if (done_) {
    cmd.done = true;
    speed_m_s_ = 0;
    stalled_s_ = boost_ = 0.0;
    return cmd;
  }
  if (pause_left_s_ > 0.0) {  // standing still at a cusp
    pause_left_s_ -= dt_s;
    speed_m_s_ = 0;
    stalled_s_ = boost_ = 0.0;
    return cmd;
  }
  const Path &seg = segments_[seg_];
  const int dir = seg.front().direction;
  const Eigen::Vector2d pos(pose.x_m, pose.y_m);
  auto pt = [&](size_t i) { return Eigen::Vector2d(seg[i].pose.x_m, seg[i].pose.y_m); };
  // Nearest sample, searched forward from the last one so loops cannot jump back.
  size_t best = nearest_;
  double best_d = (pt(best) - pos).norm();
  for (size_t i = nearest_; i < seg.size() && i < nearest_ + 60; ++i) {
    const double d = (pt(i) - pos).norm();
    if (d < best_d) {
      best_d = d;
      best = i;
    }
  }
  nearest_ = best;
  // Distance still to drive on this segment: along the samples, then the signed projection
  // onto the end tangent near the end (negative once past it).
  const Pose2 &end = seg.back().pose;
  const Eigen::Vector2d travel_end =
      dir * Eigen::Vector2d(std::cos(end.yaw_rad), std::sin(end.yaw_rad));
  double remaining_m = (pt(seg.size() - 1) - pos).dot(travel_end);
  if (nearest_ + 3 < seg.size()) {
    remaining_m = 0.0;
    for (size_t i = nearest_ + 1; i < seg.size(); ++i) remaining_m += (pt(i) - pt(i - 1)).norm();
  }
  if (remaining_m <= cfg_.stop_tolerance_m) {
    speed_m_s_ = 0;
    if (seg_ + 1 < segments_.size()) {
      ++seg_;
      seg_offset_ = offsets_[seg_];
      nearest_ = 0;
      pause_left_s_ = cfg_.cusp_pause_s;
    } else {
      done_ = true;
      cmd.done = true;
    }
    return cmd;
  }
  // Speed profile.
  double v = cfg_.cruise_speed_m_s;
  v = std::min(
      v, std::sqrt(2.0 * cfg_.decel_m_s2 * std::max(0.0, remaining_m - cfg_.stop_tolerance_m)));
  const double k_here = std::abs(seg[nearest_].curvature_1pm);
  if (k_here > 1e-6) v = std::min(v, std::sqrt(cfg_.lateral_accel_m_s2 / k_here));
  // Slow down ahead of curvature changes so the steering (rate limited) gets there in time.
  {
    double d_ahead = 0.0;
    for (size_t j = nearest_ + 1; j < seg.size() && d_ahead < cfg_.steer_preview_m; ++j) {
      d_ahead += (pt(j) - pt(j - 1)).norm();
      const double delta_rad =
          std::abs(std::atan(seg[j].curvature_1pm * cfg_.wheelbase_m) - last_steer_rad_);
      if (delta_rad > 0.02)
        v = std::min(v, cfg_.steer_rate_rad_s * 0.6 * (d_ahead + 0.01) / delta_rad);
    }
  }
  v = std::max(v, cfg_.min_speed_m_s);
  v = std::min(v, speed_m_s_ + cfg_.accel_m_s2 * dt_s);
  speed_m_s_ = v;
  // Lookahead point: the first sample ld away, or on the last arc extended past the end.
  const double ld = pp_lookahead_m(cfg_.lookahead_min_m, cfg_.lookahead_time_s, v);
  const int n = static_cast<int>(seg.size());
  const int goal = pp_goal_index(segments_xy_[seg_].data(), n, static_cast<int>(nearest_), pose.x_m,
                                 pose.y_m, ld);
  Eigen::Vector2d target = pt(seg.size() - 1);
  if (goal < n) {
    target = pt(static_cast<size_t>(goal));
  } else {
    // Past the end: continue the last arc (not the tangent, which would cut the final turn
    // and leave the heading short) until the point is ld away.
    const double k_end = seg[seg.size() >= 2 ? seg.size() - 2 : 0].curvature_1pm;
    Pose2 q = end;
    for (int i = 0; i < 100 && (Eigen::Vector2d(q.x_m, q.y_m) - pos).norm() < ld; ++i)
      q = arc_step(q, dir * 0.005, k_end);
    target = {q.x_m, q.y_m};
  }
  // The one pure pursuit law, the same forward and reverse (see <autodrive/pure_pursuit.h>).
  const pp_vehicle_t car = {cfg_.wheelbase_m, cfg_.max_steer_rad};
  cmd.steer_rad = pp_steer_to(pose.x_m, pose.y_m, pose.yaw_rad, target.x(), target.y(), &car);
  cmd.steering = cmd.steer_rad / cfg_.max_steer_rad;
  last_steer_rad_ = cmd.steer_rad;
  cmd.speed_m_s = dir * v;
  update_stall_boost(dir * measured_speed_m_s, v, dt_s);
  cmd.throttle = std::clamp(dir * (v / cfg_.top_speed_m_s + boost_), -1.0, 1.0);
  return cmd;
}

void PurePursuit::update_stall_boost(double along_m_s, double target_m_s, double dt_s) {
  if (!std::isfinite(along_m_s)) return;
  if (along_m_s >= cfg_.boost_release_fraction * target_m_s) {  // moving: let the boost go
    stalled_s_ = 0.0;
    boost_ = std::max(0.0, boost_ - 2.0 * cfg_.boost_rate_per_s * dt_s);
    return;
  }
  if (along_m_s >= cfg_.stall_fraction * target_m_s) return;  // slow, not stuck: hold
  stalled_s_ += dt_s;
  if (stalled_s_ >= cfg_.stall_s)
    boost_ = std::min(cfg_.boost_max, boost_ + cfg_.boost_rate_per_s * dt_s);
}

}  // namespace autodrive::autonomy
