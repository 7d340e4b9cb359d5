// Whole-field detection: the detector's resolution per image region from the expected tag size
// in pixels. The calibration (intrinsics with the lens, camera pose, roof-plane height) gives
// the metres per pixel everywhere, so the Eye knows where a tag looks small (the edges of a
// wide-angle lens, the far side of a tilted camera) and scans only there at full resolution.
#pragma once
#include <opencv2/core.hpp>

#include <vector>

#include "eye_camera.hpp"

namespace eye {

struct ScanRegion {
  cv::Rect rect;   // [px]
  float decimate;  // libapriltag quad_decimate for this region
};

struct ScanPlanParams {
  // The detector wants a tag at least this many pixels a side after decimation (measured: at
  // decimate 2, tags of 20-26 px were missed near the edge of a wide lens, 40 px never).
  double min_tag_px_decimated = 16.0;
  int cell_px = 80;  // the image is planned in cells of this size
};

// Smallest and largest side [px] of a square tag of side tag_size_m lying on the plane z_m
// (any yaw), seen at pixel px through the lens. {0, 0} if the pixel does not see the plane.
cv::Vec2d expected_tag_side_px(const Intrinsics &in, const CameraPose &pose, double z_m,
                               double tag_size_m, const cv::Point2d &px);

// The largest decimation of {1, 1.5, 2, 3, 4, ...} up to `coarse` that keeps a tag of side_px
// at least min_px a side.
float decimate_for_side(double side_px, float coarse, double min_px);

struct ScanPlan {
  std::vector<ScanRegion> regions;
  double max_tag_px = 0;  // the largest tag side anywhere in the frame [px]
  // The largest tag side per horizontal strip of strip_px rows [px] (empty: max_tag_px
  // everywhere), so that a band is padded by the tags that can lie across its border only.
  std::vector<double> strip_max_tag_px;
  int strip_px = 0;
};

// Regions whose union finds every tag of the plane in the frame: the whole frame at `coarse`
// (every tag big enough for it, wherever it is), plus, in cells of cell_px where the smallest
// tag needs a finer decimation, rectangles at that decimation (cell runs per level, padded by
// the largest tag in them so that a tag on their border is whole in one region). When those
// regions together cost more (pixels / decimate^2) than one scan of the frame at the finest
// level, the plan is that one scan.
ScanPlan plan_full_scan(const Intrinsics &in, const CameraPose &pose, double z_m, double tag_size_m,
                        float coarse, const ScanPlanParams &p = ScanPlanParams());

// Slice k of n of a plan: its regions cut to band k of n horizontal bands, each band extended
// downwards by the tallest tag whose top can lie in it (sqrt(2) x the largest side there: a tag
// turned 45 deg), so every tag is whole in the band of its top row and scanning slices 0..n-1
// in n frames finds every tag that stays put.
std::vector<ScanRegion> plan_slice(const ScanPlan &plan, int k, int n, int height_px);

}  // namespace eye
