// rs_: Reeds-Shepp curves (Reeds & Shepp 1990): shortest paths of a car that can reverse,
// made of arcs at the minimum turning radius (L, R) and straights (S). Implemented word
// families: CSC, CCC, CCCC, CCSC, CCSCC with their time-flip / reflection / backwards
// variants. Every candidate is checked by integrating it and comparing its end with the goal,
// so a wrong candidate can never be returned.
#pragma once
#include <vector>

#include <autodrive/autonomy/path.hpp>

namespace autodrive::autonomy {

struct RsSegment {
  char type = 'S';        // 'L', 'S' or 'R'
  double length_m = 0.0;  // signed: negative = reversing [m]
};

struct RsPath {
  std::vector<RsSegment> segments;
  double length_m() const;
};

// Every valid candidate from start to goal, shortest first.
std::vector<RsPath> rs_paths(const Pose2 &start, const Pose2 &goal, double turn_radius_m);

// Length of the shortest candidate [m], -1 when none (no heap use: for heuristics).
double rs_shortest_length_m(const Pose2 &start, const Pose2 &goal, double turn_radius_m);

// Samples a path every step_m (and at every segment boundary). Curvatures are +-1/R or 0.
Path rs_sample(const Pose2 &start, const RsPath &path, double turn_radius_m, double step_m);

}  // namespace autodrive::autonomy
