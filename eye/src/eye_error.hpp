// Eye errors: every failure the user can cause (bad file, bad frame, missing device) is an
// eye::Error whose message names the input and what is wrong. main() prints it and exits 1.
#pragma once
#include <stdexcept>
#include <string>

namespace eye {

struct Error : std::runtime_error {
  using std::runtime_error::runtime_error;
};

}  // namespace eye
