// autodrive-eye: overhead AprilTag localisation of every car, and its calibration tools.
#include <autodrive/instance.hpp>
#include <autodrive_channels.h>
#include <CLI/CLI.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

#include <algorithm>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <filesystem>

#include "eye_boards.hpp"
#include "eye_config.hpp"
#include "eye_error.hpp"
#include "eye_fuse.hpp"
#include "eye_intrinsics.hpp"
#include "eye_lockstep.hpp"
#include "eye_mapcal.hpp"
#include "eye_publish.hpp"
#include "eye_realtime.hpp"
#include "eye_source.hpp"
#include "eye_tracker.hpp"

namespace {

volatile std::sig_atomic_t g_stop = 0;
void on_signal(int) {
  g_stop = 1;
}

// Grey images from a folder (sorted by name) or a single image file.
std::vector<std::pair<std::string, cv::Mat>> load_images(const std::string &path) {
  std::vector<std::string> files;
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) {
    for (const auto &e : std::filesystem::directory_iterator(path)) {
      std::string ext = e.path().extension().string();
      std::transform(ext.begin(), ext.end(), ext.begin(), ::tolower);
      if (ext == ".png" || ext == ".jpg" || ext == ".jpeg" || ext == ".bmp" || ext == ".pgm")
        files.push_back(e.path().string());
    }
    std::sort(files.begin(), files.end());
    if (files.empty()) throw eye::Error(path + ": no .png/.jpg/.bmp/.pgm images in the folder");
  } else if (std::filesystem::exists(path, ec)) {
    files.push_back(path);
  } else {
    throw eye::Error(path + ": no such file or folder");
  }
  std::vector<std::pair<std::string, cv::Mat>> out;
  for (const auto &f : files) {
    cv::Mat g = cv::imread(f, cv::IMREAD_GRAYSCALE);
    if (g.empty()) throw eye::Error(f + ": cannot read the image");
    out.emplace_back(f, g);
  }
  return out;
}

// Every `every`-th frame of a video file or camera, up to max_views.
std::vector<cv::Mat> grab_views(cv::VideoCapture &cap, const std::string &what, int every,
                                int max_views) {
  if (!cap.isOpened()) throw eye::Error(what + ": cannot open");
  std::vector<cv::Mat> out;
  cv::Mat m, g;
  for (int i = 0; static_cast<int>(out.size()) < max_views && cap.read(m) && !g_stop; ++i) {
    if (i % every) continue;
    if (m.channels() == 3)
      cv::cvtColor(m, g, cv::COLOR_BGR2GRAY);
    else
      g = m;
    out.push_back(g.clone());
  }
  return out;
}

// What a calibration tool shows its user: the coverage picture, then each image's corners and
// reprojection error; the refusal (too few views, poor coverage, high RMS) comes after them.
eye::IntrinsicsReport calibrate_and_report(const std::vector<cv::Mat> &views,
                                           const std::vector<std::string> &names,
                                           const eye::IntrinsicsParams &ip,
                                           const std::string &coverage_png) {
  eye::IntrinsicsReport rep = eye::intrinsics_detect(views, ip);
  const auto write_picture = [&] {
    if (!cv::imwrite(coverage_png, eye::intrinsics_coverage_image(rep)))
      throw eye::Error(coverage_png + ": cannot write the coverage picture");
    std::printf("coverage picture: %s\n", coverage_png.c_str());
  };
  try {
    eye::intrinsics_solve(rep, ip);
  } catch (const eye::Error &) {
    write_picture();
    throw;
  }
  write_picture();
  for (size_t i = 0; i < rep.corners.size(); ++i) {
    const auto k = static_cast<size_t>(rep.used[i]);
    std::printf("image %s: %zu corners, reprojection RMS %.3f px\n",
                k < names.size() ? names[k].c_str() : std::to_string(k).c_str(),
                rep.corners[i].size(), rep.view_rms_px[i]);
  }
  return rep;
}

}  // namespace

