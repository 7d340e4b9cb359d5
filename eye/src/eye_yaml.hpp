// Small yaml-cpp helpers that turn a missing or malformed field into an eye::Error naming the
// file and the field ("camera.yaml: field 'k' must be a list of 9 numbers").
#pragma once
#include <yaml-cpp/yaml.h>

#include <string>
#include <vector>

namespace eye {

// Loads a YAML file; throws if it is missing or not valid YAML.
YAML::Node yaml_load_file(const std::string &path);
// The child `field` of `node`, which must exist.
YAML::Node yaml_need(const YAML::Node &node, const std::string &field, const std::string &path);
double yaml_double(const YAML::Node &node, const std::string &field, const std::string &path);
int yaml_int(const YAML::Node &node, const std::string &field, const std::string &path);
std::string yaml_string(const YAML::Node &node, const std::string &field, const std::string &path);
// A list of exactly `n` numbers (n < 0: any length).
std::vector<double> yaml_doubles(const YAML::Node &node, const std::string &field,
                                 const std::string &path, int n);

}  // namespace eye
