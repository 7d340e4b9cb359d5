// Publishes car poses as autodrive::pose2d_t on <VEH>_POSE_EYE.
#pragma once
#include <lcm/lcm-cpp.hpp>

#include <cstdint>
#include <vector>

#include "eye_locate.hpp"

namespace eye {

// One message per pose, stamped with the frame's capture time utime [us]. Returns how many
// were published (publish failures are counted out, not thrown).
int publish_poses(lcm::LCM &lcm, const std::vector<CarPose> &poses, int64_t utime);

}  // namespace eye
