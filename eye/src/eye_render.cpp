#include "eye_render.hpp"

#include <apriltag.h>
#include <tag36h11.h>

#include <algorithm>
#include <cmath>
#include <deque>
#include <opencv2/calib3d.hpp>

#include "eye_error.hpp"

namespace eye {

cv::Mat render_tag_bitmap(int id) {
  apriltag_family_t *fam = tag36h11_create();
  if (id < 0 || id >= static_cast<int>(fam->ncodes)) {
    tag36h11_destroy(fam);
    throw Error("render_tag_bitmap: tag36h11 has no id " + std::to_string(id));
  }
  // White outside, a black square of width_at_border cells, then the data bits (MSB first) at
  // (bit_x, bit_y) counted from the black square's corner.
  const int w = fam->total_width, b = fam->width_at_border, off = (w - b) / 2;
  cv::Mat out(w, w, CV_8UC1, cv::Scalar(255));
  out(cv::Rect(off, off, b, b)).setTo(0);
  const uint64_t code = fam->codes[id];
  for (uint32_t i = 0; i < fam->nbits; ++i)
    if ((code >> (fam->nbits - 1 - i)) & 1u)
      out.at<uint8_t>(static_cast<int>(fam->bit_y[i]) + off,
                      static_cast<int>(fam->bit_x[i]) + off) = 255;
  tag36h11_destroy(fam);
  return out;
}

cv::Matx33d render_plane_to_image(const Intrinsics &in, const CameraPose &pose, double z_m) {
  const cv::Matx33d &r = pose.r_cam_map;
  cv::Matx33d m(r(0, 0), r(0, 1), r(0, 2) * z_m + pose.t_cam_map[0], r(1, 0), r(1, 1),
                r(1, 2) * z_m + pose.t_cam_map[1], r(2, 0), r(2, 1),
                r(2, 2) * z_m + pose.t_cam_map[2]);
  return in.k * m;
}

static bool has_distortion(const Intrinsics &in) {
  return std::any_of(in.dist.begin(), in.dist.end(), [](double d) { return d != 0.0; });
}

const cv::Mat &render_undistort_grid(const Intrinsics &in) {
  static const cv::Mat none;
  if (!has_distortion(in)) return none;
  struct Entry {
    cv::Matx33d k;
    std::vector<double> dist;
    int w, h;
    cv::Mat grid;
  };
  static std::deque<Entry> cache;  // most recent first; references stay valid on push_front
  for (const auto &e : cache)
    if (e.k == in.k && e.dist == in.dist && e.w == in.width_px && e.h == in.height_px)
      return e.grid;
  std::vector<cv::Point2d> px;
  px.reserve(static_cast<size_t>((in.width_px + 1) * (in.height_px + 1)));
  for (int r = 0; r <= in.height_px; ++r)
    for (int c = 0; c <= in.width_px; ++c) px.emplace_back(c - 0.5, r - 0.5);
  std::vector<cv::Point2d> und;
  cv::undistortPoints(px, und, cv::Mat(in.k), in.dist, cv::noArray(), cv::Mat(in.k),
                      cv::TermCriteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 30, 1e-12));
  cv::Mat grid(in.height_px + 1, in.width_px + 1, CV_64FC2);
  std::copy(und.begin(), und.end(), grid.ptr<cv::Point2d>());
  cache.push_front({in.k, in.dist, in.width_px, in.height_px, grid});
  if (cache.size() > 4) cache.pop_back();
  return cache.front().grid;
}

// Distorted pixels of undistorted pixels (the lens model of cv::projectPoints).
static std::vector<cv::Point2d> distort_px(const Intrinsics &in,
                                           const std::vector<cv::Point2d> &und) {
  std::vector<cv::Point3d> rays;
  for (const auto &u : und)
    rays.emplace_back((u.x - in.k(0, 2)) / in.k(0, 0), (u.y - in.k(1, 2)) / in.k(1, 1), 1.0);
  std::vector<cv::Point2d> out;
  cv::projectPoints(rays, cv::Vec3d(0, 0, 0), cv::Vec3d(0, 0, 0), cv::Mat(in.k), in.dist, out);
  return out;
}

