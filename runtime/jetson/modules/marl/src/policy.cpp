#include <autodrive/marl/policy.hpp>

#include <nlohmann/json.hpp>
#include <opencv2/dnn.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <stdexcept>

namespace autodrive::marl {

namespace {
[[noreturn]] void bad(const std::string &file, const std::string &what) {
  throw std::runtime_error(file + ": " + what);
}
}  // namespace

PolicySpec read_policy_spec(const std::string &json_path) {
  std::ifstream f(json_path);
  if (!f) bad(json_path, "cannot be read (the policy's spec must sit beside its .onnx)");
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(f);
  } catch (const std::exception &e) {
    bad(json_path, std::string("not JSON: ") + e.what());
  }
  auto need = [&](const nlohmann::json &o, const std::string &where,
                  const char *key) -> const nlohmann::json & {
    if (!o.is_object() || !o.contains(key)) bad(json_path, where + key + ": missing key");
    return o.at(key);
  };
  PolicySpec s;
  const auto &obs = need(j, "", "obs");
  const auto &version = need(obs, "obs.", "layout_version");
  if (!version.is_number_integer()) bad(json_path, "obs.layout_version: not an integer");
  s.obs_version = version.get<int>();
  const auto &dim = need(obs, "obs.", "dim");
  if (!dim.is_number_integer() || dim.get<int>() < 1 || dim.get<int>() > 4096)
    bad(json_path, "obs.dim: not an integer in 1..4096");
  s.obs_dim = dim.get<int>();
  const auto &action = need(j, "", "action");
  const auto &type = need(action, "action.", "type");
  const auto in_range = [](const nlohmann::json &v) {
    return v.is_number() && std::abs(v.get<double>()) <= 1.0;
  };
  if (type == "discrete") {
    const auto &table = need(action, "action.", "throttle_steering");
    if (!table.is_array() || table.size() < 2)
      bad(json_path, "action.throttle_steering: not a list of >= 2 [throttle, steering] pairs");
    for (const auto &a : table) {
      if (!a.is_array() || a.size() != 2 || !in_range(a[0]) || !in_range(a[1]))
        bad(json_path,
            "action.throttle_steering: every entry must be [throttle, steering], "
            "each in [-1, 1]");
      s.actions.emplace_back(a[0].get<double>(), a[1].get<double>());
    }
  } else if (type == "continuous") {
    const auto &thr = need(action, "action.", "throttle");
    if (!in_range(thr)) bad(json_path, "action.throttle: not a number in [-1, 1]");
    s.continuous_throttle = thr.get<double>();
  } else {
    bad(json_path, "action.type: neither \"discrete\" nor \"continuous\"");
  }
  const auto &period = need(j, "", "control_period_s");
  if (!period.is_number() || !(period.get<double>() >= 0.005 && period.get<double>() <= 1.0))
    bad(json_path, "control_period_s: not a number in [0.005, 1] s");
  s.control_period_s = period.get<double>();
  return s;
}

struct Policy::Net {
  cv::dnn::Net net;
};

Policy::Policy(const std::string &onnx_path) : net_(std::make_unique<Net>()) {
  namespace fs = std::filesystem;
  if (fs::path(onnx_path).extension() != ".onnx")
    bad(onnx_path, "not a .onnx file (give the policy as NAME.onnx, with NAME.json beside it)");
  if (!fs::is_regular_file(onnx_path)) bad(onnx_path, "no such file");
  spec_ = read_policy_spec(fs::path(onnx_path).replace_extension(".json").string());
  try {
    net_->net = cv::dnn::readNetFromONNX(onnx_path);
  } catch (const cv::Exception &e) {
    bad(onnx_path, std::string("OpenCV DNN cannot load it: ") + e.what());
  }
  if (net_->net.empty()) bad(onnx_path, "OpenCV DNN loaded an empty network");
  net_->net.setPreferableBackend(cv::dnn::DNN_BACKEND_OPENCV);
  net_->net.setPreferableTarget(cv::dnn::DNN_TARGET_CPU);
  std::vector<float> probe(static_cast<size_t>(spec_.obs_dim), 0.0f);
  std::vector<float> out;
  try {
    out = forward(probe);
  } catch (const cv::Exception &e) {
    bad(onnx_path, "does not run on an observation of obs_dim " + std::to_string(spec_.obs_dim) +
                       " (from its .json): " + e.what());
  }
  const size_t want = spec_.actions.empty() ? 1 : spec_.actions.size();
  if (out.size() != want)
    bad(onnx_path, "its output has " + std::to_string(out.size()) +
                       " values, its .json's actions " + "want " + std::to_string(want));
}

Policy::~Policy() = default;

std::vector<float> Policy::forward(const std::vector<float> &obs) {
  if (static_cast<int>(obs.size()) != spec_.obs_dim)
    throw std::invalid_argument("observation of " + std::to_string(obs.size()) +
                                " values, the policy wants " + std::to_string(spec_.obs_dim));
  cv::Mat in(1, spec_.obs_dim, CV_32F, const_cast<float *>(obs.data()));
  net_->net.setInput(in);
  cv::Mat out = net_->net.forward();
  out = out.reshape(1, 1);
  return std::vector<float>(out.begin<float>(), out.end<float>());
}

PolicyCommand Policy::act(const std::vector<float> &obs) {
  const std::vector<float> out = forward(obs);
  if (spec_.actions.empty())
    return {spec_.continuous_throttle, std::clamp(static_cast<double>(out[0]), -1.0, 1.0)};
  const auto best = std::max_element(out.begin(), out.end()) - out.begin();
  const auto &a = spec_.actions[static_cast<size_t>(best)];
  return {a.first, a.second};
}

}  // namespace autodrive::marl
