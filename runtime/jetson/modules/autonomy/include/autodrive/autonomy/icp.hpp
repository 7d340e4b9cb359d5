// icp_: laser odometry by scan-to-scan ICP, point-to-line metric (Censi's PL-ICP idea,
// linearised): each current point is pulled onto the line through its nearest reference
// point and that point's neighbour in the reference scan.
#pragma once
#include <vector>

#include <autodrive/autonomy/geometry.hpp>

namespace autodrive::autonomy {

struct IcpConfig {
  int max_iterations = 40;
  double max_correspondence_m = 0.3;  // first iteration; shrinks to min_ below
  double min_correspondence_m = 0.05;
  double converged_step_m = 1e-5;
  double converged_step_rad = 1e-5;
};

struct IcpResult {
  Pose2 motion;      // pose of the current scan's frame in the reference scan's frame
  double rms_m = 0;  // point-to-line residual of the inliers [m]
  int inliers = 0;
  bool failed = false;  // false = healthy (enough inliers, finite solution)
};

// ref, cur: scan endpoints (same sensor, ordered by angle) in their own frames [m].
IcpResult icp_match(const std::vector<Eigen::Vector2d> &ref,
                    const std::vector<Eigen::Vector2d> &cur, const Pose2 &guess,
                    const IcpConfig &cfg = IcpConfig{});

}  // namespace autodrive::autonomy
