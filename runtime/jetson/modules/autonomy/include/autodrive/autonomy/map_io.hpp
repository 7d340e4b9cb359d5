// map_io_: save and load a GridMap as ROS map_server does (PGM image + YAML description),
// so the usual ROS tools open our maps. Trinary: free 254, occupied 0, unknown 205.
#pragma once
#include <string>

#include <autodrive/autonomy/grid_map.hpp>

namespace autodrive::autonomy {

// Writes <yaml_path> and the PGM next to it (same stem, ".pgm"). Throws std::runtime_error
// naming the file on I/O failure.
void map_save(const GridMap &map, const std::string &yaml_path);

// Reads a map_server YAML (image, resolution, origin, negate, occupied_thresh, free_thresh;
// mode trinary/scale) and its PGM (P5 binary or P2 ASCII, maxval <= 255). Throws
// std::runtime_error naming the file and what is wrong. The origin yaw must be 0.
GridMap map_load(const std::string &yaml_path);

}  // namespace autodrive::autonomy
