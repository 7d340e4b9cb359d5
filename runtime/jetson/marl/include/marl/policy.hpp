// A trained intersection policy: NAME.onnx (input `obs` float32 [N, D], output `action`:
// logits over a discrete steering set, or a continuous steering mean) run with OpenCV DNN,
// and NAME.json beside it, the one place of what the network means:
//   {"obs_version": V, "obs_dim": D, "actions": [-1, 0, 1] | "continuous",
//    "control_period_s": 0.05, "throttle": 0.6, "waypoint_lookahead_m": 0.3}
// (obs_version, obs_dim: the MARL core's observation layout it was trained on;
// waypoint_lookahead_m: the route waypoint's distance ahead in that observation [m]).
// (actions: the steering value of each logit, or "continuous" for one output in [-1, 1]).
#pragma once

#include <memory>
#include <string>
#include <vector>

namespace marl {

struct PolicySpec {
  int obs_version = 0;
  int obs_dim = 0;
  std::vector<double> steering_actions;  // empty: continuous
  double control_period_s = 0.05;        // [s]
  double throttle = 0.5;                 // [-1, 1], constant
  double waypoint_lookahead_m = 0.3;     // [m]
};

// Reads NAME.json; throws std::runtime_error naming the file and the key that is wrong.
PolicySpec read_policy_spec(const std::string &json_path);

class Policy {
 public:
  // onnx_path = NAME.onnx; its spec is NAME.json. Throws std::runtime_error naming the file
  // when either cannot be read, the network does not load, or its output does not fit the spec.
  explicit Policy(const std::string &onnx_path);
  ~Policy();
  const PolicySpec &spec() const { return spec_; }
  // The network's raw output for one observation (logits or the mean).
  std::vector<float> forward(const std::vector<float> &obs);
  // The steering [-1, 1] for one observation (argmax of the logits, or the clipped mean).
  double steering(const std::vector<float> &obs);

 private:
  struct Net;
  PolicySpec spec_;
  std::unique_ptr<Net> net_;
};

}  // namespace marl
