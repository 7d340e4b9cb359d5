// Publishes car poses as autodrive::pose2d_t on <VEH>_POSE_EYE, signed with the Eye's
// certificate (role eye): the car's estimator takes no other.
#pragma once
#include <autodrive/v2x.hpp>
#include <lcm/lcm-cpp.hpp>

#include <cstdint>
#include <vector>

#include "eye_health.hpp"
#include "eye_locate.hpp"

namespace eye {

// One message per pose, stamped (and signed) with the frame's capture time utime [us, the
// frame's clock: sim time in HIL]. Returns how many were published (publish failures are
// counted out, not thrown).
int publish_poses(lcm::LCM &lcm, autodrive::v2x::Signer &signer, const std::vector<CarPose> &poses,
                  int64_t utime);

// Publishes one camera's status on EYE_CAMERA_STATUS; returns whether LCM took it.
bool publish_status(lcm::LCM &lcm, const CameraStatus &st, int width_px, int height_px);

}  // namespace eye