void render_texture(cv::Mat &img, const cv::Mat &tex, const cv::Matx33d &h, int ss,
                    const Intrinsics *in) {
  CV_Assert(img.type() == CV_8UC1 && tex.type() == CV_8UC1 && ss >= 1);
  const double tw = tex.cols, th = tex.rows;
  const cv::Mat &grid = in ? render_undistort_grid(*in) : cv::Mat();
  if (!grid.empty()) CV_Assert(grid.rows == img.rows + 1 && grid.cols == img.cols + 1);
  // Bounding box of the texture's outer edge in the image; through a lens its straight edges
  // bend, so 8 points per edge and a pixel of margin.
  const int per_edge = grid.empty() ? 1 : 8;
  std::vector<cv::Point2d> outline;
  const cv::Vec2d edge[4] = {
      {-0.5, -0.5}, {tw - 0.5, -0.5}, {tw - 0.5, th - 0.5}, {-0.5, th - 0.5}};
  for (int e = 0; e < 4; ++e)
    for (int k = 0; k < per_edge; ++k) {
      const double a = static_cast<double>(k) / per_edge;
      const cv::Vec2d t = edge[e] * (1 - a) + edge[(e + 1) % 4] * a;
      const cv::Vec3d p = h * cv::Vec3d(t[0], t[1], 1.0);
      if (p[2] <= 0) return;  // behind the camera
      outline.emplace_back(p[0] / p[2], p[1] / p[2]);
    }
  if (!grid.empty()) outline = distort_px(*in, outline);
  const double pad = grid.empty() ? 0.0 : 1.0;
  double x0 = 1e18, x1 = -1e18, y0 = 1e18, y1 = -1e18;
  for (const auto &p : outline) {
    x0 = std::min(x0, p.x - pad);
    x1 = std::max(x1, p.x + pad);
    y0 = std::min(y0, p.y - pad);
    y1 = std::max(y1, p.y + pad);
  }
  if (!(x1 >= -1 && y1 >= -1 && x0 <= img.cols && y0 <= img.rows)) return;
  const int c0 = std::max(0, static_cast<int>(std::floor(x0 + 0.5)));
  const int c1 = std::min(img.cols - 1, static_cast<int>(std::ceil(x1 + 0.5)));
  const int r0 = std::max(0, static_cast<int>(std::floor(y0 + 0.5)));
  const int r1 = std::min(img.rows - 1, static_cast<int>(std::ceil(y1 + 0.5)));
  const cv::Matx33d hi = h.inv();
  const double n = ss * ss;
  for (int row = r0; row <= r1; ++row) {
    uint8_t *line = img.ptr<uint8_t>(row);
    for (int col = c0; col <= c1; ++col) {
      cv::Point2d g00, g01, g10, g11;  // undistorted pixel corners of this pixel
      if (!grid.empty()) {
        g00 = grid.at<cv::Point2d>(row, col);
        g01 = grid.at<cv::Point2d>(row, col + 1);
        g10 = grid.at<cv::Point2d>(row + 1, col);
        g11 = grid.at<cv::Point2d>(row + 1, col + 1);
      }
      double sum = 0, inside = 0;
      for (int j = 0; j < ss; ++j) {
        const double fy = (j + 0.5) / ss;
        for (int i = 0; i < ss; ++i) {
          const double fx = (i + 0.5) / ss;
          double x = col - 0.5 + fx, y = row - 0.5 + fy;
          if (!grid.empty()) {
            const cv::Point2d u =
                (g00 * (1 - fx) + g01 * fx) * (1 - fy) + (g10 * (1 - fx) + g11 * fx) * fy;
            x = u.x;
            y = u.y;
          }
          const cv::Vec3d q = hi * cv::Vec3d(x, y, 1.0);
          const double u = q[0] / q[2], v = q[1] / q[2];
          // Texel (tc, tr) covers [tc-0.5, tc+0.5): nearest texel is floor(u + 0.5).
          const int tc = static_cast<int>(std::floor(u + 0.5));
          const int tr = static_cast<int>(std::floor(v + 0.5));
          if (tc < 0 || tr < 0 || tc >= tex.cols || tr >= tex.rows) continue;
          sum += tex.at<uint8_t>(tr, tc);
          inside += 1;
        }
      }
      if (inside == 0) continue;
      const double v = (line[col] * (n - inside) + sum) / n;
      line[col] = static_cast<uint8_t>(std::lround(v));
    }
  }
}

