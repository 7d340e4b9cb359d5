#include "eye_tracker.hpp"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <condition_variable>
#include <cstdio>
#include <exception>
#include <functional>
#include <mutex>
#include <thread>

#include "eye_error.hpp"
#include "eye_rowdecode.hpp"

namespace eye {

static double side_px(const std::array<cv::Point2d, 4> &c) {
  double s = 1e9;
  for (size_t i = 0; i < 4; ++i) s = std::min(s, cv::norm(c[i] - c[(i + 1) % 4]));
  return s;
}

std::vector<Detection> merge_detections(const std::vector<Detection> &dets) {
  std::vector<Detection> out;
  for (const auto &d : dets) {
    auto same = std::find_if(out.begin(), out.end(), [&](const Detection &o) {
      return o.id == d.id &&
             cv::norm(o.centre_px - d.centre_px) < std::max(side_px(o.corners_px), 1.0);
    });
    if (same == out.end())
      out.push_back(d);
    else if (d.margin > same->margin)
      *same = d;
  }
  return out;
}

// One job at a time on a thread of its own, the thread living as long as the tracker. run()
// hands a job over; finish() runs it on the caller's thread if the worker has not picked it up
// yet (a loaded machine may not schedule the worker for several ms: the frame then costs what
// it costs on one thread, never more), else waits for it, and rethrows what it threw.
class DetectWorker {
 public:
  DetectWorker() : th_([this] { loop(); }) {}
  ~DetectWorker() {
    {
      std::lock_guard<std::mutex> l(m_);
      stop_ = true;
    }
    cv_.notify_all();
    th_.join();
  }
  void run(std::function<void()> job) {
    {
      std::lock_guard<std::mutex> l(m_);
      job_ = std::move(job);
      busy_ = true;
    }
    cv_.notify_all();
  }
  void finish() {
    std::unique_lock<std::mutex> l(m_);
    if (job_) {
      auto job = std::move(job_);
      job_ = nullptr;
      busy_ = false;
      l.unlock();
      job();
      return;
    }
    cv_.wait(l, [this] { return !busy_; });
    if (err_) std::rethrow_exception(std::exchange(err_, nullptr));
  }
  // Drops a job not yet started, waits for one running; no rethrow (for unwinding).
  void settle() noexcept {
    std::unique_lock<std::mutex> l(m_);
    if (job_) {
      job_ = nullptr;
      busy_ = false;
    }
    cv_.wait(l, [this] { return !busy_; });
    err_ = nullptr;
  }

