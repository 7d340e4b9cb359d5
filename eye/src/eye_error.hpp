// Eye errors: every failure the user can cause (bad file, bad frame, missing device) is an
// eye::Error whose message names the input and what is wrong. main() prints it and exits 1.
// It is the project's one bad-input type, so the shared YAML reader's errors are Eye errors too.
#pragma once
#include <autodrive/strict_yaml.hpp>

namespace eye {

using Error = autodrive::InputError;

}  // namespace eye
