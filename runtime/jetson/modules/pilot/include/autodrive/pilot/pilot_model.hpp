// The behavioural-cloning model of autodrive-pilot: an ONNX network (run by OpenCV's DNN module)
// and its JSON sidecar, the one place of its preprocessing (contract: NAME.onnx + NAME.json,
// input `frames` float32 [N,3,H,W], output `steering` float32 [N,1] in [-1, 1]).
// Loading refuses, naming the file, a missing or truncated model, a checksum that differs from
// the sidecar's, an opset outside what OpenCV 4.6 runs here, or a network that cannot take the
// sidecar's input shape.
#pragma once

#include <opencv2/core.hpp>
#include <opencv2/dnn.hpp>

#include <algorithm>
#include <array>
#include <string>

namespace autodrive::pilot {

constexpr int kMinOpset = 11;  // the contract's opsets, which OpenCV 4.6's importer runs
constexpr int kMaxOpset = 13;

enum class Colour { yuv, bgr, rgb };

// The sidecar's "input" section: how a camera frame becomes the network's input.
struct InputSpec {
  int source_width_px = 0, source_height_px = 0;  // the camera frame the model expects
  int crop_top_px = 0, crop_bottom_px = 0;        // rows cut off before resizing
  int width_px = 0, height_px = 0;                // the network's input size
  Colour colour = Colour::yuv;
  double scale = 1.0 / 255.0;  // applied to the 8-bit values first
  std::array<double, 3> mean{}, std{};
};

// Reads NAME.json; autodrive::InputError naming the file and the key on anything missing or
// out of range. opset and onnx_sha256 are returned through the out parameters.
InputSpec read_sidecar(const std::string &json_path, int &opset, std::string &onnx_sha256);

// The sidecar of a model: NAME.onnx -> NAME.json.
std::string sidecar_path(const std::string &onnx_path);

// The opset of the default ONNX domain from the model's ModelProto (top-level fields only);
// autodrive::InputError naming the file when the bytes end inside a field (a truncated file)
// or hold no opset.
int onnx_opset(const std::string &onnx_path, const std::string &bytes);

// A decoded camera frame (8-bit BGR, as cv::imdecode gives) -> the network input [1,3,H,W]
// float32: crop rows, cv::resize INTER_AREA, colour conversion, scale, mean, std, NCHW.
// InputError when the frame is not the size the model was trained on.
cv::Mat preprocess(const cv::Mat &bgr, const InputSpec &spec);

class PilotModel {
 public:
  // Loads onnx_path and its sidecar and runs one forward pass on a zero input to prove the
  // shape; autodrive::InputError naming the file otherwise.
  explicit PilotModel(const std::string &onnx_path);
  // The network's output for one preprocessed input, as it is (the tests compare it).
  float raw(const cv::Mat &blob);
  // The same clamped to the steering range [-1, 1].
  float steering(const cv::Mat &blob) { return std::clamp(raw(blob), -1.0f, 1.0f); }
  const InputSpec &spec() const { return spec_; }
  int opset() const { return opset_; }
  const std::string &path() const { return path_; }

 private:
  std::string path_;
  InputSpec spec_;
  int opset_ = 0;
  cv::dnn::Net net_;
};

}  // namespace autodrive::pilot
