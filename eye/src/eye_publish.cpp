#include <autodrive_channels.h>
#include <autodrive_lcm/pose2d.hpp>
#include "eye_publish.hpp"

#include <autodrive/pose2d_t.hpp>

namespace eye {

int publish_poses(lcm::LCM &lcm, const std::vector<CarPose> &poses, int64_t utime) {
  int n = 0;
  for (const auto &p : poses) {
    const autodrive::pose2d_t m = autodrive_lcm::map_pose2d(
        utime, p.vehicle, autodrive::pose2d_t::SOURCE_EYE, p.x_m, p.y_m, p.yaw_rad, p.cov);
    if (lcm.publish(p.vehicle + AUTODRIVE_CH_POSE_EYE_SUFFIX, &m) == 0) ++n;
  }
  return n;
}

}  // namespace eye
