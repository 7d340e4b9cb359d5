// eye_bench: the Eye's whole pipeline (JPEG decode, detection, pose, LCM publish) on one
// thread over a synthesised trajectory that drives a car across the whole map, against the
// truth; and OpenCV's aruco (DICT_APRILTAG_36h11) as the peer on the same frames.
// Progress on stderr; the figures as "key value" lines on stdout; a CSV of the trajectory.
#include <CLI/CLI.hpp>
#include <autodrive/angles.hpp>
#include <autodrive_channels.h>
#include <opencv2/aruco.hpp>
#include <opencv2/calib3d.hpp>
#include <opencv2/core/utility.hpp>
#include <opencv2/imgcodecs.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <memory>
#include <optional>

#include "eye_detect.hpp"
#include "eye_intrinsics.hpp"
#include "eye_health.hpp"
#include "eye_render.hpp"
#include "eye_mapcal.hpp"
#include "eye_publish.hpp"
#include "eye_source.hpp"
#include "eye_synth.hpp"
#include "eye_tracker.hpp"

namespace {

using clock_type = std::chrono::steady_clock;

struct Truth {
  eye::SynthCar car;
};

// A Lissajous drive over the map (0.25 m from the edges), heading along the motion.
std::vector<eye::SynthCar> trajectory(const eye::SynthScene &s, int n) {
  std::vector<eye::SynthCar> out;
  const double ax = s.map_x_m / 2 - 0.25, ay = s.map_y_m / 2 - 0.25;
  for (int i = 0; i < n; ++i) {
    const double t = 2 * M_PI * i / n;
    const double x = s.map_x_m / 2 + ax * std::sin(t),
                 y = s.map_y_m / 2 + ay * std::sin(2 * t + 0.6);
    const double dx = ax * std::cos(t), dy = 2 * ay * std::cos(2 * t + 0.6);
    out.push_back({1, x, y, std::atan2(dy, dx)});
  }
  return out;
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

double thread_cpu_s() {
  timespec t;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

struct RunResult {
  std::vector<double> pass_fps;                  // frames / wall time, per pass
  std::vector<double> pass_fps_cpu;              // frames / thread CPU time, per pass
  std::vector<std::optional<eye::CarPose>> est;  // per frame (first pass)
  double fps() const { return median(pass_fps); }
  double fps_cpu() const { return median(pass_fps_cpu); }
};

struct Scene {
  eye::SynthScene s;
  eye::RunConfig cfg;
  std::vector<eye::SynthCar> path;
  std::vector<std::vector<uchar>> jpeg;
};

Scene make_scene(int w, int h, int frames, double tag_size_m,
                 const std::vector<eye::RefTag> *refs_in) {
  Scene sc;
  sc.s = eye::synth_scene(w, h, tag_size_m);
  sc.s.blur_sigma_px = 0.6;
  sc.s.noise_sigma = 2.0;
  const auto refs = refs_in ? *refs_in : eye::synth_reference_tags(sc.s);
  // Calibrate the map from the reference tags, as a user would (not the true pose).
  eye::DetectorParams dp;
  dp.decimate = 1;
  eye::Detector det(dp);
  const eye::MapCalib m =
      eye::map_calibrate(sc.s.in, refs, {det.detect(eye::synth_frame(sc.s, {}, refs, 1))});
  std::fprintf(stderr, "[eye_bench] %dx%d: map calibration residual %.3f mm rms\n", w, h, m.rms_mm);
  sc.cfg.in = sc.s.in;
  sc.cfg.pose = m.pose;
  sc.cfg.locate = sc.s.car;
  sc.cfg.vehicles = {{AUTODRIVE_VEHICLE_DEFAULT, 1, 0.0}};
  sc.path = trajectory(sc.s, frames);
  for (int i = 0; i < frames; ++i) {
    std::vector<uchar> buf;
    // The reference tags stay on the floor while cars drive: the detector sees them too.
    cv::imencode(
        ".jpg",
        eye::synth_frame(sc.s, {sc.path[static_cast<size_t>(i)]}, refs, static_cast<uint64_t>(i)),
        buf, {cv::IMWRITE_JPEG_QUALITY, 90});
    sc.jpeg.push_back(std::move(buf));
  }
  return sc;
}

// The Eye's signer (the testbed's EYE certificate, tools/setup): the bench times signed poses,
// as autodrive-eye publishes them. Exits when it cannot sign.
autodrive::v2x::Signer &eye_signer() {
  static std::optional<autodrive::v2x::Signer> signer =
      autodrive::v2x::Signer::load("eye_bench", "EYE");
  if (!signer) std::exit(2);
  return *signer;
}

// Times `repeats` passes over the scene's frames: decode, detect (start_pass() gives a fresh
// detector for each pass, a function of the grey frame to its car poses), publish.
template <typename StartPass>
RunResult time_passes(const Scene &sc, lcm::LCM &lcm, int repeats, StartPass start_pass) {
  RunResult r;
  for (int rep = 0; rep < repeats; ++rep) {
    auto detect = start_pass();
    const auto t0 = clock_type::now();
    const double c0 = thread_cpu_s();
    for (size_t i = 0; i < sc.jpeg.size(); ++i) {
      const cv::Mat g = eye::decode_gray(sc.jpeg[i].data(), sc.jpeg[i].size(), "bench frame");
      const std::vector<eye::CarPose> poses = detect(g);
      eye::publish_poses(lcm, eye_signer(), poses, static_cast<int64_t>(i) * 33333);
      if (rep == 0)
        r.est.push_back(poses.empty() ? std::nullopt : std::optional<eye::CarPose>(poses[0]));
    }
    const double n = static_cast<double>(sc.jpeg.size());
    r.pass_fps.push_back(n / std::chrono::duration<double>(clock_type::now() - t0).count());
    r.pass_fps_cpu.push_back(n / (thread_cpu_s() - c0));
  }
  return r;
}

// The Eye: decode, detect, locate, publish.
RunResult run_eye(const Scene &sc, lcm::LCM &lcm, int repeats, bool roi) {
  eye::RunConfig cfg = sc.cfg;
  cfg.tracking.roi = roi;
  return time_passes(sc, lcm, repeats, [&cfg] {
    auto tr = std::make_shared<eye::Tracker>(cfg);  // fresh: every pass starts with a full scan
    return [tr](const cv::Mat &g) { return tr->process(g); };
  });
}

// The peer: the same pipeline with OpenCV aruco's detector in place of libapriltag.
RunResult run_peer(const Scene &sc, lcm::LCM &lcm, int repeats) {
  auto dict = cv::aruco::getPredefinedDictionary(cv::aruco::DICT_APRILTAG_36h11);
  auto params = cv::aruco::DetectorParameters::create();
  params->cornerRefinementMethod = cv::aruco::CORNER_REFINE_SUBPIX;
  const auto detect = [&](const cv::Mat &g) {
    std::vector<int> ids;
    std::vector<std::vector<cv::Point2f>> corners;
    cv::aruco::detectMarkers(g, dict, corners, ids, params);
    std::vector<eye::CarPose> poses;
    for (size_t k = 0; k < ids.size(); ++k) {
      if (ids[k] != 1) continue;
      // aruco's bitmap is AprilTag's turned 180 deg; its corners (TL, TR, BR, BL of its
      // bitmap) are our BR, BL, TL, TR: reorder to libapriltag's BL, BR, TR, TL.
      eye::Detection d;
      d.id = ids[k];
      const auto &c = corners[k];
      // No half-pixel shift: with CORNER_REFINE_SUBPIX the marker corners follow OpenCV's
      // convention (shifting them by -0.5 px measured worse: 2.9 vs 2.0 mm RMS).
      d.corners_px = {cv::Point2d(c[1]), cv::Point2d(c[0]), cv::Point2d(c[3]), cv::Point2d(c[2])};
      if (auto p = eye::locate_car(sc.cfg.in, sc.cfg.pose, sc.cfg.locate, sc.cfg.vehicles[0], d))
        poses.push_back(*p);
    }
    return poses;
  };
  return time_passes(sc, lcm, repeats, [&detect] { return detect; });
}

struct Accuracy {
  double pos_rms_mm = 0, heading_rms_deg = 0, detect_rate = 0, pos_median_mm = 0, pos_max_mm = 0;
  int misses = 0;
};

// Sums an estimate's errors against the truth; finish() turns them into an Accuracy's figures.
struct ErrorSum {
  std::vector<double> pos_mm;
  double ss_pos = 0, ss_heading = 0;
  void add(double x_m, double y_m, double yaw_rad, double true_x_m, double true_y_m,
           double true_yaw_rad) {
    const double ep = 1000 * std::hypot(x_m - true_x_m, y_m - true_y_m);
    const double eh = autodrive::angle_wrap_rad(yaw_rad - true_yaw_rad) * 180 / M_PI;
    ss_pos += ep * ep;
    ss_heading += eh * eh;
    pos_mm.push_back(ep);
  }
  // total: the poses that should have been detected.
  void finish(Accuracy &a, double total) const {
    const double n = static_cast<double>(pos_mm.size());
    a.detect_rate = n / total;
    if (n > 0) {
      a.pos_rms_mm = std::sqrt(ss_pos / n);
      a.heading_rms_deg = std::sqrt(ss_heading / n);
      a.pos_median_mm = median(pos_mm);
      a.pos_max_mm = *std::max_element(pos_mm.begin(), pos_mm.end());
    }
  }
};

// Pixel of a car's roof tag centre.
cv::Point2d eye_tag_centre_px(const eye::SynthScene &s, const eye::SynthCar &car) {
  const double c = std::cos(car.yaw_rad), sn = std::sin(car.yaw_rad);
  const double ox = s.car.tag_offset_m[0], oy = s.car.tag_offset_m[1];
  return eye::camera_project(s.in, s.pose,
                             {car.x_m + c * ox - sn * oy, car.y_m + sn * ox + c * oy,
                              s.car.base_link_height_m + s.car.tag_offset_m[2]});
}

Accuracy accuracy(const Scene &sc, const RunResult &r) {
  Accuracy a;
  ErrorSum e;
  for (size_t i = 0; i < sc.path.size(); ++i) {
    if (!r.est[i]) continue;
    const auto &t = sc.path[i];
    e.add(r.est[i]->x_m, r.est[i]->y_m, r.est[i]->yaw_rad, t.x_m, t.y_m, t.yaw_rad);
  }
  e.finish(a, static_cast<double>(sc.path.size()));
  return a;
}

// The run config of a synthetic scene (camera.yaml and map.yaml beside it), its cars' tags.
bool write_run_config(const std::string &path, const eye::LocateParams &car, const std::string &url,
                      const std::vector<eye::VehicleTag> &vehicles, bool reference_tags,
                      int threads = eye::DetectorParams{}.threads) {
  std::ofstream cfg(path);
  if (threads != eye::DetectorParams{}.threads) cfg << "detector: {threads: " << threads << "}\n";
  cfg << "intrinsics: camera.yaml\nmap: map.yaml\nlcm_url: \"" << url << "\"\n"
      << "tag_size_m: " << car.tag_size_m << "\ntag_offset_m: [" << car.tag_offset_m[0] << ", "
      << car.tag_offset_m[1] << ", " << car.tag_offset_m[2] << "]\n"
      << "base_link_height_m: " << car.base_link_height_m << "\n"
      << (reference_tags ? "reference_tags: reference_tags.yaml\n" : "") << "vehicles:\n";
  for (const auto &v : vehicles) cfg << " - {name: " << v.name << ", tag_id: " << v.tag_id << "}\n";
  return static_cast<bool>(cfg);
}

bool write_jpeg(const std::string &path, const std::vector<uchar> &jpg) {
  std::ofstream f(path, std::ios::binary);
  f.write(reinterpret_cast<const char *>(jpg.data()), static_cast<std::streamsize>(jpg.size()));
  return static_cast<bool>(f);
}

// A fixed scene for programs that feed the Eye over LCM: its calibration, a run config and
// one good frame. Returns the exit status.
int write_scene(const std::string &dir, const std::string &url, double tag_size_m) {
  const eye::SynthScene s = eye::synth_scene(640, 480, tag_size_m);
  eye::intrinsics_save(dir + "/camera.yaml", s.in);
  eye::MapCalib m;
  m.pose = s.pose;
  m.width_px = 640;
  m.height_px = 480;
  eye::mapcal_save(dir + "/map.yaml", m);
  std::vector<uchar> jpg;
  cv::imencode(".jpg", eye::synth_frame(s, {{1, 1.2, 0.9, 0.5}}, {}, 1), jpg,
               {cv::IMWRITE_JPEG_QUALITY, 95});
  if (!write_run_config(dir + "/eye.yaml", s.car, url, {{"NIGEL1", 1, 0.0}}, false) ||
      !write_jpeg(dir + "/frame.jpg", jpg)) {
    std::fprintf(stderr, "eye_bench: cannot write the scene to %s\n", dir.c_str());
    return 1;
  }
  return 0;
}

// ---- Wide-angle lens, 10 cars, whole field of view ----------------------------------------

struct WideScene {
  eye::SynthScene s;
  eye::RunConfig cfg;
  std::vector<eye::RefTag> refs;
  std::vector<std::vector<eye::SynthCar>> cars;  // per frame
  std::vector<std::vector<uchar>> jpeg;
  double tag_px_min = 1e9, tag_px_max = 0;
};

double g_wide_margin = eye::TrackingParams{}.margin;
float g_wide_sigma = eye::DetectorParams{}.sigma_px;
double g_wide_noise_k = eye::DetectorParams{}.noise_k;
int g_wide_threads = eye::DetectorParams{}.threads;

WideScene make_wide_scene(int w, int h, int frames) {
  WideScene sc;
  sc.s = eye::synth_scene_wide(w, h);
  sc.refs = eye::synth_reference_tags_in_view(sc.s);
  eye::DetectorParams dp;
  dp.decimate = 1;
  eye::Detector det(dp);
  const eye::MapCalib m =
      eye::map_calibrate(sc.s.in, sc.refs, {det.detect(eye::synth_frame(sc.s, {}, sc.refs, 7))});
  std::fprintf(stderr, "[eye_bench] wide %dx%d: map calibration residual %.3f mm rms, %zu tags\n",
               w, h, m.rms_mm, m.tags.size());
  sc.cfg.in = sc.s.in;
  sc.cfg.pose = m.pose;
  sc.cfg.locate = sc.s.car;
  sc.cfg.tracking.margin = g_wide_margin;
  sc.cfg.detector.sigma_px = g_wide_sigma;
  sc.cfg.detector.noise_k = g_wide_noise_k;
  sc.cfg.detector.threads = g_wide_threads;
  for (int k = 1; k <= 10; ++k)
    sc.cfg.vehicles.push_back({AUTODRIVE_VEHICLE_PREFIX + std::to_string(k), k, 0.0});
  sc.cars = eye::synth_wide_drive(sc.s, frames);
  for (int i = 0; i < frames; ++i) {
    for (const auto &c : sc.cars[static_cast<size_t>(i)]) {
      const double side = eye::synth_tag_side_px(sc.s, c);
      sc.tag_px_min = std::min(sc.tag_px_min, side);
      sc.tag_px_max = std::max(sc.tag_px_max, side);
    }
    std::vector<uchar> buf;
    cv::imencode(".jpg",
                 eye::synth_frame(sc.s, sc.cars[static_cast<size_t>(i)], sc.refs,
                                  static_cast<uint64_t>(1000 + i)),
                 buf, {cv::IMWRITE_JPEG_QUALITY, 90});
    sc.jpeg.push_back(std::move(buf));
  }
  return sc;
}

// The wide-angle scene for programs that feed the Eye frames at a fixed rate: camera.yaml,
// map.yaml (calibrated from the reference tags), reference_tags.yaml, eye.yaml (10 cars, url)
// and the frames as frames/NNNN.jpg. Returns the exit status.
int write_wide_scene(const WideScene &sc, const std::string &dir, const std::string &url) {
  std::filesystem::create_directories(dir + "/frames");
  eye::intrinsics_save(dir + "/camera.yaml", sc.s.in);
  eye::MapCalib m;
  m.pose = sc.cfg.pose;
  m.width_px = sc.s.in.width_px;
  m.height_px = sc.s.in.height_px;
  eye::mapcal_save(dir + "/map.yaml", m);
  std::ofstream refs(dir + "/reference_tags.yaml");
  refs << "tags:\n";
  for (const auto &r : sc.refs)
    refs << " - {id: " << r.id << ", x_m: " << r.x_m << ", y_m: " << r.y_m << ", z_m: " << r.z_m
         << ", yaw_rad: " << r.yaw_rad << ", size_m: " << r.size_m << "}\n";
  bool ok =
      static_cast<bool>(refs) && write_run_config(dir + "/eye.yaml", sc.cfg.locate, url,
                                                  sc.cfg.vehicles, true, sc.cfg.detector.threads);
  for (size_t i = 0; ok && i < sc.jpeg.size(); ++i) {
    char name[48];
    std::snprintf(name, sizeof name, "/frames/%04zu.jpg", i);
    ok = write_jpeg(dir + name, sc.jpeg[i]);
  }
  if (!ok) {
    std::fprintf(stderr, "eye_bench: cannot write the wide scene to %s\n", dir.c_str());
    return 1;
  }
  return 0;
}

struct WideResult {
  std::vector<double> pass_fps, pass_fps_cpu, latency_ms;
  std::vector<double> frame_cpu_ms;  // thread CPU per frame, decode to publish, every pass
  std::vector<std::vector<eye::CarPose>> est;  // per frame, first pass
  int full_scans = 0;                          // first pass
  double fps() const { return median(pass_fps); }
  double fps_cpu() const { return median(pass_fps_cpu); }
};

WideResult run_wide(const WideScene &sc, lcm::LCM &lcm, int repeats, const eye::RunConfig &cfg) {
  WideResult r;
  for (int rep = 0; rep < repeats; ++rep) {
    eye::Tracker tr(cfg);
    const auto t0 = clock_type::now();
    const double c0 = thread_cpu_s();
    for (size_t i = 0; i < sc.jpeg.size(); ++i) {
      const auto f0 = clock_type::now();
      const double fc0 = thread_cpu_s();
      const cv::Mat g = eye::decode_gray(sc.jpeg[i].data(), sc.jpeg[i].size(), "bench frame");
      // As autodrive-eye: the tracked cars' poses out, then the band.
      auto poses = tr.track(g);
      eye::publish_poses(lcm, eye_signer(), poses, static_cast<int64_t>(i) * 33333);
      r.latency_ms.push_back(
          std::chrono::duration<double, std::milli>(clock_type::now() - f0).count());
      const auto late = tr.finish();
      eye::publish_poses(lcm, eye_signer(), late, static_cast<int64_t>(i) * 33333);
      poses.insert(poses.end(), late.begin(), late.end());
      r.frame_cpu_ms.push_back(1e3 * (thread_cpu_s() - fc0));
      if (rep == 0) {
        r.est.push_back(poses);
        r.full_scans += tr.last_was_full_scan();
      }
    }
    const double n = static_cast<double>(sc.jpeg.size());
    r.pass_fps.push_back(n / std::chrono::duration<double>(clock_type::now() - t0).count());
    r.pass_fps_cpu.push_back(n / (thread_cpu_s() - c0));
  }
  return r;
}

Accuracy wide_accuracy(const WideScene &sc, const WideResult &r) {
  Accuracy a;
  ErrorSum e;
  double total = 0;
  for (size_t i = 0; i < sc.cars.size(); ++i)
    for (const auto &t : sc.cars[i]) {
      total += 1;
      if (std::none_of(r.est[i].begin(), r.est[i].end(),
                       [&t](const eye::CarPose &p) { return p.tag_id == t.tag_id; }) &&
          ++a.misses <= 12) {
        const auto c = eye_tag_centre_px(sc.s, t);
        std::fprintf(stderr,
                     "[eye_bench]   missed car %d in frame %zu: tag %.1f px at (%.0f, %.0f)\n",
                     t.tag_id, i, eye::synth_tag_side_px(sc.s, t), c.x, c.y);
      }
      for (const auto &p : r.est[i]) {
        if (p.tag_id != t.tag_id) continue;
        e.add(p.x_m, p.y_m, p.yaw_rad, t.x_m, t.y_m, t.yaw_rad);
      }
    }
  e.finish(a, total);
  return a;
}

double percentile(std::vector<double> v, double q) {
  std::sort(v.begin(), v.end());
  if (v.empty()) return 0;
  return v[std::min(v.size() - 1, static_cast<size_t>(q * static_cast<double>(v.size())))];
}

// A bumped camera: the wide camera moves by 5 mm and 0.3 deg after its calibration; frames
// until the Eye marks it moved (0: at once; -1: never in `frames`), and whether the unmoved
// camera stayed unmarked over the same frames.
std::pair<int, bool> bumped_camera(const WideScene &sc, int frames) {
  eye::HealthParams hp;
  eye::CameraHealth still("wide", sc.cfg.in, sc.cfg.pose, sc.refs, hp);
  eye::CameraHealth bumped("wide", sc.cfg.in, sc.cfg.pose, sc.refs, hp);
  eye::SynthScene moved = sc.s;
  cv::Matx33d rot;
  cv::Rodrigues(cv::Vec3d(0.6, 0.8, 0.0) * (0.3 * M_PI / 180), rot);
  moved.pose.r_cam_map = rot * moved.pose.r_cam_map;
  moved.pose.t_cam_map = rot * moved.pose.t_cam_map + cv::Vec3d(0.003, -0.004, 0.0);
  eye::Tracker ts(sc.cfg), tb(sc.cfg);
  int found = -1;
  for (int i = 0; i < frames; ++i) {
    const auto &cars = sc.cars[static_cast<size_t>(i)];
    auto ps = ts.process(eye::synth_frame(sc.s, cars, sc.refs, static_cast<uint64_t>(5000 + i)));
    still.observe(i * 33333, ts.last_detections(), &ps);
    auto pb = tb.process(eye::synth_frame(moved, cars, sc.refs, static_cast<uint64_t>(5000 + i)));
    if (bumped.observe(i * 33333, tb.last_detections(), &pb) && found < 0) found = i;
  }
  std::fprintf(stderr, "[eye_bench] bumped camera: ref residual %.2f mm (still %.2f mm)\n",
               bumped.status().ref_rms_mm, still.status().ref_rms_mm);
  return {found, !still.status().moved};
}

}  // namespace

int main(int argc, char **argv) {
  CLI::App app{"eye_bench: Eye pipeline speed and accuracy on a synthesised drive across the map"};
  int frames = 240, repeats = 3;
  double tag_size_m = 0.10;
  std::string csv, url = "udpm://239.255.76.67:7799?ttl=0";
  app.add_option("--frames", frames, "frames in the trajectory")->capture_default_str();
  app.add_option("--repeats", repeats, "timing passes over the frames (median per frame)")
      ->capture_default_str();
  app.add_option("--tag-size-m", tag_size_m, "roof tag black border [m]")->capture_default_str();
  app.add_option("--csv", csv, "write truth vs estimate per frame (720p) here");
  app.add_option("--lcm-url", url, "where poses are published")->capture_default_str();
  std::string scene_dir;
  app.add_option("--write-scene", scene_dir,
                 "only write a 640x480 scene to this folder (camera.yaml, map.yaml, eye.yaml "
                 "with --lcm-url, frame.jpg with NIGEL1 at x 1.2 m, y 0.9 m, yaw 0.5 rad) and "
                 "exit: the frames of tools/bench security");
  std::string wide_scene_dir;
  app.add_option("--write-wide-scene", wide_scene_dir,
                 "only render the wide-angle scene (1280x720, 10 cars, --frames frames) and write "
                 "it to this folder (camera.yaml, map.yaml, reference_tags.yaml, eye.yaml with "
                 "--lcm-url, frames/NNNN.jpg) and exit: the frames of the latency benchmark");
  bool wide_only = false;
  app.add_flag("--wide-only", wide_only,
               "only the wide-angle scene (10 cars) and the bumped camera");
  app.add_option("--wide-margin", g_wide_margin, "wide scene: tracking window margin [tag sizes]")
      ->capture_default_str();
  app.add_option("--wide-sigma-px", g_wide_sigma, "wide scene: detector quad_sigma [px]")
      ->capture_default_str();
  app.add_option("--wide-noise-k", g_wide_noise_k,
                 "wide scene: detector contrast / noise sigma (0: libapriltag's 5 grey levels)")
      ->capture_default_str();
  app.add_option("--wide-threads", g_wide_threads,
                 "wide scene: detector threads (the written scene's eye.yaml too; the timed "
                 "passes run on one thread unless --profile-wide)")
      ->check(CLI::Range(1, 2))
      ->capture_default_str();
  bool profile_wide = false;
  app.add_flag("--profile-wide", profile_wide,
               "only render the wide-angle scene and time the Eye on it (for perf / callgrind)");
  CLI11_PARSE(app, argc, argv);
  if (!scene_dir.empty()) return write_scene(scene_dir, url, tag_size_m);
  cv::setNumThreads(1);  // one thread: aruco and imdecode would otherwise use a pool

  lcm::LCM lcm(url);
  if (!lcm.good()) {
    std::fprintf(stderr, "eye_bench: cannot open LCM %s\n", url.c_str());
    return 1;
  }
  // Wide-angle lens, 10 cars: the Eye (whole-field detection), the previous default (decimate
  // 2 full scans) and decimate 1 everywhere, same frames, same tracking, same run.
  std::fprintf(stderr, "[eye_bench] wide-angle scene: rendering %d frames, 10 cars\n", frames);
  const WideScene wide = make_wide_scene(1280, 720, frames);
  if (!wide_scene_dir.empty()) return write_wide_scene(wide, wide_scene_dir, url);
  std::fprintf(stderr, "[eye_bench] wide: tags %.1f-%.1f px a side; plan:", wide.tag_px_min,
               wide.tag_px_max);
  const eye::Tracker planned(wide.cfg);
  for (const auto &r : planned.scan_plan().regions)
    std::fprintf(stderr, " [%d,%d %dx%d @%.1f]", r.rect.x, r.rect.y, r.rect.width, r.rect.height,
                 static_cast<double>(r.decimate));
  std::fprintf(stderr, "; staggered bands [rows]:");
  const int n_bands = wide.cfg.tracking.full_every;
  for (int k = 0; k < n_bands; ++k) {
    int rows = 0;
    for (const auto &r : eye::plan_slice(planned.scan_plan(), k, n_bands, wide.s.in.height_px))
      rows = std::max(rows, r.rect.height);
    std::fprintf(stderr, " %d", rows);
  }
  std::fprintf(stderr, "\n");
  if (profile_wide) {
    const WideResult r = run_wide(wide, lcm, repeats, wide.cfg);
    const Accuracy a = wide_accuracy(wide, r);
    std::printf(
        "detect_rate_wide_angle %.4f\npos_rms_mm_wide_angle %.4f\n"
        "heading_rms_deg_wide_angle %.4f\nfps_1280x720_1t_wide_angle %.2f\n"
        "fps_1280x720_1t_wide_angle_cpu %.2f\n",
        a.detect_rate, a.pos_rms_mm, a.heading_rms_deg, r.fps(), r.fps_cpu());
    // With --wide-threads 2 the CPU figures hold the calling thread only.
    std::printf("detector_threads %d\n", wide.cfg.detector.threads);
    std::printf(
        "frame_cpu_ms_p50_wide_angle %.3f\nframe_cpu_ms_p99_wide_angle %.3f\n"
        "frame_cpu_ms_max_wide_angle %.3f\nfull_scans_wide_angle %d\n",
        percentile(r.frame_cpu_ms, 0.5), percentile(r.frame_cpu_ms, 0.99),
        percentile(r.frame_cpu_ms, 1.0), r.full_scans);
    return 0;
  }
  // The fps_*_1t figures: one thread, whatever --wide-threads wrote into the scene.
  eye::RunConfig cfg_eye = wide.cfg;
  cfg_eye.detector.threads = 1;
  eye::RunConfig cfg_prev = cfg_eye, cfg_d1 = cfg_eye;
  cfg_prev.whole_field.enabled = false;
  cfg_d1.whole_field.enabled = false;
  cfg_d1.detector.decimate = 1;
  std::fprintf(stderr, "[eye_bench] wide: Eye (whole field), %d passes\n", repeats);
  const WideResult w_eye = run_wide(wide, lcm, repeats, cfg_eye);
  std::fprintf(stderr, "[eye_bench] wide: previous default (decimate 2 full scans)\n");
  const WideResult w_prev = run_wide(wide, lcm, repeats, cfg_prev);
  std::fprintf(stderr, "[eye_bench] wide: decimate 1 everywhere\n");
  const WideResult w_d1 = run_wide(wide, lcm, repeats, cfg_d1);
  // The detector alone (every frame scanned whole, no windows to carry a car through): what
  // the whole-field plan finds that the previous default's decimate-2 scan misses.
  eye::RunConfig cfg_full = cfg_eye, cfg_prev_full = cfg_prev;
  cfg_full.tracking.roi = false;
  cfg_prev_full.tracking.roi = false;
  std::fprintf(stderr, "[eye_bench] wide: whole-frame scans every frame (Eye, previous)\n");
  const WideResult wf_eye = run_wide(wide, lcm, 1, cfg_full);
  const WideResult wf_prev = run_wide(wide, lcm, 1, cfg_prev_full);
  std::fprintf(stderr, "[eye_bench] wide: full scans %d (Eye), %d (previous), %d (decimate 1)\n",
               w_eye.full_scans, w_prev.full_scans, w_d1.full_scans);
  const Accuracy aw = wide_accuracy(wide, w_eye), aw_prev = wide_accuracy(wide, w_prev),
                 aw_d1 = wide_accuracy(wide, w_d1);
  std::fprintf(stderr, "[eye_bench] bumped camera (5 mm, 0.3 deg), %d frames\n",
               std::min(frames, 60));
  const auto [bump_frames, still_ok] = bumped_camera(wide, std::min(frames, 60));

  std::printf("detect_rate_wide_angle %.4f\n", aw.detect_rate);
  std::printf("pos_rms_mm_wide_angle %.4f\n", aw.pos_rms_mm);
  std::printf("heading_rms_deg_wide_angle %.4f\n", aw.heading_rms_deg);
  std::printf("pos_max_mm_wide_angle %.4f\n", aw.pos_max_mm);
  std::printf("fps_1280x720_1t_wide_angle %.2f\n", w_eye.fps());
  std::printf("fps_1280x720_1t_wide_angle_cpu %.2f\n", w_eye.fps_cpu());
  std::printf("detect_rate_wide_angle_prev_default %.4f\n", aw_prev.detect_rate);
  std::printf("detect_rate_wide_angle_fullscan %.4f\n", wide_accuracy(wide, wf_eye).detect_rate);
  std::printf("detect_rate_wide_angle_fullscan_prev_default %.4f\n",
              wide_accuracy(wide, wf_prev).detect_rate);
  std::printf("fps_1280x720_1t_wide_angle_fullscan_cpu %.2f\n", wf_eye.fps_cpu());
  std::printf("fps_1280x720_1t_wide_angle_fullscan_prev_default_cpu %.2f\n", wf_prev.fps_cpu());
  std::printf("fps_1280x720_1t_wide_angle_prev_default %.2f\n", w_prev.fps());
  std::printf("fps_1280x720_1t_wide_angle_prev_default_cpu %.2f\n", w_prev.fps_cpu());
  std::printf("detect_rate_wide_angle_decimate1 %.4f\n", aw_d1.detect_rate);
  std::printf("fps_1280x720_1t_wide_angle_decimate1 %.2f\n", w_d1.fps());
  std::printf("fps_1280x720_1t_wide_angle_decimate1_cpu %.2f\n", w_d1.fps_cpu());
  std::printf("fps_ratio_wide_angle_vs_prev_default %.3f\n", w_eye.fps() / w_prev.fps());
  std::printf("fps_ratio_wide_angle_vs_decimate1 %.3f\n", w_eye.fps() / w_d1.fps());
  std::printf("cpu_fps_ratio_wide_angle_vs_decimate1 %.3f\n", w_eye.fps_cpu() / w_d1.fps_cpu());
  std::printf("frame_to_pose_ms_p50_wide_angle %.3f\n", percentile(w_eye.latency_ms, 0.5));
  std::printf("frame_to_pose_ms_p99_wide_angle %.3f\n", percentile(w_eye.latency_ms, 0.99));
  std::printf("frame_cpu_ms_p50_wide_angle %.3f\n", percentile(w_eye.frame_cpu_ms, 0.5));
  std::printf("frame_cpu_ms_p99_wide_angle %.3f\n", percentile(w_eye.frame_cpu_ms, 0.99));
  std::printf("tag_px_min_wide_angle %.1f\ntag_px_max_wide_angle %.1f\n", wide.tag_px_min,
              wide.tag_px_max);
  std::printf("bumped_camera_detected %d\n", bump_frames >= 0 && bump_frames < 30 ? 1 : 0);
  std::printf("bumped_camera_frames %d\n", bump_frames);
  std::printf("unmoved_camera_no_alarm %d\n", still_ok ? 1 : 0);
  if (wide_only) {
    std::printf("frames %d\nrepeats %d\n", frames, repeats);
    return 0;
  }
  // One resolution: its rendered scene, then the Eye with and without window tracking.
  const auto at_size = [&](int w, int h, Scene *scene, RunResult *tracked, RunResult *full) {
    std::fprintf(stderr, "[eye_bench] rendering %d frames at %dx%d\n", frames, w, h);
    *scene = make_scene(w, h, frames, tag_size_m, nullptr);
    std::fprintf(stderr, "[eye_bench] Eye pipeline %dx%d, %d passes\n", w, h, repeats);
    *tracked = run_eye(*scene, lcm, repeats, true);
    std::fprintf(stderr, "[eye_bench] Eye pipeline %dx%d without window tracking, %d passes\n", w,
                 h, repeats);
    *full = run_eye(*scene, lcm, repeats, false);
  };
  Scene hd, fhd;
  RunResult e720, e720full, e1080, e1080full;
  at_size(1280, 720, &hd, &e720, &e720full);
  std::fprintf(stderr, "[eye_bench] peer (OpenCV aruco) 1280x720, %d passes\n", repeats);
  const RunResult p720 = run_peer(hd, lcm, repeats);
  const Accuracy a = accuracy(hd, e720), pa = accuracy(hd, p720), afull = accuracy(hd, e720full);
  if (!csv.empty()) {
    std::ofstream f(csv);
    f << "frame,true_x_m,true_y_m,true_yaw_rad,eye_x_m,eye_y_m,eye_yaw_rad,peer_x_m,peer_y_m,peer_"
         "yaw_rad\n";
    for (size_t i = 0; i < hd.path.size(); ++i) {
      f << i << "," << hd.path[i].x_m << "," << hd.path[i].y_m << "," << hd.path[i].yaw_rad;
      for (const RunResult *r : std::initializer_list<const RunResult *>{&e720, &p720}) {
        if (r->est[i])
          f << "," << r->est[i]->x_m << "," << r->est[i]->y_m << "," << r->est[i]->yaw_rad;
        else
          f << ",,,";
      }
      f << "\n";
    }
  }
  at_size(1920, 1080, &fhd, &e1080, &e1080full);
  const Accuracy a1080 = accuracy(fhd, e1080);

  const double jpeg_kb = static_cast<double>(hd.jpeg[0].size()) / 1024.0;
  std::printf("fps_1280x720_1t %.2f\n", e720.fps());
  std::printf("fps_1920x1080_1t %.2f\n", e1080.fps());
  std::printf("peer_fps_1280x720_1t %.2f\n", p720.fps());
  std::printf("fps_1280x720_1t_cpu %.2f\n", e720.fps_cpu());
  std::printf("fps_1920x1080_1t_cpu %.2f\n", e1080.fps_cpu());
  std::printf("peer_fps_1280x720_1t_cpu %.2f\n", p720.fps_cpu());
  std::printf("fps_1280x720_1t_fullscan %.2f\n", e720full.fps());
  std::printf("fps_1280x720_1t_fullscan_cpu %.2f\n", e720full.fps_cpu());
  std::printf("fps_1920x1080_1t_fullscan %.2f\n", e1080full.fps());
  std::printf("fps_1920x1080_1t_fullscan_cpu %.2f\n", e1080full.fps_cpu());
  std::printf("detect_rate_fullscan %.4f\n", afull.detect_rate);
  std::printf("pos_rms_mm_fullscan %.4f\n", afull.pos_rms_mm);
  std::printf("pos_rms_mm %.4f\n", a.pos_rms_mm);
  std::printf("heading_rms_deg %.4f\n", a.heading_rms_deg);
  std::printf("detect_rate %.4f\n", a.detect_rate);
  std::printf("pos_median_mm %.4f\n", a.pos_median_mm);
  std::printf("pos_max_mm %.4f\n", a.pos_max_mm);
  std::printf("pos_rms_mm_1920x1080 %.4f\n", a1080.pos_rms_mm);
  std::printf("heading_rms_deg_1920x1080 %.4f\n", a1080.heading_rms_deg);
  std::printf("detect_rate_1920x1080 %.4f\n", a1080.detect_rate);
  std::printf("peer_pos_rms_mm %.4f\n", pa.pos_rms_mm);
  std::printf("peer_heading_rms_deg %.4f\n", pa.heading_rms_deg);
  std::printf("peer_detect_rate %.4f\n", pa.detect_rate);
  std::printf("frames %d\nrepeats %d\ntag_size_m %.3f\njpeg_kb_1280x720 %.1f\n", frames, repeats,
              tag_size_m, jpeg_kb);
  return 0;
}
