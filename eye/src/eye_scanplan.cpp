#include "eye_scanplan.hpp"

#include <algorithm>
#include <cmath>

namespace eye {

cv::Vec2d expected_tag_side_px(const Intrinsics &in, const CameraPose &pose, double z_m,
                               double tag_size_m, const cv::Point2d &px) {
  const auto norm = intrinsics_normalise(in, {px});
  cv::Vec2d xy;
  if (!camera_ray_to_plane(pose, norm[0], z_m, &xy)) return {0, 0};
  // Jacobian of the projection (with the lens) over one tag size along map x and y; the
  // side at yaw t is |a cos t + b sin t|: its extremes are the singular values of [a b].
  const double h = 0.5 * tag_size_m;
  const cv::Point2d xm = camera_project(in, pose, {xy[0] - h, xy[1], z_m});
  const cv::Point2d xp = camera_project(in, pose, {xy[0] + h, xy[1], z_m});
  const cv::Point2d ym = camera_project(in, pose, {xy[0], xy[1] - h, z_m});
  const cv::Point2d yp = camera_project(in, pose, {xy[0], xy[1] + h, z_m});
  const cv::Point2d a = xp - xm, b = yp - ym;
  // Eigenvalues of M^T M for M = [a b].
  const double p = a.dot(a), q = a.dot(b), r = b.dot(b);
  const double tr = p + r, det = p * r - q * q;
  const double disc = std::sqrt(std::max(0.0, tr * tr / 4 - det));
  return {std::sqrt(std::max(0.0, tr / 2 - disc)), std::sqrt(tr / 2 + disc)};
}

float decimate_for_side(double side_px, float coarse, double min_px) {
  float best = 1.0f;
  for (float d : {1.5f, 2.0f, 3.0f, 4.0f, 6.0f, 8.0f})
    if (d <= coarse && side_px / d >= min_px) best = d;
  return std::min(best, std::max(1.0f, coarse));
}

ScanPlan plan_full_scan(const Intrinsics &in, const CameraPose &pose, double z_m, double tag_size_m,
                        float coarse, const ScanPlanParams &p) {
  const int w = in.width_px, h = in.height_px, cell = std::max(16, p.cell_px);
  const int nc = (w + cell - 1) / cell, nr = (h + cell - 1) / cell;
  // Per cell: the smallest tag (its decimation) and the largest (its padding), over the
  // cell's corners and centre.
  std::vector<float> level(static_cast<size_t>(nc * nr));
  double max_side = 0;
  std::vector<double> big(level.size());
  for (int r = 0; r < nr; ++r)
    for (int c = 0; c < nc; ++c) {
      const double x0 = c * cell - 0.5, y0 = r * cell - 0.5;
      const double x1 = std::min(w, (c + 1) * cell) - 0.5, y1 = std::min(h, (r + 1) * cell) - 0.5;
      double lo = 1e9, hi = 0;
      for (const cv::Point2d &q :
           {cv::Point2d(x0, y0), cv::Point2d(x1, y0), cv::Point2d(x0, y1), cv::Point2d(x1, y1),
            cv::Point2d((x0 + x1) / 2, (y0 + y1) / 2)}) {
        const cv::Vec2d s = expected_tag_side_px(in, pose, z_m, tag_size_m, q);
        if (s[1] <= 0) continue;  // this pixel sees the sky: no tag there
        lo = std::min(lo, s[0]);
        hi = std::max(hi, s[1]);
      }
      const size_t k = static_cast<size_t>(r * nc + c);
      level[k] = hi > 0 ? decimate_for_side(lo, coarse, p.min_tag_px_decimated) : coarse;
      big[k] = hi;
      max_side = std::max(max_side, hi);
    }
  const cv::Rect frame(0, 0, w, h);
  ScanPlan plan;
  plan.max_tag_px = max_side;
  plan.strip_px = cell;
  plan.strip_max_tag_px.assign(static_cast<size_t>(nr), 0.0);
  for (int r = 0; r < nr; ++r)
    for (int c = 0; c < nc; ++c)
      plan.strip_max_tag_px[static_cast<size_t>(r)] = std::max(
          plan.strip_max_tag_px[static_cast<size_t>(r)], big[static_cast<size_t>(r * nc + c)]);
  std::vector<ScanRegion> &out = plan.regions;
  // The whole frame at the coarse decimation finds every tag big enough for it, wherever it
  // is (also one across cell borders); finer rectangles add the cells where tags are small.
  out.push_back({frame, coarse});
  std::vector<float> levels(level.begin(), level.end());
  std::sort(levels.begin(), levels.end());
  levels.erase(std::unique(levels.begin(), levels.end()), levels.end());
  if (levels.front() >= coarse) return plan;
  for (float lv : levels) {
    if (lv >= coarse) continue;
    // Runs of cells at this level per cell row, merged with the same run in the next rows.
    struct Run {
      int c0, c1, r0, r1;
      double pad;
    };
    std::vector<Run> runs;
    for (int r = 0; r < nr; ++r)
      for (int c = 0; c < nc;) {
        if (level[static_cast<size_t>(r * nc + c)] != lv) {
          ++c;
          continue;
        }
        int e = c;
        double pad = 0;
        while (e < nc && level[static_cast<size_t>(r * nc + e)] == lv)
          pad = std::max(pad, big[static_cast<size_t>(r * nc + e++)]);
        auto it = std::find_if(runs.begin(), runs.end(),
                               [&](const Run &q) { return q.c0 == c && q.c1 == e && q.r1 == r; });
        if (it != runs.end()) {
          it->r1 = r + 1;
          it->pad = std::max(it->pad, pad);
        } else {
          runs.push_back({c, e, r, r + 1, pad});
        }
        c = e;
      }
    for (const auto &q : runs) {
      const int pad = static_cast<int>(std::ceil(q.pad));
      const cv::Rect rect = cv::Rect(cv::Point(q.c0 * cell - pad, q.r0 * cell - pad),
                                     cv::Point(q.c1 * cell + pad, q.r1 * cell + pad)) &
                            frame;
      if (rect.area() > 0) out.push_back({rect, lv});
    }
  }
  // Padding and overlap have a price: when the regions cost more detector work (pixels /
  // decimate^2) than one scan of the frame at the finest level, that scan is the plan.
  double cost = 0;
  for (const auto &r : out) cost += r.rect.area() / (static_cast<double>(r.decimate) * r.decimate);
  const float finest = levels.front();
  if (cost >= frame.area() / (static_cast<double>(finest) * finest)) out = {{frame, finest}};
  return plan;
}

std::vector<ScanRegion> plan_slice(const ScanPlan &plan, int k, int n, int height_px) {
  if (n <= 1) return plan.regions;
  const int y0 = k * height_px / n, core_end = (k + 1) * height_px / n;
  // A tag whose top row is in [y0, core_end) lies within [y0, core_end + tallest): the largest
  // side over those rows (every row if the plan has no strips) bounds its height.
  const double tallest = std::sqrt(2.0) * plan.max_tag_px;
  double side = plan.max_tag_px;
  if (!plan.strip_max_tag_px.empty() && plan.strip_px > 0) {
    side = 0;
    const int s0 = y0 / plan.strip_px;
    const int s1 = static_cast<int>(std::ceil((core_end + tallest) / plan.strip_px));
    for (int s = std::max(0, s0);
         s < std::min<int>(s1, static_cast<int>(plan.strip_max_tag_px.size())); ++s)
      side = std::max(side, plan.strip_max_tag_px[static_cast<size_t>(s)]);
  }
  const int y1 = core_end + static_cast<int>(std::ceil(std::sqrt(2.0) * side));
  std::vector<ScanRegion> out;
  for (const auto &r : plan.regions) {
    const cv::Rect band = r.rect & cv::Rect(r.rect.x, y0, r.rect.width, y1 - y0);
    if (band.area() > 0) out.push_back({band, r.decimate});
  }
  return out;
}

}  // namespace eye
