#include "eye_intrinsics.hpp"

#include <opencv2/aruco/charuco.hpp>
#include <opencv2/calib3d.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "eye_error.hpp"

namespace eye {

IntrinsicsReport intrinsics_detect(const std::vector<cv::Mat> &views, const IntrinsicsParams &p) {
  IntrinsicsReport rep;
  rep.views_total = static_cast<int>(views.size());
  if (views.empty()) throw Error("calibrate-intrinsics: no images");
  const cv::Size pattern(p.inner_cols, p.inner_rows);
  const cv::Size size = views[0].size();
  std::vector<cv::Point3f> board;
  for (int r = 0; r < p.inner_rows; ++r)
    for (int c = 0; c < p.inner_cols; ++c)
      board.emplace_back(static_cast<float>(c * p.square_m), static_cast<float>(r * p.square_m),
                         0.f);
  rep.image_size = size;
  auto &obj = rep.points;
  auto &img = rep.corners;
  const auto dict = cv::aruco::getPredefinedDictionary(cv::aruco::DICT_5X5_100);
  const auto charuco = cv::aruco::CharucoBoard::create(
      p.inner_cols + 1, p.inner_rows + 1, static_cast<float>(p.square_m),
      static_cast<float>(p.square_m * p.marker_ratio), dict);
  for (size_t i = 0; i < views.size(); ++i) {
    const cv::Mat &v = views[i];
    if (v.size() != size)
      throw Error("calibrate-intrinsics: images differ in size (" + std::to_string(v.cols) + "x" +
                  std::to_string(v.rows) + " vs " + std::to_string(size.width) + "x" +
                  std::to_string(size.height) + ")");
    std::vector<cv::Point2f> corners;
    std::vector<cv::Point3f> points;
    if (p.charuco) {
      std::vector<int> mids, cids;
      std::vector<std::vector<cv::Point2f>> mcorners;
      cv::aruco::detectMarkers(v, dict, mcorners, mids);
      if (mids.size() < 4) continue;
      cv::aruco::interpolateCornersCharuco(mcorners, mids, v, charuco, corners, cids);
      if (corners.size() < 6) continue;
      for (auto &c : corners)
        c +=
            cv::Point2f(static_cast<float>(kArucoToOpencvPx), static_cast<float>(kArucoToOpencvPx));
      // Calibrate from ids' board points with calibrateCamera (same solver as checkerboards).
      for (int id : cids) points.push_back(charuco->chessboardCorners[static_cast<size_t>(id)]);
    } else {
      if (!cv::findChessboardCornersSB(v, pattern, corners, cv::CALIB_CB_ACCURACY)) continue;
      points = board;
    }
    for (const auto &c : corners) {
      const int cx = std::min(3, std::max(0, static_cast<int>(4 * c.x / size.width)));
      const int cy = std::min(3, std::max(0, static_cast<int>(4 * c.y / size.height)));
      rep.cells[static_cast<size_t>(cy * 4 + cx)] = true;
    }
    obj.push_back(points);
    img.push_back(corners);
    rep.used.push_back(static_cast<int>(i));
  }
  rep.views_used = static_cast<int>(img.size());
  int cells = 0;
  for (bool b : rep.cells) cells += b;
  rep.coverage = cells / 16.0;
  return rep;
}

void intrinsics_solve(IntrinsicsReport &rep, const IntrinsicsParams &p) {
  const auto &obj = rep.points;
  const auto &img = rep.corners;
  const cv::Size size = rep.image_size;
  if (rep.views_used < p.min_views)
    throw Error("calibrate-intrinsics: too few views: the " +
                std::string(p.charuco ? "ChArUco board" : "checkerboard") + " (" +
                std::to_string(p.inner_cols) + "x" + std::to_string(p.inner_rows) +
                " inner corners) was found in " + std::to_string(rep.views_used) + " of " +
                std::to_string(rep.views_total) + " images, need at least " +
                std::to_string(p.min_views));
  if (rep.coverage < p.min_coverage) {
    char b[160];
    std::snprintf(b, sizeof b,
                  "calibrate-intrinsics: poor coverage: corners reach %.0f%% of the image's 4x4 "
                  "grid, need %.0f%%; move the board into the corners of the image",
                  100 * rep.coverage, 100 * p.min_coverage);
    throw Error(b);
  }
  cv::Mat k, dist;
  std::vector<cv::Mat> rv, tv;
  const double rms =
      cv::calibrateCamera(obj, img, size, k, dist, rv, tv, p.fix_k3 ? cv::CALIB_FIX_K3 : 0);
  if (!(rms <= p.max_rms_px)) {
    char b[160];
    std::snprintf(b, sizeof b,
                  "calibrate-intrinsics: RMS reprojection error too high: %.3f px > %.3f px", rms,
                  p.max_rms_px);
    throw Error(b);
  }
  rep.in.width_px = size.width;
  rep.in.height_px = size.height;
  rep.in.k = cv::Matx33d(k);
  rep.in.dist.assign(dist.ptr<double>(), dist.ptr<double>() + dist.total());
  rep.in.rms_px = rms;
  rep.in.views = rep.views_used;
  rep.view_rms_px.clear();
  for (size_t i = 0; i < obj.size(); ++i) {
    std::vector<cv::Point2f> back;
    cv::projectPoints(obj[i], rv[i], tv[i], k, dist, back);
    double sq = 0;
    for (size_t j = 0; j < back.size(); ++j) {
      const cv::Point2f d = back[j] - img[i][j];
      sq += d.dot(d);
    }
    rep.view_rms_px.push_back(
        std::sqrt(sq / static_cast<double>(std::max<size_t>(1, back.size()))));
  }
}

IntrinsicsReport intrinsics_calibrate(const std::vector<cv::Mat> &views,
                                      const IntrinsicsParams &p) {
  IntrinsicsReport rep = intrinsics_detect(views, p);
  intrinsics_solve(rep, p);
  return rep;
}

}  // namespace eye
