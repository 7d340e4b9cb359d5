// The one strict YAML config reader of the runtime, the autonomy and the Eye. Every error
// names the file and the dotted key ("nigel_car.yaml: bridge.baud: missing key"), a key no
// reader asked for is refused as a typo (reject_unknown), and a value of the wrong kind is
// refused with its text, never read as a default. Every number has a range (in_range,
// positive(..., hi)): a value outside is refused naming the key and the bound.
#pragma once

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <initializer_list>
#include <memory>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

namespace autodrive {

// Bad input from a user: a config, a calibration, a map, a device. The message names the input
// and what is wrong; programs print it and exit non-zero. The runtime's autodrive::config::Error
// and the Eye's eye::Error are this type.
class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace autodrive

namespace autodrive::yaml {

using Error = autodrive::InputError;

// The file's top-level node; Error naming the file if it cannot be read or parsed.
inline YAML::Node load_file(const std::string &path) {
  try {
    return YAML::LoadFile(path);
  } catch (const YAML::BadFile &) {
    throw Error(path + ": cannot be opened");
  } catch (const YAML::Exception &e) {
    throw Error(path + ": is not valid YAML: " + e.what());
  }
}

inline YAML::Node load_string(const std::string &text, const std::string &name) {
  try {
    return YAML::Load(text);
  } catch (const YAML::Exception &e) {
    throw Error(name + ": is not valid YAML: " + e.what());
  }
}

// A mapping (or an absent one: every key then reads as missing) with its dotted path.
class Section {
 public:
  Section(const YAML::Node &node, std::string path, std::string file)
      : node_(node),
        path_(std::move(path)),
        file_(std::make_shared<const std::string>(std::move(file))),
        used_(std::make_shared<std::set<std::string>>()) {
    if (node_ && !node_.IsMap()) fail(path_.empty() ? "(top level)" : path_, "expected a mapping");
  }

  [[noreturn]] void fail(const std::string &dotted_key, const std::string &what) const {
    throw Error(*file_ + ": " + dotted_key + ": " + what);
  }
  // fail() for a key of this section.
  [[noreturn]] void fail_key(const std::string &k, const std::string &what) const {
    fail(key(k), what);
  }

  std::string key(const std::string &k) const { return path_.empty() ? k : path_ + "." + k; }
  const std::string &path() const { return path_; }
  const std::string &file() const { return *file_; }
  bool present() const { return static_cast<bool>(node_); }
  bool has(const std::string &k) const { return node_ && node_[k]; }