 private:
  void loop() {
    std::unique_lock<std::mutex> l(m_);
    for (;;) {
      cv_.wait(l, [this] { return stop_ || job_; });
      if (stop_) return;
      auto job = std::move(job_);
      job_ = nullptr;
      l.unlock();
      try {
        job();
      } catch (...) {
        l.lock();
        err_ = std::current_exception();
        l.unlock();
      }
      l.lock();
      busy_ = false;
      cv_.notify_all();
    }
  }
  std::mutex m_;
  std::condition_variable cv_;
  std::function<void()> job_;  // handed over, not yet started
  std::exception_ptr err_;
  bool busy_ = false, stop_ = false;
  std::thread th_;
};

namespace {
// Settles the worker's job when a scope is left by an exception: the job reads the caller's
// frame and writes the caller's variables.
struct SettleOnExit {
  DetectWorker *w;
  ~SettleOnExit() {
    if (w) w->settle();
  }
};
}  // namespace

Tracker::~Tracker() {
  if (work_) work_->settle();  // its job reads pending_
}

Tracker::Tracker(const RunConfig &c) : cfg_(c), det_(c.detector) {
  if (c.detector.threads > 1) {
    det2_ = std::make_unique<Detector>(c.detector);
    work_ = std::make_unique<DetectWorker>();
  }
  for (const auto &v : c.vehicles) by_tag_[v.tag_id] = v;
  const double z_roof_m = c.locate.base_link_height_m + c.locate.tag_offset_m[2];
  if (c.whole_field.enabled) {
    plan_ = plan_full_scan(c.in, c.pose, z_roof_m, c.locate.tag_size_m, c.detector.decimate,
                           c.whole_field.plan);
  } else {
    plan_.regions = {{cv::Rect(0, 0, c.in.width_px, c.in.height_px), c.detector.decimate}};
    // Bands padded by the largest tag (as seen from the frame centre, x1.5 for the edges).
    plan_.max_tag_px = 1.5 * expected_tag_side_px(c.in, c.pose, z_roof_m, c.locate.tag_size_m,
                                                  {c.in.width_px / 2.0, c.in.height_px / 2.0})[1];
  }
}

void Tracker::hint(int tag_id, const std::array<cv::Point2d, 4> &corners_px) {
  if (by_tag_.count(tag_id) && !tracks_.count(tag_id)) hints_[tag_id] = corners_px;
}

std::vector<Detection> Tracker::scan_regions(Detector &det, const cv::Mat &gray,
                                             const std::vector<ScanRegion> &rs) {
  std::vector<Detection> dets;
  for (const auto &r : rs) {
    auto d = r.rect.area() == gray.cols * gray.rows && r.decimate == cfg_.detector.decimate
                 ? det.detect(gray)
                 : det.detect(gray, r.rect, r.decimate);
    dets.insert(dets.end(), d.begin(), d.end());
  }
  return rs.size() > 1 ? merge_detections(dets) : dets;
}

std::vector<Detection> Tracker::full_scan(const cv::Mat &gray) {
  if (!work_) return scan_regions(det_, gray, plan_.regions);
  // Two bands of the plan (the upper one extended by the tallest tag across their border).
  std::vector<Detection> upper;
  work_->run([&] { upper = scan_regions(*det2_, gray, plan_slice(plan_, 0, 2, gray.rows)); });
  std::vector<Detection> lower;
  {
    SettleOnExit settle{work_.get()};
    lower = scan_regions(det_, gray, plan_slice(plan_, 1, 2, gray.rows));
    settle.w = nullptr;
  }
  work_->finish();
  upper.insert(upper.end(), lower.begin(), lower.end());
  return merge_detections(upper);
}

cv::Rect Tracker::window_rect(const std::array<cv::Point2d, 4> &c, double margin) {
  double x0 = c[0].x, x1 = c[0].x, y0 = c[0].y, y1 = c[0].y;
  for (const auto &p : c) {
    x0 = std::min(x0, p.x);
    x1 = std::max(x1, p.x);
    y0 = std::min(y0, p.y);
    y1 = std::max(y1, p.y);
  }
  const double grow = margin * std::max(x1 - x0, y1 - y0);
  return cv::Rect(
      cv::Point(static_cast<int>(std::floor(x0 - grow)), static_cast<int>(std::floor(y0 - grow))),
      cv::Point(static_cast<int>(std::ceil(x1 + grow)) + 1,
                static_cast<int>(std::ceil(y1 + grow)) + 1));
}

std::vector<Detection> Tracker::scan_window(Detector &det, const cv::Mat &gray,
                                            const RowDecoder *rows, int id,
                                            const std::array<cv::Point2d, 4> &c, double margin) {
  const cv::Rect win = window_rect(c, margin);
  // The decode failed: the caller's finish() of the second thread rethrows its error.
  if (rows && !rows->wait_rows(win.br().y)) throw Error(rows->what() + ": the decode failed");
  // Windows are small: full resolution (measured: at 1.5 a 35 px tag near the image border was
  // lost from its window for 6 frames).
  const float dec = 1.0f;
  std::vector<Detection> out;
  for (const auto &d : det.detect(gray, win, dec))
    if (d.id == id) out.push_back(d);
  return out;
}

void Tracker::update_contrast(const cv::Mat &gray) {
  noise_sigma_ = estimate_noise_sigma(gray);
  const int contrast = std::max(cfg_.detector.min_contrast,
                                static_cast<int>(std::ceil(cfg_.detector.noise_k * noise_sigma_)));
  det_.set_min_contrast(contrast);
  if (det2_) det2_->set_min_contrast(contrast);
}

std::vector<CarPose> Tracker::process(const cv::Mat &gray) {
  auto out = track(gray);
  const auto late = finish();
  out.insert(out.end(), late.begin(), late.end());
  return out;
}

std::vector<CarPose> Tracker::track(const TrackInput &in) {
  if (pending_.active) finish();
  RowDecoder *const jpeg = in.jpeg.get();
  const cv::Mat &gray = jpeg ? jpeg->image() : in.gray;
  if (gray.cols != cfg_.in.width_px || gray.rows != cfg_.in.height_px)
    throw Error("frame: size " + std::to_string(gray.cols) + "x" + std::to_string(gray.rows) +
                " differs from the calibrated " + std::to_string(cfg_.in.width_px) + "x" +
                std::to_string(cfg_.in.height_px) + " of " + cfg_.intrinsics_path);
  const int n_bands = std::max(1, cfg_.tracking.full_every);
  last_full_ = !cfg_.tracking.roi || (tracks_.empty() && hints_.empty());
  // A JPEG is decoded on the second thread while the windows wait for their rows; without
  // windows or a second thread, whole, here.
  RowDecoder *const rows = jpeg && work_ && !last_full_ ? jpeg : nullptr;
  if (jpeg && !rows) jpeg->decode();
  const long frame = frame_++;
  // The camera's noise changes slowly (gain, light): measured once per staggered cycle, in
  // finish() (off the poses' path) except for the first frame, which needs it now.
  if (frame == 0 && cfg_.detector.noise_k > 0) update_contrast(gray);
  Pending &p = pending_;
  p = Pending();
  p.gray = gray;
  p.decoder = in.jpeg;
  std::vector<Detection> dets;
  if (!last_full_) {
    // The staggered periodic scan: band (frame mod n) of the full-scan plan, in finish().
    p.band = plan_slice(plan_, static_cast<int>(frame % n_bands), n_bands, gray.rows);
    // Where each tag should be now (last corners moved by the last frame's motion), searched
    // in the order of the windows' lowest rows: the caller's thread takes them from the top,
    // each once the rows under it are decoded; the second thread decodes, then takes them from
    // the bottom.
    std::vector<std::pair<int, std::array<cv::Point2d, 4>>> preds;
    for (const auto &[id, t] : tracks_) {
      std::array<cv::Point2d, 4> pred = t.corners;
      for (auto &q : pred) q += t.velocity_px;
      preds.emplace_back(id, pred);
    }
    const double margin = cfg_.tracking.margin;
    std::sort(preds.begin(), preds.end(), [&](const auto &a, const auto &b) {
      return window_rect(a.second, margin).br().y < window_rect(b.second, margin).br().y;
    });
    std::vector<std::vector<Detection>> found(preds.size());
    std::mutex take_m;
    size_t top = 0, bottom = preds.size();
    std::atomic<bool> lost{false};
    // Searches windows until none is left or one is lost; from_top: the caller's thread.
    const auto search = [&](Detector &det, bool from_top) {
      for (;;) {
        size_t k = 0;
        {
          std::lock_guard<std::mutex> l(take_m);
          if (top >= bottom || lost) return;
          k = from_top ? top++ : --bottom;
        }
        const auto &[id, pred] = preds[k];
        found[k] = scan_window(det, gray, from_top ? rows : nullptr, id, pred, margin);
        // Missing from its window (a sharp turn, a jolt, occlusion): a window 3x as large,
        // then the whole frame at once; windows only ever save time, never detections.
        if (found[k].empty())
          found[k] =
              scan_window(det, gray, from_top ? rows : nullptr, id, pred, 3.0 * margin + 1.0);
        if (found[k].empty()) lost = true;
      }
    };
    SettleOnExit settle{work_.get()};
    if (work_)
      work_->run([this, &search] {
        if (pending_.decoder) pending_.decoder->decode();  // no-op when decoded already
        search(*det2_, false);
      });
    try {
      search(det_, true);
    } catch (const Error &) {
      if (work_) work_->finish();  // the decoder's own error, which says what is wrong
      throw;
    }
    if (work_) work_->finish();  // its windows (and the decode's error, if any)
    settle.w = nullptr;
    last_full_ = lost;
    for (const auto &f : found) dets.insert(dets.end(), f.begin(), f.end());
    if (!last_full_)
      for (const auto &[id, c] : hints_) {
        const auto f = scan_window(det_, gray, nullptr, id, c, margin);
        dets.insert(dets.end(), f.begin(), f.end());
      }
    // The band looks for cars not tracked yet: finish() scans it once the tracked cars' poses
    // are out (a whole-frame scan covers it). Not on the second thread meanwhile: whoever
    // receives the poses on this machine needs a core then.
    if (last_full_) p.band.clear();
  }
  hints_.clear();
  dets = last_full_ ? full_scan(gray) : merge_detections(dets);
  p.tracked = dets;
  p.active = true;
  std::vector<CarPose> out;
  std::map<int, int> count;
  std::map<int, Track> tracks;
  for (const auto &d : dets) count[d.id]++;
  for (const auto &d : dets) {
    auto it = by_tag_.find(d.id);
    // A tag seen twice in one frame is ambiguous (a copy, a reflection): publish neither.
    if (it == by_tag_.end() || count[d.id] > 1) continue;
    if (auto pose = locate_car(cfg_.in, cfg_.pose, cfg_.locate, it->second, d)) {
      out.push_back(*pose);
      Track t{d.corners_px, {0, 0}};
      auto old = tracks_.find(d.id);
      if (old != tracks_.end()) {
        cv::Point2d c0(0, 0), c1(0, 0);
        for (size_t i = 0; i < 4; ++i) {
          c0 += 0.25 * old->second.corners[i];
          c1 += 0.25 * d.corners_px[i];
        }
        t.velocity_px = c1 - c0;
      }
      tracks[d.id] = t;
    }
  }
  tracks_ = std::move(tracks);
  return out;
}

std::vector<CarPose> Tracker::finish() {
  Pending &p = pending_;
  if (!p.active) return {};
  p.active = false;
  if (!p.band.empty()) p.found = scan_regions(det_, p.gray, p.band);
  std::vector<Detection> all = p.tracked;
  all.insert(all.end(), p.found.begin(), p.found.end());
  last_dets_ = p.found.empty() ? std::move(all) : merge_detections(all);
  std::map<int, int> count;
  for (const auto &d : last_dets_) count[d.id]++;
  std::vector<CarPose> out;
  for (const auto &d : last_dets_) {
    auto it = by_tag_.find(d.id);
    if (it == by_tag_.end()) continue;
    if (count[d.id] > 1) {
      tracks_.erase(d.id);  // a copy elsewhere: ambiguous from the next frame on
      continue;
    }
    if (tracks_.count(d.id)) continue;  // posed by track()
    if (auto pose = locate_car(cfg_.in, cfg_.pose, cfg_.locate, it->second, d)) {
      out.push_back(*pose);
      tracks_[d.id] = Track{d.corners_px, {0, 0}};
      hints_.erase(d.id);  // tracked now: its window finds it
    }
  }
  const long frame = frame_ - 1;
  if (frame > 0 && frame % std::max(1, cfg_.tracking.full_every) == 0 && cfg_.detector.noise_k > 0)
    update_contrast(p.gray);
  last_gray_ = p.gray;
  p.gray.release();
  p.decoder.reset();
  return out;
}

cv::Mat Tracker::annotate(const cv::Mat &gray, const std::vector<CarPose> &poses) const {
  cv::Mat bgr;
  cv::cvtColor(gray, bgr, cv::COLOR_GRAY2BGR);
  for (const auto &p : poses) {
    for (size_t i = 0; i < 4; ++i)
      cv::line(bgr, p.corners_px[i], p.corners_px[(i + 1) % 4], cv::Scalar(0, 255, 0), 2,
               cv::LINE_AA);
    // top edge of the print (tag x axis) in red
    cv::line(bgr, p.corners_px[2], p.corners_px[3], cv::Scalar(0, 0, 255), 2, cv::LINE_AA);
    char b[128];
    std::snprintf(b, sizeof b, "%s x=%.3f y=%.3f yaw=%.1fdeg", p.vehicle.c_str(), p.x_m, p.y_m,
                  p.yaw_rad * 180.0 / M_PI);
    cv::putText(bgr, b, p.corners_px[3] + cv::Point2d(0, -8), cv::FONT_HERSHEY_SIMPLEX, 0.5,
                cv::Scalar(0, 255, 255), 1, cv::LINE_AA);
  }
  return bgr;
}

}  // namespace eye
