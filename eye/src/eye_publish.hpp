// Publishes car poses as autodrive::pose2d_t on <VEH>_POSE_EYE.
#pragma once
#include <lcm/lcm-cpp.hpp>

#include <cstdint>
#include <vector>

#include "eye_health.hpp"
#include "eye_locate.hpp"

namespace eye {

// One message per pose, stamped with the frame's capture time utime [us]. Returns how many
// were published (publish failures are counted out, not thrown).
int publish_poses(lcm::LCM &lcm, const std::vector<CarPose> &poses, int64_t utime);

// Publishes one camera's status on EYE_CAMERA_STATUS; returns whether LCM took it.
bool publish_status(lcm::LCM &lcm, const CameraStatus &st, int width_px, int height_px);

}  // namespace eye
