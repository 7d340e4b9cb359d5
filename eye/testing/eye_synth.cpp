#include "eye_synth.hpp"

#include <opencv2/imgproc.hpp>

#include <cmath>

#include "eye_render.hpp"

namespace eye {

SynthScene synth_scene(int w, int h, double tag_size_m) {
  SynthScene s;
  s.in.width_px = w;
  s.in.height_px = h;
  s.in.dist = {0, 0, 0, 0, 0};
  // Fit the map plus a 0.1 m margin into the image from 2.5 m up (the tighter axis decides).
  const double f = std::min(0.5 * w / (1.7 / 2.5), 0.5 * h / (1.2 / 2.5));
  s.in.k = cv::Matx33d(f, 0, (w - 1) / 2.0, 0, f, (h - 1) / 2.0, 0, 0, 1);
  s.pose = camera_look_at({1.52, 0.93, 2.5}, {1.5, 1.0, 0.0}, {0, 1, 0});
  s.car.tag_size_m = tag_size_m;
  s.car.tag_offset_m = eye::LocateParams{}.tag_offset_m;  // Nigel's (vehicle/nigel.params)
  s.car.base_link_height_m = 0.0;
  // Floor: mid grey with a smooth gradient and soft blobs, so thresholds see texture.
  s.floor = cv::Mat(h, w, CV_8UC1);
  for (int r = 0; r < h; ++r)
    for (int c = 0; c < w; ++c)
      s.floor.at<uint8_t>(r, c) =
          static_cast<uint8_t>(120 + 25 * std::sin(c * 0.011) * std::cos(r * 0.017) + 20.0 * c / w);
  return s;
}

cv::Mat synth_frame(const SynthScene &s, const std::vector<SynthCar> &cars,
                    const std::vector<RefTag> &floor_tags, uint64_t seed) {
  cv::Mat img = s.floor.clone();
  for (const auto &t : floor_tags)
    render_tag(img, s.in, s.pose, t.id, t.size_m, t.x_m, t.y_m, t.z_m, t.yaw_rad, s.ss);
  const double z_roof = s.car.base_link_height_m + s.car.tag_offset_m[2];
  for (const auto &car : cars) {
    const double c = std::cos(car.yaw_rad), sn = std::sin(car.yaw_rad);
    const double ox = s.car.tag_offset_m[0], oy = s.car.tag_offset_m[1];
    const double tx = car.x_m + c * ox - sn * oy, ty = car.y_m + sn * ox + c * oy;
    // dark body 0.26 x 0.19 m, white roof around the tag, then the tag.
    render_rect(img, s.in, s.pose, 45, 0.26, 0.19, tx, ty, z_roof - 0.04, car.yaw_rad, s.ss);
    const double roof = s.car.tag_size_m * 1.4;
    render_rect(img, s.in, s.pose, 235, roof, roof, tx, ty, z_roof - 0.001, car.yaw_rad, s.ss);
    render_tag(img, s.in, s.pose, car.tag_id, s.car.tag_size_m, tx, ty, z_roof, car.yaw_rad, s.ss);
  }
  if (s.blur_sigma_px > 0) cv::GaussianBlur(img, img, cv::Size(0, 0), s.blur_sigma_px);
  if (s.noise_sigma > 0) {
    cv::Mat n(img.size(), CV_32F);
    cv::RNG rng(seed);
    rng.fill(n, cv::RNG::NORMAL, 0.0, s.noise_sigma);
    cv::Mat f;
    img.convertTo(f, CV_32F);
    f += n;
    f.convertTo(img, CV_8U);  // saturates
  }
  return img;
}

std::vector<RefTag> synth_reference_tags(const SynthScene &s) {
  std::vector<RefTag> out;
  const double xs[3] = {0.15, s.map_x_m / 2, s.map_x_m - 0.15};
  const double ys[3] = {0.15, s.map_y_m / 2, s.map_y_m - 0.15};
  int id = 100;
  for (double y : ys)
    for (double x : xs) {
      if (x == s.map_x_m / 2 && y == s.map_y_m / 2) continue;  // keep the centre free
      out.push_back({id, x, y, 0.0, 0.3 * (id - 100), 0.12});
      ++id;
    }
  return out;
}

}  // namespace eye
