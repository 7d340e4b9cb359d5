#include <autodrive/autonomy/grid_map.hpp>

#include <algorithm>
#include <cmath>

#include <opencv2/imgproc.hpp>

namespace autodrive::autonomy {

GridMap::GridMap(int width, int height, double resolution, double origin_x, double origin_y)
    : width_cells(width),
      height_cells(height),
      resolution_m(resolution),
      origin_x_m(origin_x),
      origin_y_m(origin_y),
      log_odds(static_cast<size_t>(width) * height, 0.0f) {}

bool GridMap::world_to_cell(double x_m, double y_m, int &cx, int &cy) const {
  cx = static_cast<int>(std::floor((x_m - origin_x_m) / resolution_m));
  cy = static_cast<int>(std::floor((y_m - origin_y_m) / resolution_m));
  return in_bounds(cx, cy);
}

double GridMap::probability(int cx, int cy) const {
  if (!in_bounds(cx, cy)) return 0.5;
  return 1.0 - 1.0 / (1.0 + std::exp(static_cast<double>(log_odds[index(cx, cy)])));
}

CellState GridMap::state(int cx, int cy) const {
  if (!in_bounds(cx, cy)) return CellState::kUnknown;
  const double p = probability(cx, cy);
  if (p > occupied_thresh) return CellState::kOccupied;
  if (p < free_thresh) return CellState::kFree;
  return CellState::kUnknown;
}

void GridMap::update_ray(double sx_m, double sy_m, double ex_m, double ey_m, bool hit, float l_free,
                         float l_occ, float l_min, float l_max) {
  int x0, y0, x1, y1;
  world_to_cell(sx_m, sy_m, x0, y0);
  world_to_cell(ex_m, ey_m, x1, y1);
  // Bresenham from sensor cell to end cell (end cell excluded from the free update).
  const int dx = std::abs(x1 - x0), dy = -std::abs(y1 - y0);
  const int stepx = x0 < x1 ? 1 : -1, stepy = y0 < y1 ? 1 : -1;
  int err = dx + dy, x = x0, y = y0;
  while (!(x == x1 && y == y1)) {
    if (in_bounds(x, y)) {
      float &l = log_odds[index(x, y)];
      l = std::clamp(l + l_free, l_min, l_max);
    }
    const int e2 = 2 * err;
    if (e2 >= dy) {
      err += dy;
      x += stepx;
    }
    if (e2 <= dx) {
      err += dx;
      y += stepy;
    }
  }
  if (hit && in_bounds(x1, y1)) {
    float &l = log_odds[index(x1, y1)];
    l = std::clamp(l + l_occ, l_min, l_max);
  }
}

std::vector<float> grid_distance_field_m(const GridMap &g, bool unknown_is_obstacle) {
  // A one-cell obstacle border stands for "outside the map"; distanceTransform measures the
  // distance to the nearest zero pixel.
  cv::Mat free_mask(g.height_cells + 2, g.width_cells + 2, CV_8UC1, cv::Scalar(0));
  for (int cy = 0; cy < g.height_cells; ++cy) {
    for (int cx = 0; cx < g.width_cells; ++cx) {
      const CellState s = g.state(cx, cy);
      const bool obstacle =
          s == CellState::kOccupied || (unknown_is_obstacle && s == CellState::kUnknown);
      free_mask.at<uint8_t>(cy + 1, cx + 1) = obstacle ? 0 : 255;
    }
  }
  cv::Mat dist_cells;
  cv::distanceTransform(free_mask, dist_cells, cv::DIST_L2, cv::DIST_MASK_PRECISE, CV_32F);
  std::vector<float> out(static_cast<size_t>(g.width_cells) * g.height_cells);
  for (int cy = 0; cy < g.height_cells; ++cy)
    for (int cx = 0; cx < g.width_cells; ++cx)
      out[g.index(cx, cy)] =
          dist_cells.at<float>(cy + 1, cx + 1) * static_cast<float>(g.resolution_m);
  return out;
}

void grid_mark_occupied(GridMap &g, const std::vector<Eigen::Vector2d> &points_m, double radius_m) {
  const int rc = static_cast<int>(std::ceil(radius_m / g.resolution_m));
  for (const auto &p : points_m) {
    int cx, cy;
    g.world_to_cell(p.x(), p.y(), cx, cy);
    for (int dy = -rc; dy <= rc; ++dy) {
      for (int dx = -rc; dx <= rc; ++dx) {
        if (!g.in_bounds(cx + dx, cy + dy)) continue;
        if ((g.cell_center_m(cx + dx, cy + dy) - p).norm() > radius_m + 0.5 * g.resolution_m)
          continue;
        g.log_odds[g.index(cx + dx, cy + dy)] = 10.0f;
      }
    }
  }
}

}  // namespace autodrive::autonomy
