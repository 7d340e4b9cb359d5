// V2V component of the runtime: broadcasts this car's state (v2v_state_t on V2V) at v2v_hz of
// message time, from the EKF's map-frame pose (<VEH>_POSE_MAP) and the applied command
// (<VEH>_STATE); keeps a PeerTable of the other cars and logs its status every 5 s (fresh peers
// and the stale states dropped). No map pose yet (no Eye, no estimator.initial_pose_map): no
// broadcast, said once.
#pragma once

#include <atomic>
#include <memory>
#include <string>

#include <autodrive/core/config.hpp>

namespace autodrive::v2v {

class V2vNode {
 public:
  explicit V2vNode(const autodrive::config::Config &config);
  ~V2vNode();
  std::string init_error() const;
  void run(const std::atomic<bool> &stop);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace autodrive::v2v
