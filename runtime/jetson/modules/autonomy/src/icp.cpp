#include <autodrive/autonomy/icp.hpp>

#include <cmath>
#include <limits>

#include <Eigen/Dense>

namespace autodrive::autonomy {

IcpResult icp_match(const std::vector<Eigen::Vector2d> &ref,
                    const std::vector<Eigen::Vector2d> &cur, const Pose2 &guess,
                    const IcpConfig &cfg) {
  IcpResult res;
  res.motion = guess;
  if (ref.size() < 10 || cur.size() < 10) {
    res.failed = true;
    return res;
  }
  // Normals of the reference points from their ordered neighbours (none across big gaps).
  std::vector<Eigen::Vector2d> normal(ref.size(), Eigen::Vector2d::Zero());
  for (size_t j = 0; j < ref.size(); ++j) {
    const size_t a = j == 0 ? 0 : j - 1, b = j + 1 == ref.size() ? j : j + 1;
    const Eigen::Vector2d t = ref[b] - ref[a];
    if (t.norm() > 1e-6 && t.norm() < 0.25) normal[j] = Eigen::Vector2d(-t.y(), t.x()).normalized();
  }
  Pose2 p = guess;
  for (int it = 0; it < cfg.max_iterations; ++it) {
    const double frac = std::min(1.0, it / 10.0);
    const double gate_m =
        cfg.max_correspondence_m + frac * (cfg.min_correspondence_m - cfg.max_correspondence_m);
    Eigen::Matrix3d H = Eigen::Matrix3d::Zero();
    Eigen::Vector3d g = Eigen::Vector3d::Zero();
    const double c = std::cos(p.yaw_rad), s = std::sin(p.yaw_rad);
    double sq_sum = 0;
    int n = 0;
    for (const auto &q : cur) {
      const Eigen::Vector2d w = pose_apply(p, q);
      double best = std::numeric_limits<double>::max();
      size_t bj = 0;
      for (size_t j = 0; j < ref.size(); ++j) {
        const double d2 = (ref[j] - w).squaredNorm();
        if (d2 < best) {
          best = d2;
          bj = j;
        }
      }
      if (best > gate_m * gate_m) continue;
      const Eigen::Vector2d dw_dth(-s * q.x() - c * q.y(), c * q.x() - s * q.y());
      const Eigen::Vector2d diff = w - ref[bj];
      if (normal[bj].squaredNorm() > 0.5) {  // point-to-line
        const Eigen::Vector2d &nn = normal[bj];
        const double e = nn.dot(diff);
        const Eigen::Vector3d J(nn.x(), nn.y(), nn.dot(dw_dth));
        H += J * J.transpose();
        g += J * e;
        sq_sum += e * e;
      } else {  // isolated point: point-to-point
        Eigen::Matrix<double, 2, 3> J;
        J << 1, 0, dw_dth.x(), 0, 1, dw_dth.y();
        H += J.transpose() * J;
        g += J.transpose() * diff;
        sq_sum += diff.squaredNorm();
      }
      ++n;
    }
    res.inliers = n;
    res.rms_m = n > 0 ? std::sqrt(sq_sum / n) : 0.0;
    if (n < 10) {
      res.failed = true;
      return res;
    }
    const Eigen::Vector3d d = -(H + 1e-9 * Eigen::Matrix3d::Identity()).ldlt().solve(g);
    if (!d.allFinite()) {
      res.failed = true;
      return res;
    }
    p.x_m += d.x();
    p.y_m += d.y();
    p.yaw_rad = angle_wrap_rad(p.yaw_rad + d.z());
    if (it >= 10 && d.head<2>().norm() < cfg.converged_step_m &&
        std::abs(d.z()) < cfg.converged_step_rad)
      break;
  }
  res.motion = p;
  return res;
}

}  // namespace autodrive::autonomy