int main(int argc, char **argv) {
  CLI::App app{
      "autodrive-eye: overhead AprilTag (tag36h11) localisation of every car on the map.\n"
      "Calibrate the camera (calibrate-intrinsics), then its pose over the map from\n"
      "reference tags (calibrate-map), then localise the cars (run)."};
  app.require_subcommand(1);

  // calibrate-intrinsics
  auto *ci = app.add_subcommand("calibrate-intrinsics",
                                "Camera matrix and distortion from checkerboard views");
  std::string ci_images, ci_video, ci_out;
  int ci_device = -1, ci_every = 15, ci_max = 40;
  eye::IntrinsicsParams ip;
  auto *ci_src = ci->add_option_group("input", "one of");
  ci_src->add_option("--images", ci_images, "folder of checkerboard images (png/jpg)");
  ci_src->add_option("--video", ci_video, "video file of the board moving");
  ci_src->add_option("--device", ci_device, "live camera index (V4L2)");
  ci_src->require_option(1);
  ci->add_option("--every", ci_every, "video/device: use every N-th frame")->capture_default_str();
  ci->add_option("--max-views", ci_max, "video/device: stop after this many frames")
      ->capture_default_str();
  ci->add_option("--cols", ip.inner_cols, "inner corners along the board's width")
      ->capture_default_str();
  ci->add_option("--rows", ip.inner_rows, "inner corners along the board's height")
      ->capture_default_str();
  ci->add_option("--square-m", ip.square_m, "square edge [m]")->capture_default_str();
  ci->add_option("--min-views", ip.min_views, "refuse fewer usable views")->capture_default_str();
  ci->add_option("--min-coverage", ip.min_coverage,
                 "refuse if corners reach less than this fraction of a 4x4 image grid")
      ->capture_default_str();
  ci->add_option("--max-rms-px", ip.max_rms_px, "refuse a higher reprojection RMS [px]")
      ->capture_default_str();
  ci->add_flag("!--free-k3", ip.fix_k3, "also fit k3 (wide-angle lenses)");
  ci->add_flag("--charuco", ip.charuco,
               "ChArUco board (DICT_5X5_100, squares = cols+1 x rows+1) instead of a checkerboard");
  ci->add_option("--marker-ratio", ip.marker_ratio, "ChArUco: marker edge / square edge")
      ->capture_default_str();
  ci->add_option("-o,--out", ci_out, "output YAML (camera matrix, distortion, RMS)")->required();
  std::string ci_coverage;
  ci->add_option("--coverage-png", ci_coverage,
                 "the coverage picture: the 4x4 grid, reached cells green, every corner found "
                 "(default: the output's name with .coverage.png)");

  // make-board-images
  auto *mb = app.add_subcommand(
      "make-board-images",
      "A calibration set without a camera: the checkerboard rendered through a camera model "
      "from many poses, covering the image (calibrate-intrinsics --images DIR takes it)");
  std::string mb_intr, mb_config, mb_out;
  eye::BoardSetParams bp;
  eye::IntrinsicsParams mp;
  auto *mb_cam = mb->add_option_group("camera model", "one of");
  mb_cam->add_option("--intrinsics", mb_intr, "the camera model: an intrinsics YAML");
  mb_cam->add_option("-c,--config", mb_config, "a run config: its intrinsics are the model");
  mb_cam->require_option(1);
  mb->add_option("--views", bp.views, "images to render (16: each 4x4 grid cell once)")
      ->check(CLI::Range(1, 200))
      ->capture_default_str();
  mb->add_option("--cols", mp.inner_cols, "inner corners along the board's width")
      ->capture_default_str();
  mb->add_option("--rows", mp.inner_rows, "inner corners along the board's height")
      ->capture_default_str();
  mb->add_option("--square-m", mp.square_m, "square edge [m]")->capture_default_str();
  mb->add_option("--max-tilt-rad", bp.max_tilt_rad, "largest board tilt [rad]")
      ->check(CLI::Range(0.0, 1.2))
      ->capture_default_str();
  mb->add_option("-o,--out", mb_out, "folder for board-NN.png (created)")->required();

  // calibrate-map
  auto *cm = app.add_subcommand("calibrate-map",
                                "Camera pose over the map from reference tags at known places");
  std::string cm_intr, cm_tags, cm_images, cm_out;
  double cm_max_rms_mm = 5.0;
  int cm_min_tags = 3;
  float cm_decimate = 1.0f;
  cm->add_option("--intrinsics", cm_intr, "intrinsics YAML from calibrate-intrinsics")->required();
  cm->add_option("--tags", cm_tags,
                 "reference tags YAML: tags: [{id, x_m, y_m, z_m, yaw_rad, size_m}]")
      ->required();
  cm->add_option("--images", cm_images, "an image or a folder of images of the map (fixed camera)")
      ->required();
  cm->add_option("-o,--out", cm_out, "output YAML (camera pose in the map, residuals)")->required();
  cm->add_option("--max-rms-mm", cm_max_rms_mm, "refuse a higher corner residual RMS [mm]")
      ->capture_default_str();
  cm->add_option("--min-tags", cm_min_tags, "refuse if fewer reference tags are seen")
      ->capture_default_str();
  cm->add_option("--decimate", cm_decimate, "detector decimation (1: most accurate)")
      ->capture_default_str();
  std::string cm_ov_map, cm_ov_intr, cm_ov_images;
  cm->add_option("--overlap-map", cm_ov_map,
                 "another camera's map.yaml (same map frame): report how the two calibrations "
                 "agree on the reference tags both cameras see");
  cm->add_option("--overlap-intrinsics", cm_ov_intr, "that camera's intrinsics YAML");
  cm->add_option("--overlap-images", cm_ov_images, "that camera's image(s) of the map");

  // run
  auto *rn = app.add_subcommand("run", "Localise the cars and publish <VEH>_POSE_EYE (pose2d_t)");
  std::string rn_config, rn_source = std::string("lcm:") + AUTODRIVE_CH_EYE_IMAGE, rn_debug, rn_url;
  std::string rn_sign_as = "EYE";
  double rn_fps = 30.0, rn_idle_s = 0.0, rn_sim_latency_ms = -1.0, rn_cpu_delay_ms = 0.0;
  int rn_max_frames = 0, rn_debug_every = 1, rn_realtime = -1;
  bool rn_quiet = false;
  rn->add_option("-c,--config", rn_config, "run config YAML (see eye/config/eye.yaml)")->required();
  rn->add_option("-s,--source", rn_source,
                 "device:<index> | gst:<pipeline> | video:<file> | folder:<dir> | lcm:<channel>")
      ->capture_default_str();
  rn->add_option("--fps", rn_fps, "video/folder sources: frame rate used to stamp frames [Hz]")
      ->capture_default_str();
  rn->add_option("--lcm-url", rn_url, "override the config's lcm_url");
  rn->add_option("--realtime-priority", rn_realtime,
                 "override the config's realtime_priority (SCHED_FIFO 1..98; 0: ordinary)")
      ->check(CLI::Range(0, 98));
  rn->add_option("--debug-image", rn_debug, "write the annotated frame to this file (png/jpg)");
  rn->add_option("--debug-every", rn_debug_every, "write the debug image every N frames")
      ->capture_default_str();
  rn->add_option("--max-frames", rn_max_frames, "stop after this many frames (0: never)")
      ->capture_default_str();
  rn->add_option("--idle-timeout-s", rn_idle_s,
                 "lcm source: stop after this long without a frame (0: never)")
      ->capture_default_str();
  rn->add_flag("-q,--quiet", rn_quiet, "no per-frame line on stdout");
  rn->add_option("--sign-as", rn_sign_as,
                 "sign the poses with this eye-role certificate (NAME.cert, NAME.sk in "
                 "$AUTODRIVE_KEY_DIR; tools/keys issue --role eye)")
      ->capture_default_str();
  rn->add_option("--sim-latency-ms", rn_sim_latency_ms,
                 "lockstep with the simulator (lcm: sources, autodrive-sim --eye-sync): publish "
                 "a frame's poses (stamped with its capture time) when SIM_CLOCK reaches capture "
                 "time + this [ms of sim time], then EYE_FRAME_DONE; overrides the config's "
                 "sim_latency_ms (e.g. tools/bench eye's capture_to_pose_ms_p99)")
      ->check(CLI::Range(0.0, 10000.0));
  rn->add_option("--cpu-delay-ms", rn_cpu_delay_ms,
                 "test double, a slower Eye: spend this much more CPU time on each frame [ms]")
      ->check(CLI::Range(0.0, 10000.0));

  CLI11_PARSE(app, argc, argv);
  std::signal(SIGINT, on_signal);
  std::signal(SIGTERM, on_signal);

  try {
    if (*mb) {
      const eye::Intrinsics in =
          mb_intr.empty() ? eye::runconfig_load(mb_config).in : eye::intrinsics_load(mb_intr);
      std::filesystem::create_directories(mb_out);
      const auto boards = eye::boards_render(in, mp, bp);
      for (size_t i = 0; i < boards.size(); ++i) {
        char name[32];
        std::snprintf(name, sizeof name, "board-%02zu.png", i + 1);
        const std::string path = (std::filesystem::path(mb_out) / name).string();
        if (!cv::imwrite(path, boards[i].image)) throw eye::Error(path + ": cannot write");
      }
      std::printf("wrote %zu board images (%dx%d px, %dx%d inner corners, %.3f m squares) to %s\n",
                  boards.size(), in.width_px, in.height_px, mp.inner_cols, mp.inner_rows,
                  mp.square_m, mb_out.c_str());
      return 0;
    }
    if (*ci) {
      std::vector<cv::Mat> views;
      std::vector<std::string> names;
      if (!ci_images.empty()) {
        for (auto &[name, img] : load_images(ci_images)) {
          names.push_back(std::filesystem::path(name).filename().string());
          views.push_back(img);
        }
      } else if (!ci_video.empty()) {
        if (!std::filesystem::exists(ci_video)) throw eye::Error(ci_video + ": no such file");
        cv::VideoCapture cap(ci_video, cv::CAP_FFMPEG);
        views = grab_views(cap, ci_video, std::max(1, ci_every), ci_max);
      } else {
        cv::VideoCapture cap(ci_device, cv::CAP_V4L2);
        views =
            grab_views(cap, "camera " + std::to_string(ci_device), std::max(1, ci_every), ci_max);
      }
      if (ci_coverage.empty())
        ci_coverage = std::filesystem::path(ci_out).replace_extension(".coverage.png").string();
      const auto rep = calibrate_and_report(views, names, ip, ci_coverage);
      eye::intrinsics_save(ci_out, rep.in);
      std::printf(
          "views %d/%d, coverage %.0f%%, rms %.4f px\nfx %.3f fy %.3f cx %.3f cy %.3f\n"
          "wrote %s\n",
          rep.views_used, rep.views_total, 100 * rep.coverage, rep.in.rms_px, rep.in.k(0, 0),
          rep.in.k(1, 1), rep.in.k(0, 2), rep.in.k(1, 2), ci_out.c_str());
      return 0;
    }
    if (*cm) {
      const eye::Intrinsics in = eye::intrinsics_load(cm_intr);
      const auto refs = eye::reftags_load(cm_tags);
      eye::DetectorParams dp;
      dp.decimate = cm_decimate;
      eye::Detector det(dp);
      std::vector<std::vector<eye::Detection>> frames;
      for (auto &[name, img] : load_images(cm_images)) {
        if (img.cols != in.width_px || img.rows != in.height_px)
          throw eye::Error(name + ": image size " + std::to_string(img.cols) + "x" +
                           std::to_string(img.rows) + " differs from the intrinsics in " + cm_intr);
        frames.push_back(det.detect(img));
      }
      const auto m = eye::map_calibrate(in, refs, frames, cm_min_tags);
      for (const auto &t : m.tags) std::printf("tag %3d  residual %.3f mm\n", t.id, t.rms_mm);
      for (int id : m.missing_ids) std::printf("tag %3d  NOT SEEN\n", id);
      const cv::Vec3d c = m.pose.centre_map();
      std::printf(
          "camera centre on the map (%.4f, %.4f, %.4f) m\n"
          "residual rms %.3f mm, max %.3f mm over %zu tags\n",
          c[0], c[1], c[2], m.rms_mm, m.max_mm, m.tags.size());
      if (!(m.rms_mm <= cm_max_rms_mm)) {
        std::fprintf(stderr,
                     "autodrive-eye: calibrate-map: residual rms %.3f mm > %.3f mm: check the "
                     "tag positions in %s and the intrinsics in %s; nothing written\n",
                     m.rms_mm, cm_max_rms_mm, cm_tags.c_str(), cm_intr.c_str());
        return 1;
      }
      eye::mapcal_save(cm_out, m);
      std::printf("wrote %s\n", cm_out.c_str());
      if (!cm_ov_map.empty()) {
        if (cm_ov_intr.empty() || cm_ov_images.empty())
          throw eye::Error(
              "calibrate-map: --overlap-map needs --overlap-intrinsics and "
              "--overlap-images");
        const eye::Intrinsics in_b = eye::intrinsics_load(cm_ov_intr);
        const eye::MapCalib m_b = eye::mapcal_load(cm_ov_map);
        std::vector<std::vector<eye::Detection>> frames_b;
        for (auto &[name, img] : load_images(cm_ov_images)) {
          if (img.cols != in_b.width_px || img.rows != in_b.height_px)
            throw eye::Error(name + ": image size differs from the intrinsics in " + cm_ov_intr);
          frames_b.push_back(det.detect(img));
        }
        const auto o =
            eye::map_overlap_agreement(refs, in, m.pose, frames, in_b, m_b.pose, frames_b);
        for (const auto &t : o.tags)
          std::printf("overlap tag %3d  cameras agree within %.3f mm rms\n", t.id, t.rms_mm);
        if (o.tags.empty())
          std::printf("overlap: no reference tag seen by both cameras\n");
        else
          std::printf("overlap: %zu shared tags, %.3f mm rms, max %.3f mm\n", o.tags.size(),
                      o.rms_mm, o.max_mm);
      }
      return 0;
    }
    if (*rn) {
      eye::RunConfig cfg = eye::runconfig_load(rn_config);
      if (!rn_url.empty()) cfg.lcm_url = rn_url;
      if (rn_realtime >= 0) cfg.realtime_priority = rn_realtime;
      // Before any thread starts (LCM's, the sources', the trackers'): they inherit it.
      const std::string rt_why = eye::request_realtime(cfg.realtime_priority);
      if (!rt_why.empty())
        std::fprintf(stderr,
                     "autodrive-eye: WARNING: %s: realtime_priority %d not granted (%s): running "
                     "at ordinary priority, poses may be late on a busy machine; grant it "
                     "(setcap cap_sys_nice+ep on autodrive-eye, or an rtprio limit) or set "
                     "realtime_priority: 0\n",
                     rn_config.c_str(), cfg.realtime_priority, rt_why.c_str());
      cfg.lcm_url = autodrive::instance_lcm_url(cfg.lcm_url);  // AUTODRIVE_INSTANCE
      lcm::LCM lcm(cfg.lcm_url);
      if (!lcm.good()) throw eye::Error("lcm: cannot open " + cfg.lcm_url);
      auto signer = autodrive::v2x::Signer::load("autodrive-eye", rn_sign_as);
      if (!signer) return 2;  // the reason is printed: no car would take unsigned poses
      if (signer->cert().role != V2X_ROLE_EYE)
        throw eye::Error("--sign-as " + rn_sign_as + ": a " + v2x_role_name(signer->cert().role) +
                         " certificate; Eye poses need an eye certificate");
      if (rn_sim_latency_ms >= 0) cfg.sim_latency_ms = rn_sim_latency_ms;
      // One source per camera: the config's `source`, else --source (one camera only).
      std::vector<std::unique_ptr<eye::Source>> srcs;
      std::vector<eye::RunConfig> cams;
      std::vector<std::vector<eye::RefTag>> refs;
      for (size_t i = 0; i < cfg.cameras.size(); ++i) {
        const std::string spec = cfg.cameras[i].source.empty() ? rn_source : cfg.cameras[i].source;
        if (cfg.cameras.size() > 1 && cfg.cameras[i].source.empty())
          throw eye::Error(rn_config + ": cameras[" + std::to_string(i) +
                           "].source: missing key (each of several cameras needs its source)");
        if (cfg.sim_latency_ms >= 0 && spec.rfind("lcm:", 0) != 0)
          throw eye::Error("source '" + spec +
                           "': sim_latency_ms / --sim-latency-ms needs lcm: sources (the "
                           "simulator's frames, stamped in sim time)");
        cams.push_back(eye::runconfig_camera(cfg, i));
        srcs.push_back(eye::source_open(spec, rn_fps, cfg.lcm_url, rn_idle_s,
                                        cams.back().in.width_px, cams.back().in.height_px));
        refs.push_back(cfg.reference_tags);
      }
      // After the sources: the simulator may send its first frame as soon as it is told
      std::unique_ptr<eye::SimLockstep> lockstep;
      if (cfg.sim_latency_ms >= 0)
        lockstep = std::make_unique<eye::SimLockstep>(cfg.lcm_url, cfg.sim_latency_ms);
      eye::MultiEye multi(cams, refs, cfg.health);
      std::vector<eye::Frame> fs(srcs.size());
      long frames = 0, published = 0;
      std::vector<double> latency_ms;  // capture (device, gst) to poses on LCM
      // Cameras on the bus (the simulator's) stamp the frames they take together with one
      // capture time. A frame lost on one channel (UDP, or a full queue) would pair the other
      // cameras' frames with a later one of it, so lcm: sources are brought to the newest
      // capture time among them before their frames are used together.
      bool align = srcs.size() > 1;
      for (size_t i = 0; i < cfg.cameras.size(); ++i)
        align = align && cfg.cameras[i].source.rfind("lcm:", 0) == 0;
      long unpaired = 0;  // frames dropped because another camera lacked theirs
      const auto all_next = [&] {
        for (size_t i = 0; i < srcs.size(); ++i)
          if (!srcs[i]->next(&fs[i])) return false;
        for (bool same = !align; !same;) {
          int64_t newest = fs[0].utime;
          for (const auto &f : fs) newest = std::max(newest, f.utime);
          same = true;
          for (size_t i = 0; i < srcs.size(); ++i)
            for (; fs[i].utime < newest; ++unpaired)
              if (!srcs[i]->next(&fs[i])) return false;
          for (const auto &f : fs) same = same && f.utime == fs[0].utime;
        }
        return true;
      };
      while (!g_stop && (rn_max_frames <= 0 || frames < rn_max_frames) && all_next()) {
        // A frame never ends the run: one of another size than its camera's calibration is
        // skipped (with the other cameras' frames of that time) and logged at a limited rate.
        bool sizes_ok = true;
        for (size_t i = 0; i < fs.size(); ++i) {
          const auto &in = cams[i].in;
          if (fs[i].width_px() == in.width_px && fs[i].height_px() == in.height_px) continue;
          sizes_ok = false;
          eye::skipped_frames_log().event(
              cams[i].camera_name, fs[i].label + ": size " + std::to_string(fs[i].width_px()) +
                                       "x" + std::to_string(fs[i].height_px()) +
                                       " differs from the calibrated " +
                                       std::to_string(in.width_px) + "x" +
                                       std::to_string(in.height_px) + " (frame skipped)");
        }
        if (!sizes_ok) {
          if (lockstep) {  // the sim waits for every frame it sent: this one is done, empty
            lockstep->hold(fs[0].utime, &g_stop);
            lockstep->done(lcm, fs[0].utime, 0);
          }
          continue;
        }
        // Cameras of one Eye are triggered together (the simulator renders them at one sim
        // time): the frame time is the first camera's capture time.
        std::vector<eye::TrackInput> grays;
        for (const auto &f : fs) grays.push_back({f.gray, f.jpeg});
        const int64_t utime = fs[0].utime;
        // The tracked cars' poses go out first; the staggered band (new cars, reference tags
        // for health) finishes after them.
        auto poses = multi.track(grays, utime);
        if (rn_cpu_delay_ms > 0) eye::burn_cpu_ms(rn_cpu_delay_ms);
        if (!lockstep) {
          published += eye::publish_poses(lcm, *signer, poses, utime);
          if (fs[0].wall_clock)
            latency_ms.push_back(1e-3 * static_cast<double>(eye::now_utime() - utime));
        }
        const auto late = multi.finish();
        if (lockstep) {  // every pose of the frame at capture + latency of sim time
          poses.insert(poses.end(), late.begin(), late.end());
          lockstep->hold(utime, &g_stop);
          published += eye::publish_poses(lcm, *signer, poses, utime);
          lockstep->done(lcm, utime, static_cast<int>(poses.size()));
        } else {
          published += eye::publish_poses(lcm, *signer, late, utime);
          poses.insert(poses.end(), late.begin(), late.end());
        }
        for (size_t i : multi.newly_moved()) {
          const auto &st = multi.health(i).status();
          std::fprintf(stderr,
                       "autodrive-eye: WARNING: camera %s moved: reference tags %.2f mm (%.2f px) "
                       "off their calibrated places; its poses now carry %gx covariance: "
                       "recalibrate (calibrate-map)\n",
                       st.camera.c_str(), st.ref_rms_mm, st.ref_rms_px, st.cov_scale);
        }
        for (size_t i = 0; i < multi.size(); ++i)
          if (multi.health(i).status_due(utime))
            eye::publish_status(lcm, multi.health(i).status(), cams[i].in.width_px,
                                cams[i].in.height_px);
        if (!rn_debug.empty() && frames % std::max(1, rn_debug_every) == 0 &&
            !cv::imwrite(rn_debug, multi.tracker(0).annotate(multi.tracker(0).last_frame(),
                                                             multi.last_per_camera()[0])))
          throw eye::Error(rn_debug + ": cannot write the debug image");
        if (!rn_quiet) {
          std::printf("%s utime=%lld", fs[0].label.c_str(), static_cast<long long>(utime));
          for (const auto &p : poses)
            std::printf("  %s x=%.4f y=%.4f yaw=%.4f", p.vehicle.c_str(), p.x_m, p.y_m, p.yaw_rad);
          std::printf("\n");
          std::fflush(stdout);
        }
        ++frames;
      }
      std::fprintf(stderr, "autodrive-eye: %ld frames, %ld poses published\n", frames, published);
      if (lockstep)
        std::fprintf(stderr,
                     "autodrive-eye: in lockstep with the simulator: poses out at capture + "
                     "%.3f ms of sim time; %ld frame(s) released without " AUTODRIVE_CH_SIM_CLOCK
                     " getting there\n",
                     1e-3 * static_cast<double>(lockstep->latency_us()), lockstep->given_up());
      if (unpaired > 0)
        std::fprintf(stderr,
                     "autodrive-eye: %ld camera frames dropped: another camera had no frame of "
                     "their capture time\n",
                     unpaired);
      if (!latency_ms.empty()) {
        std::sort(latency_ms.begin(), latency_ms.end());
        const auto pct = [&](double q) {
          return latency_ms[std::min(
              latency_ms.size() - 1,
              static_cast<size_t>(q * static_cast<double>(latency_ms.size())))];
        };
        std::fprintf(stderr, "autodrive-eye: capture to pose on LCM: p50 %.2f ms, p99 %.2f ms\n",
                     pct(0.5), pct(0.99));
      }
      return 0;
    }
  } catch (const eye::Error &e) {
    std::fprintf(stderr, "autodrive-eye: error: %s\n", e.what());
    return 1;
  } catch (const cv::Exception &e) {
    std::fprintf(stderr, "autodrive-eye: OpenCV error: %s\n", e.what());
    return 1;
  }
  return 0;
}
