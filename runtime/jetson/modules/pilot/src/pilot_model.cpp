#include <autodrive/pilot/pilot_model.hpp>

#include <autodrive/strict_yaml.hpp>  // autodrive::InputError
#include <nlohmann/json.hpp>
#include <openssl/evp.h>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <fstream>
#include <sstream>

namespace autodrive::pilot {
namespace {

using autodrive::InputError;

std::string read_bytes(const std::string &path, const char *what) {
  std::ifstream f(path, std::ios::binary);
  if (!f) throw InputError(path + ": cannot be opened (" + what + " missing?)");
  std::ostringstream s;
  s << f.rdbuf();
  return s.str();
}

std::string sha256_hex(const std::string &bytes) {
  unsigned char md[EVP_MAX_MD_SIZE];
  unsigned int n = 0;
  EVP_Digest(bytes.data(), bytes.size(), md, &n, EVP_sha256(), nullptr);
  static const char *hex = "0123456789abcdef";
  std::string out;
  for (unsigned int i = 0; i < n; ++i) {
    out += hex[md[i] >> 4];
    out += hex[md[i] & 15];
  }
  return out;
}

// Protobuf wire format, just enough to walk a message's top-level fields.
struct Wire {
  const std::string &b;
  size_t pos = 0;
  bool varint(uint64_t &v) {
    v = 0;
    for (int shift = 0; shift < 64; shift += 7) {
      if (pos >= b.size()) return false;
      const auto c = static_cast<uint8_t>(b[pos++]);
      v |= static_cast<uint64_t>(c & 0x7f) << shift;
      if (!(c & 0x80)) return true;
    }
    return false;
  }
  // Skips or returns (LEN) the field's payload; false when it runs past the end.
  bool field(uint64_t key, std::string *payload) {
    uint64_t n = 0;
    switch (key & 7) {
      case 0: return varint(n);
      case 1: n = 8; break;
      case 5: n = 4; break;
      case 2:
        if (!varint(n)) return false;
        break;
      default: return false;
    }
    if (n > b.size() - pos) return false;
    if (payload) *payload = b.substr(pos, n);
    pos += n;
    return true;
  }
};

Colour colour_of(const std::string &path, const std::string &name) {
  if (name == "yuv") return Colour::yuv;
  if (name == "bgr") return Colour::bgr;
  if (name == "rgb") return Colour::rgb;
  throw InputError(path + ": input.colour: '" + name + "' is not yuv, bgr or rgb");
}

}  // namespace

std::string sidecar_path(const std::string &onnx_path) {
  const auto dot = onnx_path.rfind(".onnx");
  return (dot == std::string::npos ? onnx_path : onnx_path.substr(0, dot)) + ".json";
}

InputSpec read_sidecar(const std::string &json_path, int &opset, std::string &onnx_sha256) {
  const std::string text = read_bytes(json_path, "the model's sidecar");
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(text);
  } catch (const nlohmann::json::exception &e) {
    throw InputError(json_path + ": is not valid JSON: " + e.what());
  }
  auto need = [&](const nlohmann::json &o, const char *key, const std::string &dotted) {
    if (!o.is_object() || !o.contains(key))
      throw InputError(json_path + ": " + dotted + ": missing key");
    return o.at(key);
  };
  auto integer = [&](const nlohmann::json &o, const char *key, int lo, int hi) {
    const std::string dotted = std::string("input.") + key;
    const auto v = need(o, key, dotted);
    if (!v.is_number_integer() || v.get<int64_t>() < lo || v.get<int64_t>() > hi)
      throw InputError(json_path + ": " + dotted + ": " + v.dump() + " is not an integer in [" +
                       std::to_string(lo) + ", " + std::to_string(hi) + "]");
    return v.get<int>();
  };
  auto number = [&](const nlohmann::json &v, const std::string &dotted) {
    if (!v.is_number() || !std::isfinite(v.get<double>()))
      throw InputError(json_path + ": " + dotted + ": " + v.dump() + " is not a finite number");
    return v.get<double>();
  };
  const auto in = need(j, "input", "input");
  InputSpec s;
  s.source_width_px = integer(in, "source_width", 1, 8192);
  s.source_height_px = integer(in, "source_height", 1, 8192);
  s.crop_top_px = integer(in, "crop_top_px", 0, s.source_height_px - 1);
  s.crop_bottom_px = integer(in, "crop_bottom_px", 0, s.source_height_px - 1 - s.crop_top_px);
  s.width_px = integer(in, "width", 1, 4096);
  s.height_px = integer(in, "height", 1, 4096);
  const auto colour = need(in, "colour", "input.colour");
  s.colour = colour_of(json_path, colour.is_string() ? colour.get<std::string>() : colour.dump());
  s.scale = number(need(in, "scale", "input.scale"), "input.scale");
  for (const char *key : {"mean", "std"}) {
    const auto v = need(in, key, std::string("input.") + key);
    if (!v.is_array() || v.size() != 3)
      throw InputError(json_path + ": input." + key + ": expected a list of 3 numbers");
    auto &out = std::string(key) == "mean" ? s.mean : s.std;
    for (size_t k = 0; k < 3; ++k) out[k] = number(v[k], std::string("input.") + key);
  }
  for (double sd : s.std)
    if (!(sd > 0)) throw InputError(json_path + ": input.std: every entry must be > 0");
  const auto op = need(j, "opset", "opset");
  if (!op.is_number_integer()) throw InputError(json_path + ": opset: not an integer");
  opset = op.get<int>();
  const auto sha = need(j, "onnx_sha256", "onnx_sha256");
  if (!sha.is_string() || sha.get<std::string>().size() != 64)
    throw InputError(json_path + ": onnx_sha256: expected 64 hex digits");
  onnx_sha256 = sha.get<std::string>();
  return s;
}

