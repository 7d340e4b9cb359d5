#include "eye_yaml.hpp"

#include <cmath>

#include "eye_error.hpp"

namespace eye {

YAML::Node yaml_load_file(const std::string &path) {
  try {
    YAML::Node n = YAML::LoadFile(path);
    if (!n.IsMap()) throw Error(path + ": expected a YAML mapping at the top level");
    return n;
  } catch (const YAML::BadFile &) {
    throw Error(path + ": cannot open file");
  } catch (const YAML::Exception &e) {
    throw Error(path + ": not valid YAML: " + e.what());
  }
}

YAML::Node yaml_need(const YAML::Node &node, const std::string &field, const std::string &path) {
  YAML::Node c = node[field];
  if (!c) throw Error(path + ": missing field '" + field + "'");
  return c;
}

double yaml_double(const YAML::Node &node, const std::string &field, const std::string &path) {
  YAML::Node c = yaml_need(node, field, path);
  try {
    double v = c.as<double>();
    if (!std::isfinite(v)) throw Error(path + ": field '" + field + "' is not finite");
    return v;
  } catch (const YAML::Exception &) {
    throw Error(path + ": field '" + field + "' must be a number");
  }
}

int yaml_int(const YAML::Node &node, const std::string &field, const std::string &path) {
  YAML::Node c = yaml_need(node, field, path);
  try {
    return c.as<int>();
  } catch (const YAML::Exception &) {
    throw Error(path + ": field '" + field + "' must be an integer");
  }
}

std::string yaml_string(const YAML::Node &node, const std::string &field, const std::string &path) {
  YAML::Node c = yaml_need(node, field, path);
  if (!c.IsScalar()) throw Error(path + ": field '" + field + "' must be a string");
  return c.as<std::string>();
}

std::vector<double> yaml_doubles(const YAML::Node &node, const std::string &field,
                                 const std::string &path, int n) {
  YAML::Node c = yaml_need(node, field, path);
  const std::string what =
      n < 0 ? std::string("a list of numbers") : "a list of " + std::to_string(n) + " numbers";
  if (!c.IsSequence() || (n >= 0 && static_cast<int>(c.size()) != n))
    throw Error(path + ": field '" + field + "' must be " + what);
  std::vector<double> v;
  try {
    for (const auto &e : c) v.push_back(e.as<double>());
  } catch (const YAML::Exception &) {
    throw Error(path + ": field '" + field + "' must be " + what);
  }
  for (double x : v)
    if (!std::isfinite(x)) throw Error(path + ": field '" + field + "' has a non-finite entry");
  return v;
}

}  // namespace eye