// Homography from texture coordinates of a w x h texel texture spread over length_m (texture
// rows, towards -x: row 0 is the top = +x) by width_m (columns, towards -y: col 0 is the left =
// +y) to the plane frame of the object, then to the map, then to pixels.
static cv::Matx33d texture_homography(const Intrinsics &in, const CameraPose &pose, int tw, int th,
                                      double length_m, double width_m, double x_m, double y_m,
                                      double z_m, double yaw_rad) {
  const double sx = length_m / th, sy = width_m / tw;
  // texture (u, v) -> object plane (x, y): x = (th/2 - (v + 0.5)) sx, y = (tw/2 - (u + 0.5)) sy
  const cv::Matx33d tex_to_obj(0, -sx, (th / 2.0 - 0.5) * sx, -sy, 0, (tw / 2.0 - 0.5) * sy, 0, 0,
                               1);
  const double c = std::cos(yaw_rad), s = std::sin(yaw_rad);
  const cv::Matx33d obj_to_map(c, -s, x_m, s, c, y_m, 0, 0, 1);
  return render_plane_to_image(in, pose, z_m) * obj_to_map * tex_to_obj;
}

void render_tag(cv::Mat &img, const Intrinsics &in, const CameraPose &pose, int id, double size_m,
                double x_m, double y_m, double z_m, double yaw_rad, int ss) {
  const cv::Mat bmp = render_tag_bitmap(id);
  // tag36h11: 10 cells in total, the black border spans the middle 8.
  const double whole_m = size_m * bmp.cols / 8.0;
  render_texture(
      img, bmp,
      texture_homography(in, pose, bmp.cols, bmp.rows, whole_m, whole_m, x_m, y_m, z_m, yaw_rad),
      ss, &in);
}

void render_rect(cv::Mat &img, const Intrinsics &in, const CameraPose &pose, uint8_t grey,
                 double length_m, double width_m, double x_m, double y_m, double z_m,
                 double yaw_rad, int ss) {
  const cv::Mat tex(1, 1, CV_8UC1, cv::Scalar(grey));
  render_texture(img, tex,
                 texture_homography(in, pose, 1, 1, length_m, width_m, x_m, y_m, z_m, yaw_rad), ss,
                 &in);
}

CameraPose camera_look_at(const cv::Vec3d &eye_m, const cv::Vec3d &target_m,
                          const cv::Vec3d &up_m) {
  const cv::Vec3d z = cv::normalize(target_m - eye_m);
  const cv::Vec3d x = cv::normalize((-up_m).cross(z));
  const cv::Vec3d y = z.cross(x);
  CameraPose p;
  p.r_cam_map = cv::Matx33d(x[0], x[1], x[2], y[0], y[1], y[2], z[0], z[1], z[2]);
  p.t_cam_map = -(p.r_cam_map * eye_m);
  return p;
}

cv::Mat render_checkerboard(const Intrinsics &in, const CameraPose &board_pose, int cols, int rows,
                            double square_m, int ss) {
  cv::Mat img(in.height_px, in.width_px, CV_8UC1, cv::Scalar(128));
  // Texture: one texel per square plus a white margin of one square around the board.
  cv::Mat tex(rows + 2, cols + 2, CV_8UC1, cv::Scalar(255));
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < cols; ++c) tex.at<uint8_t>(r + 1, c + 1) = ((r + c) % 2) ? 255 : 0;
  // Texel (c, r) covers board x in [(c-1) sq, c sq] (y likewise): the board's squares fill
  // [0, cols sq] x [0, rows sq] and its inner corners sit at (i sq, j sq), i, j >= 1.
  const cv::Matx33d tex_to_board(square_m, 0, -0.5 * square_m, 0, square_m, -0.5 * square_m, 0, 0,
                                 1);
  render_texture(img, tex, render_plane_to_image(in, board_pose, 0.0) * tex_to_board, ss, &in);
  return img;
}

}  // namespace eye
