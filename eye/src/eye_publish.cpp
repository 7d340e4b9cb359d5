#include <autodrive_channels.h>
#include <autodrive_lcm/pose2d.hpp>
#include "eye_publish.hpp"

#include <autodrive/eye_camera_status_t.hpp>
#include <autodrive/pose2d_t.hpp>

namespace eye {

int publish_poses(lcm::LCM &lcm, autodrive::v2x::Signer &signer, const std::vector<CarPose> &poses,
                  int64_t utime) {
  int n = 0;
  for (const auto &p : poses) {
    autodrive::pose2d_t m = autodrive_lcm::map_pose2d(
        utime, p.vehicle, autodrive::pose2d_t::SOURCE_EYE, p.x_m, p.y_m, p.yaw_rad, p.cov);
    const std::string channel = p.vehicle + AUTODRIVE_CH_POSE_EYE_SUFFIX;
    signer.sign(channel, m, utime);
    if (lcm.publish(channel, &m) == 0) ++n;
  }
  return n;
}

bool publish_status(lcm::LCM &lcm, const CameraStatus &st, int width_px, int height_px) {
  autodrive::eye_camera_status_t m;
  m.utime = st.utime;
  m.camera = st.camera;
  m.width_px = width_px;
  m.height_px = height_px;
  m.fps_hz = static_cast<float>(st.fps_hz);
  m.frames = st.frames;
  m.tags_seen = static_cast<int16_t>(st.tags_seen);
  m.cars_seen = static_cast<int16_t>(st.cars_seen);
  m.ref_tags_seen = static_cast<int16_t>(st.ref_tags_seen);
  m.ref_residual_rms_mm = static_cast<float>(st.ref_rms_mm);
  m.ref_residual_rms_px = static_cast<float>(st.ref_rms_px);
  m.moved = st.moved;
  m.cov_scale = static_cast<float>(st.cov_scale);
  return lcm.publish(AUTODRIVE_CH_EYE_CAMERA_STATUS, &m) == 0;
}

}  // namespace eye
