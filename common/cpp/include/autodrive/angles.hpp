// The one angle helper of the C++ code (runtime, estimator, autonomy, Eye, benches): wrapping a
// heading to (-pi, pi] [rad], so that differences of headings near +-pi are small.
#pragma once

#include <cmath>

namespace autodrive {

constexpr double kPi = 3.14159265358979323846;

// a_rad wrapped to (-pi, pi] [rad].
inline double angle_wrap_rad(double a_rad) {
  a_rad = std::fmod(a_rad + kPi, 2.0 * kPi);
  if (a_rad <= 0.0) a_rad += 2.0 * kPi;
  return a_rad - kPi;
}

// The signed smallest rotation from from_rad to to_rad, in (-pi, pi] [rad].
inline double angle_diff_rad(double to_rad, double from_rad) {
  return angle_wrap_rad(to_rad - from_rad);
}

}  // namespace autodrive
