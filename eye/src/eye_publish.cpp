#include <autodrive_channels.h>
#include "eye_publish.hpp"

#include <autodrive/pose2d_t.hpp>

namespace eye {

int publish_poses(lcm::LCM &lcm, const std::vector<CarPose> &poses, int64_t utime) {
  int n = 0;
  for (const auto &p : poses) {
    autodrive::pose2d_t m;
    m.utime = utime;
    m.vehicle = p.vehicle;
    m.frame_id = "map";
    m.source = autodrive::pose2d_t::SOURCE_EYE;
    m.x_m = p.x_m;
    m.y_m = p.y_m;
    m.yaw_rad = p.yaw_rad;
    for (int i = 0; i < 9; ++i) m.covariance[i] = p.cov[static_cast<size_t>(i)];
    if (lcm.publish(p.vehicle + AUTODRIVE_CH_POSE_EYE_SUFFIX, &m) == 0) ++n;
  }
  return n;
}

}  // namespace eye
