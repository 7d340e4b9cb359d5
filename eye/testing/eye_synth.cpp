#include "eye_synth.hpp"

#include <opencv2/imgproc.hpp>

#include <algorithm>
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
  if (!s.shading.empty()) {
    cv::Mat f;
    img.convertTo(f, CV_32F);
    cv::multiply(f, s.shading, f);
    f.convertTo(img, CV_8U);
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

SynthScene synth_scene_wide(int w, int h) {
  SynthScene s = synth_scene(w, h, AUTODRIVE_VEHICLE_TAG_SIZE_M);
  const double f = 0.44 * w;
  s.in.k = cv::Matx33d(f, 0, (w - 1) / 2.0, 0, f, (h - 1) / 2.0, 0, 0, 1);
  s.in.dist = {-0.30, 0.10, 0, 0, 0};
  // Roof tags keep their pixel size at any resolution: the camera is 1.12 m above the roofs
  // at 1280 px wide, proportionally lower for smaller images (tests).
  const double roof_m = s.car.base_link_height_m + s.car.tag_offset_m[2];
  const double height_m = roof_m + 1.12 * w / 1280.0, tilt_rad = 15.0 * M_PI / 180.0;
  // The camera looks at the map centre (cx, cy) from the -y side, tilted by tilt_rad.
  s.map_x_m = 4.0;
  s.map_y_m = 3.0;
  const double cx = s.map_x_m / 2, cy = s.map_y_m / 2;
  s.pose =
      camera_look_at({cx, cy - height_m * std::tan(tilt_rad), height_m}, {cx, cy, 0.0}, {0, 1, 0});
  // The map: what the image corners see on the floor (plus nothing: tags reach every edge).
  double x0 = 1e9, x1 = -1e9, y0 = 1e9, y1 = -1e9;
  for (const cv::Point2d &c :
       {cv::Point2d(-0.5, -0.5), cv::Point2d(w - 0.5, -0.5), cv::Point2d(w - 0.5, h - 0.5),
        cv::Point2d(-0.5, h - 0.5), cv::Point2d(w / 2.0, -0.5), cv::Point2d(w / 2.0, h - 0.5)}) {
    const cv::Vec2d p = synth_pixel_to_plane(s, c, 0.0);
    x0 = std::min(x0, p[0]);
    x1 = std::max(x1, p[0]);
    y0 = std::min(y0, p[1]);
    y1 = std::max(y1, p[1]);
  }
  // Shift the world so that the map starts at the origin.
  const cv::Vec3d shift(-x0, -y0, 0);
  s.pose.t_cam_map -= s.pose.r_cam_map * shift;
  s.map_x_m = x1 - x0;
  s.map_y_m = y1 - y0;
  s.blur_sigma_px = 0.8;
  s.noise_sigma = 6.0;
  synth_set_light(s, 0.55, 0.45);
  return s;
}

void synth_set_light(SynthScene &s, double gain, double vignetting) {
  const int w = s.in.width_px, h = s.in.height_px;
  s.shading = cv::Mat(h, w, CV_32F);
  const double cx = (w - 1) / 2.0, cy = (h - 1) / 2.0, r2max = cx * cx + cy * cy;
  for (int r = 0; r < h; ++r)
    for (int c = 0; c < w; ++c) {
      const double q = ((c - cx) * (c - cx) + (r - cy) * (r - cy)) / r2max;
      s.shading.at<float>(r, c) = static_cast<float>(gain * (1.0 - vignetting * q));
    }
}

cv::Vec2d synth_pixel_to_plane(const SynthScene &s, const cv::Point2d &px, double z_m) {
  const auto norm = intrinsics_normalise(s.in, {px});
  cv::Vec2d xy(0, 0);
  camera_ray_to_plane(s.pose, norm[0], z_m, &xy);
  return xy;
}

double synth_tag_side_px(const SynthScene &s, const SynthCar &car) {
  const double c = std::cos(car.yaw_rad), sn = std::sin(car.yaw_rad);
  const double ox = s.car.tag_offset_m[0], oy = s.car.tag_offset_m[1];
  const double tx = car.x_m + c * ox - sn * oy, ty = car.y_m + sn * ox + c * oy;
  const double z = s.car.base_link_height_m + s.car.tag_offset_m[2];
  const auto tf = tag_corners_tagframe(s.car.tag_size_m);
  std::array<cv::Point2d, 4> p;
  for (size_t i = 0; i < 4; ++i)
    p[i] = camera_project(
        s.in, s.pose, {tx + c * tf[i][0] - sn * tf[i][1], ty + sn * tf[i][0] + c * tf[i][1], z});
  double side = 1e9;
  for (size_t i = 0; i < 4; ++i) side = std::min(side, cv::norm(p[i] - p[(i + 1) % 4]));
  return side;
}

std::vector<RefTag> synth_reference_tags_in_view(const SynthScene &s) {
  std::vector<RefTag> out;
  int id = 100;
  for (double fy : {0.16, 0.5, 0.84})
    for (double fx : {0.14, 0.5, 0.86}) {
      if (fx == 0.5 && fy == 0.5) continue;
      const cv::Vec2d p =
          synth_pixel_to_plane(s, {fx * (s.in.width_px - 1), fy * (s.in.height_px - 1)}, 0.0);
      out.push_back({id, p[0], p[1], 0.0, 0.4 * (id - 100), 0.10});
      ++id;
    }
  return out;
}

// A point at arc length u (0..1 of the perimeter) along a rectangle of half-extents ax, ay with
// quarter-circle corners of radius rc, centred at (cx, cy), counter-clockwise in the image.
static cv::Point2d rounded_rect(double u, double cx, double cy, double ax, double ay, double rc) {
  const double lx = 2 * (ax - rc), ly = 2 * (ay - rc), arc = 0.5 * M_PI * rc;
  double s = (u - std::floor(u)) * (2 * lx + 2 * ly + 4 * arc);
  // Segments: bottom edge (+x), corner, right edge (-y), corner, top (-x), corner, left (+y).
  const double seg[8] = {lx, arc, ly, arc, lx, arc, ly, arc};
  const cv::Point2d start[4] = {{cx - ax + rc, cy + ay},
                                {cx + ax, cy + ay - rc},
                                {cx + ax - rc, cy - ay},
                                {cx - ax, cy - ay + rc}};
  const cv::Point2d dir[4] = {{1, 0}, {0, -1}, {-1, 0}, {0, 1}};
  for (int k = 0; k < 8; ++k) {
    if (s > seg[k] && k < 7) {
      s -= seg[k];
      continue;
    }
    const int e = k / 2;
    if (k % 2 == 0) return start[e] + s * dir[e];
    // The corner after edge e: centre one radius inwards from the edge's end.
    const cv::Point2d end = start[e] + seg[k - 1] * dir[e];
    const cv::Point2d in = dir[(e + 1) % 4] * rc;  // towards the centre of the turn
    const double a = s / rc;
    return end + in - in * std::cos(a) + dir[e] * rc * std::sin(a);
  }
  return {cx, cy};
}

std::vector<std::vector<SynthCar>> synth_wide_drive(const SynthScene &s, int frames,
                                                    double speed_px) {
  const double w = s.in.width_px, h = s.in.height_px, margin_px = 32;
  const double z_roof = s.car.base_link_height_m + s.car.tag_offset_m[2];
  const auto loop = [&](int l, double u) {
    const double sc = l == 0 ? 1.0 : 0.42;
    const double ax = sc * ((w - 1) / 2 - margin_px), ay = sc * ((h - 1) / 2 - margin_px);
    return rounded_rect(u, (w - 1) / 2, (h - 1) / 2, ax, ay, 0.3 * ay);
  };
  const auto perimeter = [&](int l) {
    double p = 0;
    for (int k = 0; k < 400; ++k) p += cv::norm(loop(l, (k + 1) / 400.0) - loop(l, k / 400.0));
    return p;
  };
  const double per[2] = {perimeter(0), perimeter(1)};
  std::vector<std::vector<SynthCar>> out(static_cast<size_t>(frames));
  for (int i = 0; i < frames; ++i)
    for (int k = 0; k < 10; ++k) {
      const int l = k / 5;
      const double u = i * speed_px / per[l] + (k % 5) / 5.0 + 0.1 * l;
      const cv::Vec2d a = synth_pixel_to_plane(s, loop(l, u), z_roof);
      const cv::Vec2d b = synth_pixel_to_plane(s, loop(l, u + 1e-4), z_roof);
      const double yaw = std::atan2(b[1] - a[1], b[0] - a[0]);
      const double c = std::cos(yaw), sn = std::sin(yaw);
      const double ox = s.car.tag_offset_m[0], oy = s.car.tag_offset_m[1];
      out[static_cast<size_t>(i)].push_back(
          {k + 1, a[0] - (c * ox - sn * oy), a[1] - (sn * ox + c * oy), yaw});
    }
  return out;
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
