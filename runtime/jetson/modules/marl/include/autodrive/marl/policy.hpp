// A trained intersection policy: NAME.onnx (input `obs` float32 [N, D], output `action`:
// logits over a discrete action set, or a continuous steering mean) run with OpenCV DNN, and
// NAME.json beside it (written by tools/marl's export, python/autodrive/learn/marl/export.py),
// the one place of what the network means. The keys read here:
//   {"obs": {"layout_version": V, "dim": D},
//    "action": {"type": "discrete", "throttle_steering": [[1.0, -1.0], [1.0, 0.0], ...]}
//            | {"type": "continuous", "throttle": 1.0},
//    "control_period_s": 0.1}
#pragma once

#include <memory>
#include <string>
#include <utility>
#include <vector>

namespace autodrive::marl {

struct PolicySpec {
  int obs_version = 0;
  int obs_dim = 0;
  // Discrete: (throttle, steering) of each logit; empty: continuous.
  std::vector<std::pair<double, double>> actions;
  double continuous_throttle = 0;  // continuous: the constant throttle [-1, 1]
  double control_period_s = 0.1;   // [s]
};

struct PolicyCommand {
  double throttle = 0, steering = 0;  // [-1, 1]
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
  // The command for one observation (the argmax logit's, or the clipped mean steering).
  PolicyCommand act(const std::vector<float> &obs);

 private:
  struct Net;
  PolicySpec spec_;
  std::unique_ptr<Net> net_;
};

}  // namespace autodrive::marl
