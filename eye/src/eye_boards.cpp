#include "eye_boards.hpp"

#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include <cmath>
#include <cstdio>

#include "eye_error.hpp"
#include "eye_render.hpp"

namespace eye {

namespace {

constexpr int kGrid = 4;           // the coverage grid of calibrate-intrinsics (4 x 4 cells)
constexpr double kPullIn = 0.72;   // cell centres pulled towards the image centre by this
constexpr double kSpin_rad = 0.2;  // the board also turns about the optical axis, up to this

}  // namespace

std::vector<BoardView> boards_render(const Intrinsics &in, const IntrinsicsParams &p,
                                     const BoardSetParams &b) {
  if (p.charuco) throw Error("make-board-images: renders checkerboards only (drop --charuco)");
  if (in.width_px <= 0 || in.height_px <= 0)
    throw Error("make-board-images: the camera model has no image size");
  if (b.views < 1) throw Error("make-board-images: --views must be at least 1");
  const int cols = p.inner_cols + 1, rows = p.inner_rows + 1;
  const double bw = cols * p.square_m, bh = rows * p.square_m;
  // At this distance the untilted board spans width_share of the image width.
  const double dist_m = in.k(0, 0) * bw / (b.width_share * in.width_px);
  std::vector<BoardView> out;
  for (int i = 0; i < b.views; ++i) {
    const int cell = i % (kGrid * kGrid), round = i / (kGrid * kGrid);
    const double u = 0.5 + kPullIn * (((cell % kGrid) + 0.5) / kGrid - 0.5);
    const double v = 0.5 + kPullIn * (((cell / kGrid) + 0.5) / kGrid - 0.5);
    const auto ray = intrinsics_normalise(in, {{u * in.width_px, v * in.height_px}})[0];
    // Tilt alternately about x and y, its sign and size changing from round to round.
    const double sign = ((cell + round) % 2) ? 1.0 : -1.0;
    const double tilt = b.max_tilt_rad * sign * (1.0 - 0.3 * (round % 3));
    const double ax = (i % 2) ? tilt : 0.3 * tilt, ay = (i % 2) ? 0.3 * tilt : tilt;
    cv::Mat rvec = (cv::Mat_<double>(3, 1) << ax, ay, kSpin_rad * std::sin(1.3 * i)), r;
    cv::Rodrigues(rvec, r);
    BoardView view;
    view.board_to_cam.r_cam_map = cv::Matx33d(r);
    const cv::Vec3d centre_cam = dist_m * cv::Vec3d(ray.x, ray.y, 1.0);
    view.board_to_cam.t_cam_map =
        centre_cam - view.board_to_cam.r_cam_map * cv::Vec3d(bw / 2, bh / 2, 0);
    view.image = render_checkerboard(in, view.board_to_cam, cols, rows, p.square_m, b.ss);
    out.push_back(std::move(view));
  }
  return out;
}

cv::Mat intrinsics_coverage_image(const IntrinsicsReport &rep) {
  cv::Mat img(rep.image_size, CV_8UC3, cv::Scalar(40, 40, 40));
  const double cw = rep.image_size.width / double(kGrid),
               ch = rep.image_size.height / double(kGrid);
  for (int r = 0; r < kGrid; ++r)
    for (int c = 0; c < kGrid; ++c) {
      const cv::Rect cell(int(c * cw), int(r * ch), int(cw), int(ch));
      const bool hit = rep.cells[static_cast<size_t>(r * kGrid + c)];
      img(cell).setTo(hit ? cv::Scalar(40, 90, 40) : cv::Scalar(40, 40, 120));
      cv::rectangle(img, cell, cv::Scalar(160, 160, 160), 1);
    }
  for (size_t v = 0; v < rep.corners.size(); ++v) {
    cv::Mat hue(1, 1, CV_8UC3,
                cv::Scalar(static_cast<int>(180 * v / rep.corners.size()), 255, 255));
    cv::cvtColor(hue, hue, cv::COLOR_HSV2BGR);
    const cv::Vec3b bgr = hue.at<cv::Vec3b>(0, 0);
    for (const auto &c : rep.corners[v])
      cv::circle(img, c, 2, cv::Scalar(bgr[0], bgr[1], bgr[2]), cv::FILLED, cv::LINE_AA);
  }
  char text[160];
  std::snprintf(text, sizeof text, "%d/%d images, coverage %.0f%% of the 4x4 grid%s",
                rep.views_used, rep.views_total, 100 * rep.coverage,
                rep.in.rms_px > 0 ? "" : " (not calibrated)");
  cv::putText(img, text, {10, 24}, cv::FONT_HERSHEY_SIMPLEX, 0.6, cv::Scalar(255, 255, 255), 1,
              cv::LINE_AA);
  if (rep.in.rms_px > 0) {
    std::snprintf(text, sizeof text, "RMS reprojection error %.3f px", rep.in.rms_px);
    cv::putText(img, text, {10, 48}, cv::FONT_HERSHEY_SIMPLEX, 0.6, cv::Scalar(255, 255, 255), 1,
                cv::LINE_AA);
  }
  return img;
}

}  // namespace eye