int onnx_opset(const std::string &onnx_path, const std::string &bytes) {
  Wire w{bytes};
  int opset = -1;
  while (w.pos < bytes.size()) {
    uint64_t key = 0;
    std::string payload;
    if (!w.varint(key) || !w.field(key, (key >> 3) == 8 ? &payload : nullptr))
      throw InputError(onnx_path + ": truncated or not an ONNX model (a field at byte " +
                       std::to_string(w.pos) + " of " + std::to_string(bytes.size()) +
                       " runs past the end)");
    if ((key >> 3) != 8 || (key & 7) != 2) continue;
    Wire o{payload};  // OperatorSetIdProto: domain = 1 (string), version = 2 (int64)
    std::string domain;
    int64_t version = -1;
    while (o.pos < payload.size()) {
      uint64_t k = 0, v = 0;
      if (!o.varint(k)) break;
      if ((k >> 3) == 2 && (k & 7) == 0 && o.varint(v)) {
        version = static_cast<int64_t>(v);
      } else if (!o.field(k, (k >> 3) == 1 ? &domain : nullptr)) {
        break;
      }
    }
    if ((domain.empty() || domain == "ai.onnx") && version >= 0) opset = static_cast<int>(version);
  }
  if (opset < 0) throw InputError(onnx_path + ": holds no opset of the default ONNX domain");
  return opset;
}

cv::Mat preprocess(const cv::Mat &bgr, const InputSpec &s) {
  if (bgr.cols != s.source_width_px || bgr.rows != s.source_height_px || bgr.channels() != 3)
    throw InputError("frame " + std::to_string(bgr.cols) + "x" + std::to_string(bgr.rows) + "x" +
                     std::to_string(bgr.channels()) + " is not the model's " +
                     std::to_string(s.source_width_px) + "x" + std::to_string(s.source_height_px) +
                     "x3");
  const cv::Mat rows = bgr.rowRange(s.crop_top_px, bgr.rows - s.crop_bottom_px);
  cv::Mat small, coloured, f;
  cv::resize(rows, small, cv::Size(s.width_px, s.height_px), 0, 0, cv::INTER_AREA);
  if (s.colour == Colour::yuv)
    cv::cvtColor(small, coloured, cv::COLOR_BGR2YUV);
  else if (s.colour == Colour::rgb)
    cv::cvtColor(small, coloured, cv::COLOR_BGR2RGB);
  else
    coloured = small;
  coloured.convertTo(f, CV_32F, s.scale);
  cv::subtract(f, cv::Scalar(s.mean[0], s.mean[1], s.mean[2]), f);
  cv::divide(f, cv::Scalar(s.std[0], s.std[1], s.std[2]), f);
  return cv::dnn::blobFromImage(f);  // HWC -> NCHW [1,3,H,W], no scaling, no swap
}

PilotModel::PilotModel(const std::string &onnx_path) : path_(onnx_path) {
  const std::string bytes = read_bytes(onnx_path, "the model");
  std::string sha;
  int sidecar_opset = 0;
  spec_ = read_sidecar(sidecar_path(onnx_path), sidecar_opset, sha);
  if (sha256_hex(bytes) != sha)
    throw InputError(onnx_path +
                     ": its SHA-256 is not the sidecar's onnx_sha256 (a truncated or "
                     "replaced file; " +
                     std::to_string(bytes.size()) + " bytes)");
  opset_ = onnx_opset(onnx_path, bytes);
  if (opset_ != sidecar_opset)
    throw InputError(onnx_path + ": opset " + std::to_string(opset_) + " but its sidecar says " +
                     std::to_string(sidecar_opset));
  if (opset_ < kMinOpset || opset_ > kMaxOpset)
    throw InputError(onnx_path + ": opset " + std::to_string(opset_) + " cannot be run here (" +
                     std::to_string(kMinOpset) + ".." + std::to_string(kMaxOpset) + ")");
  try {
    net_ = cv::dnn::readNetFromONNX(bytes.data(), bytes.size());
    net_.setPreferableBackend(cv::dnn::DNN_BACKEND_OPENCV);
    net_.setPreferableTarget(cv::dnn::DNN_TARGET_CPU);
  } catch (const cv::Exception &e) {
    throw InputError(onnx_path + ": OpenCV's DNN module cannot load it: " + e.what());
  }
  const int shape[] = {1, 3, spec_.height_px, spec_.width_px};
  try {
    (void)raw(cv::Mat(4, shape, CV_32F, cv::Scalar(0)));
  } catch (const cv::Exception &e) {
    throw InputError(onnx_path + ": cannot run the sidecar's input shape [1,3," +
                     std::to_string(spec_.height_px) + "," + std::to_string(spec_.width_px) +
                     "]: " + e.what());
  }
}

float PilotModel::raw(const cv::Mat &blob) {
  net_.setInput(blob, "frames");
  const cv::Mat out = net_.forward();
  if (out.total() != 1)
    throw InputError(path_ + ": output has " + std::to_string(out.total()) +
                     " values per frame, expected 1 (steering [N,1])");
  const float s = out.ptr<float>()[0];
  if (!std::isfinite(s)) throw InputError(path_ + ": the network's steering is not finite");
  return s;
}

}  // namespace autodrive::pilot
