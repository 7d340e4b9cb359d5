// A standard synthetic overhead scene for tests and the benchmark: a 3.0 x 2.0 m map seen by
// a slightly tilted pinhole camera 2.5 m up, cars drawn as a body, a white roof and a roof tag
// at the real height (tag_offset_m above base_link), optional blur and sensor noise.
#pragma once
#include <opencv2/core.hpp>

#include <cstdint>
#include <vector>

#include "eye_camera.hpp"
#include "eye_locate.hpp"
#include "eye_mapcal.hpp"

namespace eye {

struct SynthScene {
  Intrinsics in;  // distortion-free
  CameraPose pose;
  LocateParams car;                     // tag size, tag offset, base_link height
  double map_x_m = 3.0, map_y_m = 2.0;  // map extent from the origin [m]
  int ss = 4;                           // samples per pixel side
  double blur_sigma_px = 0.0;
  double noise_sigma = 0.0;  // grey levels
  cv::Mat floor;             // pre-rendered background
};

struct SynthCar {
  int tag_id = 0;
  double x_m = 0, y_m = 0, yaw_rad = 0;  // base_link on the map
};

// width_px x height_px camera over the map; tag_size_m: black border of the roof tags.
SynthScene synth_scene(int width_px, int height_px, double tag_size_m = 0.10);
// Renders a frame; floor_tags are drawn on their own plane (z_m). seed: noise.
cv::Mat synth_frame(const SynthScene &s, const std::vector<SynthCar> &cars,
                    const std::vector<RefTag> &floor_tags, uint64_t seed);
// Reference tags near the corners and edges of the map (ids 100..), for calibrate-map.
std::vector<RefTag> synth_reference_tags(const SynthScene &s);

}  // namespace eye
