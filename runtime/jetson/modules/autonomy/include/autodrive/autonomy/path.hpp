// A drivable path for a car-like vehicle: poses of the rear-axle centre (the base frame)
// sampled along the path, each with the driving direction and curvature used to reach the
// next sample.
#pragma once
#include <vector>

#include <autodrive/autonomy/geometry.hpp>

namespace autodrive::autonomy {

struct PathPoint {
  Pose2 pose;
  int direction = 1;           // +1 forward, -1 reverse
  double curvature_1pm = 0.0;  // signed, + = turning left (tan(steer)/wheelbase) [1/m]
};
using Path = std::vector<PathPoint>;

// Length of a path along its samples [m].
double path_length_m(const Path &path);
// Number of direction changes (cusps).
int path_cusps(const Path &path);

// Moves a pose along an arc of signed length ds [m] (negative = reversing) at curvature k [1/m].
Pose2 arc_step(const Pose2 &p, double ds_m, double curvature_1pm);

}  // namespace autodrive::autonomy
