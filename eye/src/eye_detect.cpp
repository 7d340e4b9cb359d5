#include "eye_detect.hpp"

#include <apriltag.h>
#include <tag36h11.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>

#include "eye_error.hpp"

namespace eye {

Detector::Detector(const DetectorParams &p) : params_(p) {
  apriltag_family_t *fam = tag36h11_create();
  apriltag_detector_t *td = apriltag_detector_create();
  apriltag_detector_add_family_bits(td, fam, 2);
  td->nthreads = 1;
  td->quad_decimate = p.decimate;
  td->quad_sigma = p.sigma_px;
  td->refine_edges = p.refine_edges;
  td->decode_sharpening = p.sharpening;
  td->qtp.min_white_black_diff = p.min_contrast;
  td_ = td;
  fam_ = fam;
}

Detector::~Detector() {
  apriltag_detector_destroy(static_cast<apriltag_detector_t *>(td_));
  tag36h11_destroy(static_cast<apriltag_family_t *>(fam_));
}

void Detector::set_min_contrast(int grey) {
  static_cast<apriltag_detector_t *>(td_)->qtp.min_white_black_diff = std::clamp(grey, 0, 255);
}

int Detector::min_contrast() const {
  return static_cast<const apriltag_detector_t *>(td_)->qtp.min_white_black_diff;
}

double estimate_noise_sigma(const cv::Mat &gray, int row_step) {
  if (gray.type() != CV_8UC1 || gray.rows < 3 || gray.cols < 3) return 0;
  // |response| <= 16 * 255: a histogram gives the median in one pass, no sort.
  std::vector<uint32_t> hist(16 * 255 + 1, 0);
  uint64_t n = 0;
  for (int r = 1; r + 1 < gray.rows; r += std::max(1, row_step)) {
    const uint8_t *a = gray.ptr<uint8_t>(r - 1), *b = gray.ptr<uint8_t>(r),
                  *c = gray.ptr<uint8_t>(r + 1);
    for (int x = 1; x + 1 < gray.cols; ++x) {
      const int v = a[x - 1] - 2 * a[x] + a[x + 1] - 2 * (b[x - 1] - 2 * b[x] + b[x + 1]) +
                    c[x - 1] - 2 * c[x] + c[x + 1];
      ++hist[static_cast<size_t>(std::abs(v))];
      ++n;
    }
  }
  uint64_t seen = 0;
  size_t med = 0;
  while (med < hist.size() && 2 * (seen + hist[med]) < n) seen += hist[med++];
  return static_cast<double>(med) / (6.0 * 0.6745);
}

std::vector<Detection> Detector::detect(const cv::Mat &gray) {
  if (gray.empty() || gray.type() != CV_8UC1)
    throw Error("detector: frame must be a non-empty 8-bit grey image");
  image_u8_t im{gray.cols, gray.rows, static_cast<int32_t>(gray.step[0]),
                const_cast<uint8_t *>(gray.ptr<uint8_t>())};
  zarray_t *dets = apriltag_detector_detect(static_cast<apriltag_detector_t *>(td_), &im);
  std::vector<Detection> out;
  for (int i = 0; i < zarray_size(dets); ++i) {
    apriltag_detection_t *d;
    zarray_get(dets, i, &d);
    if (d->hamming > params_.max_hamming || d->decision_margin < params_.min_margin) continue;
    Detection o;
    o.id = d->id;
    o.hamming = d->hamming;
    o.margin = d->decision_margin;
    for (int j = 0; j < 4; ++j)
      o.corners_px[static_cast<size_t>(j)] =
          cv::Point2d(d->p[j][0] + kApriltagToOpencvPx, d->p[j][1] + kApriltagToOpencvPx);
    o.centre_px = cv::Point2d(d->c[0] + kApriltagToOpencvPx, d->c[1] + kApriltagToOpencvPx);
    out.push_back(o);
  }
  apriltag_detections_destroy(dets);
  return out;
}

std::vector<Detection> Detector::detect(const cv::Mat &gray, const cv::Rect &roi, float decimate) {
  const cv::Rect r = roi & cv::Rect(0, 0, gray.cols, gray.rows);
  // No tag fits in a sliver, and libapriltag 3.3 crashes (quad_thresh) on a few-pixel image.
  const int min_px = static_cast<int>(std::ceil(8 * std::max(1.0f, decimate)));
  if (r.width < min_px || r.height < min_px) return {};
  auto *td = static_cast<apriltag_detector_t *>(td_);
  td->quad_decimate = decimate;
  std::vector<Detection> out;
  try {
    out = detect(gray(r));
  } catch (...) {
    td->quad_decimate = params_.decimate;
    throw;
  }
  td->quad_decimate = params_.decimate;
  // Region pixel (c, r) is frame pixel (c + x, r + y): shifting the corners is exact.
  const cv::Point2d off(r.x, r.y);
  for (auto &d : out) {
    for (auto &p : d.corners_px) p += off;
    d.centre_px += off;
  }
  return out;
}

}  // namespace eye
