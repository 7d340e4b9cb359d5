// A standard synthetic overhead scene for tests and the benchmark: a 3.0 x 2.0 m map seen by
// a slightly tilted pinhole camera 2.5 m up, cars drawn as a body, a white roof and a roof tag
// at the real height (tag_offset_m above base_link), optional blur and sensor noise; and a
// wide-angle variant (barrel lens k1 -0.30 k2 0.10, dim light, vignetting, noise sigma 6).
#pragma once
#include <opencv2/core.hpp>

#include <cstdint>
#include <vector>

#include "eye_camera.hpp"
#include "eye_locate.hpp"
#include "eye_mapcal.hpp"

namespace eye {

struct SynthScene {
  Intrinsics in;  // its distortion is rendered
  CameraPose pose;
  LocateParams car;                     // tag size, tag offset, base_link height
  double map_x_m = 3.0, map_y_m = 2.0;  // map extent from the origin [m]
  int ss = 4;                           // samples per pixel side
  double blur_sigma_px = 0.0;
  double noise_sigma = 0.0;  // grey levels
  cv::Mat floor;             // pre-rendered background
  cv::Mat shading;           // CV_32F light per pixel (dim light x vignetting); empty: 1
};

struct SynthCar {
  int tag_id = 0;
  double x_m = 0, y_m = 0, yaw_rad = 0;  // base_link on the map
};

// width_px x height_px camera over the map; tag_size_m: black border of the roof tags.
SynthScene synth_scene(int width_px, int height_px, double tag_size_m = 0.10);
// The wide-angle scene: a w x h camera with a barrel lens (k1 -0.30, k2 0.10, f = 0.44 w) tilted
// 15 deg, 1.12 m above the roofs (at 1280 px wide; lower for smaller images, so tags keep
// their pixel size) over a map sized to what it sees; light at 55 %, vignetting
// (45 % darker in the image corners), blur 0.8 px, noise sigma 6 grey levels; Nigel's 0.08 m
// roof tags appear ~20-40 px a side. The map extent covers the whole image.
SynthScene synth_scene_wide(int width_px, int height_px);
// Sets light: gain (1 = full light) times a radial falloff reaching 1 - vignetting in the
// image corners.
void synth_set_light(SynthScene &s, double gain, double vignetting);
// The map point (x, y) on the plane z_m seen at (distorted) pixel px.
cv::Vec2d synth_pixel_to_plane(const SynthScene &s, const cv::Point2d &px, double z_m);
// The roof tag's smallest side [px] of a car at this pose (after the lens).
double synth_tag_side_px(const SynthScene &s, const SynthCar &car);

// Renders a frame; floor_tags are drawn on their own plane (z_m). seed: noise.
cv::Mat synth_frame(const SynthScene &s, const std::vector<SynthCar> &cars,
                    const std::vector<RefTag> &floor_tags, uint64_t seed);
// Reference tags where the camera sees them: a 3 x 3 grid of image points (14/50/86 % of the
// width, 16/50/84 % of the height) without the centre, 0.10 m, on the floor, ids 100..
std::vector<RefTag> synth_reference_tags_in_view(const SynthScene &s);
// 10 cars (tag ids 1..10) on two loops drawn in the image: an outer one hugging the image
// border (edges and corners: tag centres 32 px in, so
// the black border of a 40 px tag stays in the image) and an inner one, 5 per loop, evenly spaced
// so they never overlap, heading along the motion, each tag moving speed_px per frame (15 px: ~0.5
// m/s at 30 fps, twice Nigel's top speed). Per frame, the 10 cars.
std::vector<std::vector<SynthCar>> synth_wide_drive(const SynthScene &s, int frames,
                                                    double speed_px = 15.0);

// Reference tags near the corners and edges of the map (ids 100..), for calibrate-map.
std::vector<RefTag> synth_reference_tags(const SynthScene &s);

}  // namespace eye
