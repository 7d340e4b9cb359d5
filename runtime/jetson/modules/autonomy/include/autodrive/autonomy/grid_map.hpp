// Occupancy grid in log-odds (grid_), the map every autonomy module shares.
// Cell (0,0) is the lower-left cell; its lower-left corner sits at (origin_x_m, origin_y_m).
// Row index grows with +y, column index with +x (the PGM writer flips rows, as map_server).
#pragma once
#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include <autodrive/autonomy/geometry.hpp>

namespace autodrive::autonomy {

enum class CellState : int8_t { kUnknown = -1, kFree = 0, kOccupied = 100 };

struct GridMap {
  int width_cells = 0;
  int height_cells = 0;
  double resolution_m = 0.02;  // cell side [m]
  double origin_x_m = 0.0;     // lower-left corner of cell (0,0) [m]
  double origin_y_m = 0.0;
  std::vector<float> log_odds;  // row-major, 0 = unknown (p = 0.5)

  // Thresholds on p(occupied) used when classifying, as map_server's defaults.
  double occupied_thresh = 0.65;
  double free_thresh = 0.196;

  GridMap() = default;
  GridMap(int width, int height, double resolution, double origin_x, double origin_y);

  bool in_bounds(int cx, int cy) const {
    return cx >= 0 && cy >= 0 && cx < width_cells && cy < height_cells;
  }
  int index(int cx, int cy) const { return cy * width_cells + cx; }
  // Continuous cell coordinates of a world point (cell centres at .5).
  Eigen::Vector2d world_to_cellf(double x_m, double y_m) const {
    return {(x_m - origin_x_m) / resolution_m, (y_m - origin_y_m) / resolution_m};
  }
  bool world_to_cell(double x_m, double y_m, int &cx, int &cy) const;
  Eigen::Vector2d cell_center_m(int cx, int cy) const {
    return {origin_x_m + (cx + 0.5) * resolution_m, origin_y_m + (cy + 0.5) * resolution_m};
  }
  double probability(int cx, int cy) const;  // p(occupied) in [0, 1]
  CellState state(int cx, int cy) const;     // out of bounds -> unknown

  // Ray update from a sensor at (sx, sy) to a hit at (ex, ey) [m]: cells on the ray become
  // freer, the end cell more occupied (when hit is true; false = max-range ray, no end cell).
  void update_ray(double sx_m, double sy_m, double ex_m, double ey_m, bool hit, float l_free,
                  float l_occ, float l_min, float l_max);
};

// grid_ helpers.
// Distance from each cell centre to the nearest occupied (or unknown when unknown_is_obstacle)
// cell [m], row-major like the grid. Cells outside the map count as obstacles.
std::vector<float> grid_distance_field_m(const GridMap &g, bool unknown_is_obstacle);

// Marks discs of radius_m around points [m] as occupied (saturated log odds), e.g. obstacles
// seen live by the LIDAR (the radius covers the faces of a box not seen yet).
void grid_mark_occupied(GridMap &g, const std::vector<Eigen::Vector2d> &points_m, double radius_m);

}  // namespace autodrive::autonomy
