/* The one angle wrap of the C code (simulator, MARL core, path tracking), the same as the C++
 * one (<autodrive/angles.hpp>): a heading wrapped to (-pi, pi] [rad], so that differences of
 * headings near +-pi are small. Header-only (target autodrive_angle_wrap). */
#ifndef AUTODRIVE_ANGLE_WRAP_H
#define AUTODRIVE_ANGLE_WRAP_H

#include <math.h>

/* a_rad wrapped to (-pi, pi] [rad]. */
static inline double autodrive_angle_wrap_rad(double a_rad) {
  const double pi = 3.14159265358979323846;
  a_rad = fmod(a_rad + pi, 2.0 * pi);
  if (a_rad <= 0.0) a_rad += 2.0 * pi;
  return a_rad - pi;
}

#endif