  template <typename T>
  T get(const std::string &k) const {
    used_->insert(k);
    if (!has(k)) fail_missing(k);
    return convert<T>(k);
  }
  // A required key is missing: a present key one or two letters off it (`devcie` for
  // `device`) is its typo, reported as the unknown key it is; else "missing key".
  [[noreturn]] void fail_missing(const std::string &k) const {
    if (node_)
      for (const auto &kv : node_) {
        const std::string other = kv.first.as<std::string>();
        if (!used_->count(other) && edit_distance(other, k) <= 2)
          fail_key(other, "unknown key (a typo of " + key(k) + "?)");
      }
    fail_key(k, "missing key");
  }
  template <typename T>
  T get(const std::string &k, T fallback) const {
    used_->insert(k);
    return has(k) ? convert<T>(k) : fallback;
  }
  // Reads k into out if present; out keeps its default otherwise.
  template <typename T>
  void read(const std::string &k, T &out) const {
    out = get<T>(k, out);
  }
  double positive(const std::string &k, double fallback, bool required = false) const {
    const double v = required ? get<double>(k) : get<double>(k, fallback);
    if (!(v > 0.0) || !std::isfinite(v)) fail_key(k, "must be a finite number > 0");
    return v;
  }
  // A finite number (yaml-cpp reads .inf and .nan as numbers).
  double number(const std::string &k) const { return finite(k, get<double>(k)); }
  double number(const std::string &k, double fallback) const {
    return finite(k, get<double>(k, fallback));
  }
  // A finite number > 0 and <= hi.
  double positive_up_to(const std::string &k, double hi, double fallback,
                        bool required = false) const {
    const double v = positive(k, fallback, required);
    if (v > hi) fail_key(k, out_of_range(v, "> 0 and <= " + text(hi)));
    return v;
  }
  // A number (int or double) in [lo, hi]; required, or the fallback when absent.
  template <typename T>
  T in_range(const std::string &k, T lo, T hi) const {
    return check_range(k, get<T>(k), lo, hi);
  }
  template <typename T>
  T in_range(const std::string &k, T lo, T hi, T fallback) const {
    return check_range(k, get<T>(k, fallback), lo, hi);
  }
  // Reads k into out if present (out keeps its default otherwise); refused outside [lo, hi].
  template <typename T>
  void read_in_range(const std::string &k, T &out, T lo, T hi) const {
    out = in_range<T>(k, lo, hi, out);
  }
  int positive_int(const std::string &k, int fallback, bool required = false) const {
    const int v = required ? get<int>(k) : get<int>(k, fallback);
    if (v <= 0) fail_key(k, "must be an integer > 0");
    return v;
  }
  // Exactly n finite numbers, e.g. a position [x, y, z]; n = 0: any number of them.
  std::vector<double> numbers(const std::string &k, size_t n) const {
    const std::string expected =
        n ? "expected a list of " + std::to_string(n) + " numbers" : "expected a list of numbers";
    used_->insert(k);
    if (!has(k)) fail_key(k, "missing key");
    if (!node_[k].IsSequence() || (n && node_[k].size() != n)) fail_key(k, expected);
    const auto v = convert<std::vector<double>>(k);
    for (const double x : v)
      if (!std::isfinite(x)) fail_key(k, "has a non-finite entry");
    return v;
  }
  // Keys a reader knows and does not need (e.g. notes a calibration file carries for people).
  void allow(std::initializer_list<const char *> keys) const {
    for (const char *k : keys) used_->insert(k);
  }
  Section child(const std::string &k) const {
    used_->insert(k);
    return Section(node_ ? node_[k] : YAML::Node(), key(k), *file_);
  }
  // The list under k (marked as read; each entry is then read as its own Section); fails with
  // `expected` unless it is a sequence.
  YAML::Node list(const std::string &k, const std::string &expected) const {
    used_->insert(k);
    if (!has(k)) fail_key(k, "missing key");
    const YAML::Node n = node_[k];
    if (!n.IsSequence()) fail_key(k, expected);
    return n;
  }
  // Keys that must not be here, each with the reason (e.g. a figure of the car).
  void reject_keys(std::initializer_list<const char *> keys, const std::string &why) const {
    for (const char *k : keys)
      if (has(k)) fail_key(k, why);
  }
  // Any key not read is a typo or an unsupported option: refuse it rather than ignore it.
  void reject_unknown() const {
    if (!node_) return;
    for (const auto &kv : node_) {
      const std::string k = kv.first.as<std::string>();
      if (!used_->count(k)) fail_key(k, "unknown key");
    }
  }
  const YAML::Node &node() const { return node_; }

 private:
  // Levenshtein distance of two short keys [edits].
  static size_t edit_distance(const std::string &a, const std::string &b) {
    std::vector<size_t> row(b.size() + 1);
    for (size_t j = 0; j <= b.size(); ++j) row[j] = j;
    for (size_t i = 1; i <= a.size(); ++i) {
      size_t diagonal = row[0];
      row[0] = i;
      for (size_t j = 1; j <= b.size(); ++j) {
        const size_t above = row[j];
        row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] != b[j - 1])});
        diagonal = above;
      }
    }
    return row[b.size()];
  }

  template <typename T>
  static std::string text(T v) {
    std::ostringstream s;
    s << v;
    return s.str();
  }
  template <typename T>
  static std::string out_of_range(T v, const std::string &bound) {
    return text(v) + " is out of range: must be " + bound;
  }
  template <typename T>
  T check_range(const std::string &k, T v, T lo, T hi) const {
    if constexpr (std::is_floating_point_v<T>) v = finite(k, v);
    if (!(v >= lo && v <= hi)) fail_key(k, out_of_range(v, text(lo) + ".." + text(hi)));
    return v;
  }
  double finite(const std::string &k, double v) const {
    if (!std::isfinite(v)) fail_key(k, "must be a finite number");
    return v;
  }
  template <typename T>
  T convert(const std::string &k) const {
    try {
      return node_[k].template as<T>();
    } catch (const YAML::Exception &) {
      std::ostringstream s;
      s << "bad value";
      if (node_[k].IsScalar()) s << " '" << node_[k].Scalar() << "'";
      fail_key(k, s.str());
    }
  }
  YAML::Node node_;
  std::string path_;
  std::shared_ptr<const std::string> file_;
  std::shared_ptr<std::set<std::string>> used_;
};

}  // namespace autodrive::yaml
