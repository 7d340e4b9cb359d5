// A named route and the intersection's conflict zone, read from a map's JSON sidecar
// (maps/<map>.json, written by tools/gen-maps: the one source of routes).
#pragma once

#include <autodrive/autonomy/path.hpp>

#include <string>
#include <vector>

namespace autodrive::marl {

struct Route {
  std::string name;
  std::vector<autodrive::autonomy::Pose2>
      points;                              // along the lane centre, yaw = direction of travel
  std::vector<double> s_m;                 // arc length at each point [m]
  double half_width_m = 0;                 // the lane's half width [m] (the shield's lane term)
  autodrive::autonomy::Path path() const;  // for the pure-pursuit tracker, forward only
  // Index of the point nearest to (x, y) [m].
  size_t nearest(double x_m, double y_m) const;
};

struct ConflictZone {
  double cx_m = 0, cy_m = 0;  // centre [m]
  double half_m = 0;          // half side of the square [m]
  bool contains(double x_m, double y_m) const;
};

// Throws std::runtime_error naming the file and what is wrong (no such route: lists them).
Route read_route(const std::string &map_json, const std::string &name);
// The square over the map's 4-way ("cross") tile's roads, grown by margin_m [m] on each side.
ConflictZone read_conflict_zone(const std::string &map_json, double margin_m);

}  // namespace autodrive::marl
