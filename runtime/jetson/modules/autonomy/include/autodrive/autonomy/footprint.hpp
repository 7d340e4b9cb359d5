// fp_: collision checking of the car's rectangular footprint on an inflated grid. The
// rectangle is covered by a row of discs; a pose is free when every disc centre lies on a
// cell at least (disc radius + margin) from the nearest obstacle (unknown counts as obstacle),
// i.e. on a grid inflated by that amount.
#pragma once

#include <autodrive_vehicle.h>
#include <vector>

#include <autodrive/autonomy/grid_map.hpp>
#include <autodrive/autonomy/path.hpp>

namespace autodrive::autonomy {

struct Footprint {
  // Nigel's envelope, derived from vehicle/nigel.params (chassis box and wheels): the car's,
  // not a setting.
  double length_m = AUTODRIVE_VEHICLE_ENVELOPE_LENGTH_M;              // bumper to bumper
  double width_m = AUTODRIVE_VEHICLE_ENVELOPE_WIDTH_M;                // tyre to tyre
  double center_ahead_m = AUTODRIVE_VEHICLE_ENVELOPE_CENTER_AHEAD_M;  // ahead of the rear axle
  double margin_m = 0.015;  // extra clearance kept from obstacles [m]
  int discs = 6;            // 4 cm apart along the length: each disc a little wider than the car
};

class CollisionChecker {
 public:
  CollisionChecker(const GridMap &map, const Footprint &fp, bool unknown_is_obstacle = true);
  // Smallest (distance to obstacle - disc radius) over the discs [m]; < margin = collision.
  double clearance_m(const Pose2 &base) const;
  bool pose_free(const Pose2 &base) const { return clearance_m(base) >= fp_.margin_m; }
  bool path_free(const Path &path) const;
  double disc_radius_m() const { return disc_radius_m_; }
  const GridMap &map() const { return map_; }
  const std::vector<float> &field_m() const { return field_m_; }
  const Footprint &footprint() const { return fp_; }

 private:
  const GridMap &map_;
  Footprint fp_;
  double disc_radius_m_;
  std::vector<double> disc_offsets_m_;
  std::vector<float> field_m_;
};

}  // namespace autodrive::autonomy
