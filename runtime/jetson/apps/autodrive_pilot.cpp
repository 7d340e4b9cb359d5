// autodrive-pilot: drives a car from its front camera alone with a behavioural-cloning model.
// Subscribes <VEH>_CAM_FRONT (the runtime's camera driver on the car, the simulator's camera in
// HIL) and <VEH>_ODOM (speed, the runtime's estimator), runs the ONNX model with OpenCV's DNN
// module on one thread, and publishes signed <VEH>_COMMAND (the project's Signer; the bridge's
// lease) with the network's steering and a throttle that holds a set speed and slows for large
// steering. When frames stop arriving for frame_timeout_ms of its clock (`clock: wall|sim`; a
// frozen SIM_CLOCK counts as no frames) it stops the car (disengaged commands) and says so; it
// drives again when frames return. --predict runs the model
// on image files instead.
#include <autodrive/instance.hpp>
#include <autodrive/command_auth.hpp>
#include <autodrive/compressed_image_t.hpp>
#include <autodrive/vehicle_command_t.hpp>
#include <autodrive/odometry_t.hpp>
#include <autodrive_channels.h>
#include <autodrive_lcm/subscribe.hpp>

#include <CLI/CLI.hpp>
#include <lcm/lcm-cpp.hpp>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <csignal>
#include <ctime>
#include <cstdio>
#include <fstream>
#include <optional>
#include <thread>
#include <string>
#include <vector>

#include <autodrive/core/clock.hpp>
#include <autodrive/pilot/frame_watchdog.hpp>
#include <autodrive/pilot/pilot_config.hpp>
#include <autodrive/pilot/pilot_model.hpp>
#include <autodrive/pilot/speed_rule.hpp>

namespace {

volatile std::sig_atomic_t g_stop = 0;
void on_signal(int) {
  g_stop = 1;
}

constexpr int kStopCommands = 10;             // disengaged commands on the way out
constexpr int64_t kReportPeriodUs = 5000000;  // a progress line every 5 s (monotonic)

// This thread's CPU time [ms]: what a frame costs on a core of its own, whatever else runs on
// the machine (the wall-clock figures include waiting for the CPU on a loaded host).
double thread_cpu_ms() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return t.tv_sec * 1e3 + t.tv_nsec * 1e-6;
}

double percentile(std::vector<double> v, double q) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  const size_t i = std::min(v.size() - 1, static_cast<size_t>(q * static_cast<double>(v.size())));
  return v[i];
}

class PilotNode {
 public:
  PilotNode(const autodrive::pilot::PilotConfig &cfg, lcm::LCM &lcm,
            autodrive::pilot::PilotModel &model, autodrive::auth::Signer signer)
      : cfg_(cfg),
        lcm_(lcm),
        model_(model),
        signer_(std::move(signer)),
        rule_(cfg.speed),
        clock_(cfg.clock),
        watchdog_(clock_, cfg.frame_timeout_ms),
        ch_cam_(cfg.vehicle + AUTODRIVE_CH_CAM_FRONT_SUFFIX),
        ch_cmd_(cfg.vehicle + AUTODRIVE_CH_COMMAND_SUFFIX) {
    clock_.attach(lcm_);
  }

  void on_frame(const autodrive::compressed_image_t *m) {
    const auto t0 = std::chrono::steady_clock::now();
    const cv::Mat bgr = cv::imdecode(m->data, cv::IMREAD_COLOR);
    if (bgr.empty()) {
      spdlog::warn("{}: a {}-byte '{}' frame does not decode: skipped", ch_cam_, m->data.size(),
                   m->format);
      return;
    }
    const auto t1 = std::chrono::steady_clock::now();
    const double cpu0 = thread_cpu_ms();
    float steering = 0.0f;
    try {
      steering = model_.steering(autodrive::pilot::preprocess(bgr, model_.spec()));
    } catch (const autodrive::InputError &e) {
      spdlog::warn("{}: {}: skipped", ch_cam_, e.what());
      return;
    }
    const auto t2 = std::chrono::steady_clock::now();
    decode_ms_.push_back(std::chrono::duration<double, std::milli>(t1 - t0).count());
    infer_ms_.push_back(std::chrono::duration<double, std::milli>(t2 - t1).count());
    infer_cpu_ms_.push_back(thread_cpu_ms() - cpu0);
    if (stopped_) spdlog::info("{}: frames again: driving", ch_cam_);
    if (!watchdog_.seen()) spdlog::info("{}: first frame: driving", ch_cam_);
    stopped_ = false;
    watchdog_.frame();
    const double dt_s = last_frame_utime_ > 0 ? (m->utime - last_frame_utime_) * 1e-6 : 0.0;
    last_frame_utime_ = m->utime;
    steering_ = steering;
    publish(true, std::clamp(dt_s, 0.0, 0.5), m->utime);
  }

  // The speed the runtime's estimator reports (wheel encoders and IMU) [m/s].
  void on_odom(const autodrive::odometry_t *m) {
    speed_m_s_ = m->vx_m_s;
    state_utime_ = m->utime;
  }

  // Between messages: the frame watchdog and the command rate.
  void tick() {
    const int64_t now = autodrive::clock::monotonic_us();
    if (now - last_report_us_ >= kReportPeriodUs) report(now);
    if (!watchdog_.seen()) return;  // not driving yet: nothing to hold
    if (!stopped_ && watchdog_.silent(now)) {
      stopped_ = true;
      ++timeouts_;
      spdlog::error("no frame on {} for {} ms (frame_timeout_ms {}{}): STOPPING the car", ch_cam_,
                    watchdog_.silent_ms(), cfg_.frame_timeout_ms,
                    clock_.frozen(now) ? ", the sim clock is frozen" : "");
      rule_.reset();
    }
    if (now - last_pub_us_ >= static_cast<int64_t>(1e6 / cfg_.command_rate_hz))
      publish(!stopped_, 0.0, std::max(last_frame_utime_, state_utime_));
  }

  void stop_car() {
    for (int i = 0; i < kStopCommands; ++i) {
      publish(false, 0.0, std::max(last_frame_utime_, state_utime_));
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
  }

  nlohmann::json stats() const {
    return {{"frames", infer_ms_.size()},
            {"inference_ms_p50", percentile(infer_ms_, 0.50)},
            {"inference_ms_p99", percentile(infer_ms_, 0.99)},
            {"inference_cpu_ms_p50", percentile(infer_cpu_ms_, 0.50)},
            {"inference_cpu_ms_p99", percentile(infer_cpu_ms_, 0.99)},
            {"decode_ms_p50", percentile(decode_ms_, 0.50)},
            {"frame_timeouts", timeouts_},
            {"commands", seq_},
            {"model", model_.path()},
            {"opset", model_.opset()}};
  }

 private:
  void publish(bool engaged, double dt_s, int64_t utime) {
    autodrive::vehicle_command_t c{};
    c.utime = utime;
    c.seq = seq_++;
    c.steering = engaged ? steering_ : 0.0f;
    c.throttle = engaged ? static_cast<float>(rule_.throttle(steering_, speed_m_s_, dt_s)) : 0.0f;
    c.engaged = engaged;
    c.headlights = 1;
    signer_.sign(c);
    lcm_.publish(ch_cmd_, &c);
    last_pub_us_ = autodrive::clock::monotonic_us();
  }

  void report(int64_t now) {
    const size_t n = infer_ms_.size();
    if (last_report_us_ > 0)
      spdlog::info(
          "frames {} (+{})  inference p50 {:.2f} ms p99 {:.2f} ms  steering {:+.3f}  "
          "speed {:.3f} m/s{}",
          n, n - reported_frames_, percentile(infer_ms_, 0.5), percentile(infer_ms_, 0.99),
          steering_, speed_m_s_, stopped_ ? "  STOPPED (no frames)" : "");
    reported_frames_ = n;
    last_report_us_ = now;
  }

  const autodrive::pilot::PilotConfig &cfg_;
  lcm::LCM &lcm_;
  autodrive::pilot::PilotModel &model_;
  autodrive::auth::Signer signer_;
  autodrive::pilot::SpeedRule rule_;
  autodrive::clock::Clock clock_;
  autodrive::pilot::FrameWatchdog watchdog_;
  std::string ch_cam_, ch_cmd_;
  std::vector<double> infer_ms_, infer_cpu_ms_, decode_ms_;
  float steering_ = 0.0f;
  double speed_m_s_ = 0.0;
  int64_t last_frame_utime_ = 0, state_utime_ = 0, last_pub_us_ = 0, last_report_us_ = 0;
  size_t reported_frames_ = 0;
  int timeouts_ = 0;
  int32_t seq_ = 0;
  bool stopped_ = false;
};

// --predict: the raw network output for each image file, one "path value" line each; with
// stats_path, the preprocessing + inference time percentiles [ms] as JSON there.
int predict(autodrive::pilot::PilotModel &model, const std::vector<std::string> &images,
            const std::string &stats_path) {
  std::vector<double> infer_ms, infer_cpu_ms;
  for (const auto &path : images) {
    const cv::Mat bgr = cv::imread(path, cv::IMREAD_COLOR);
    if (bgr.empty()) {
      std::fprintf(stderr, "autodrive-pilot: --predict: %s: cannot be read as an image\n",
                   path.c_str());
      return 2;
    }
    const auto t0 = std::chrono::steady_clock::now();
    const double cpu0 = thread_cpu_ms();
    const float out = model.raw(autodrive::pilot::preprocess(bgr, model.spec()));
    infer_cpu_ms.push_back(thread_cpu_ms() - cpu0);
    infer_ms.push_back(
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
    std::printf("%s %.9g\n", path.c_str(), out);
  }
  if (!stats_path.empty())
    std::ofstream(stats_path)
        << nlohmann::json{{"frames", infer_ms.size()},
                          {"inference_ms_p50", percentile(infer_ms, 0.5)},
                          {"inference_ms_p99", percentile(infer_ms, 0.99)},
                          {"inference_cpu_ms_p50", percentile(infer_cpu_ms, 0.5)},
                          {"inference_cpu_ms_p99", percentile(infer_cpu_ms, 0.99)},
                          {"model", model.path()}}
               .dump(2)
        << "\n";
  return 0;
}

}  // namespace

int main(int argc, char **argv) {
  CLI::App cli{
      "autodrive-pilot: drives the car from its front camera with a behavioural-cloning ONNX "
      "model (OpenCV DNN, one thread): <VEH>_CAM_FRONT + <VEH>_ODOM in, signed <VEH>_COMMAND "
      "out; stops the car when frames stop arriving"};
  std::string config_path, model_override, url_override, vehicle_override, key_file, stats_path;
  std::vector<std::string> predict_images;
  bool check_only = false;
  cli.add_option("--config", config_path,
                 "YAML configuration (runtime/jetson/config/pilot_*.yaml)");
  cli.add_option("--model", model_override,
                 "the model NAME.onnx (its NAME.json beside it); "
                 "overrides the config's model");
  cli.add_option("--lcm-url", url_override, "override lcm_url of the config");
  cli.add_option("--vehicle", vehicle_override, "override vehicle (e.g. NIGEL1)");
  cli.add_option("--key-file", key_file,
                 "the car's command key (default: $AUTODRIVE_KEY_DIR/<VEH>.key, else "
                 "~/.config/autodrive/keys/<VEH>.key; tools/keys creates it)");
  cli.add_option(
      "--stats", stats_path,
      "on exit, write frames and inference (preprocessing + network) time percentiles [ms] as "
      "JSON here (also with --predict)");
  cli.add_option("--predict", predict_images,
                 "run the model on these image files and print 'path steering' per line (no "
                 "LCM, no config needed), then exit");
  cli.add_flag("--check", check_only, "load and check the model, print what it is, and exit");
  CLI11_PARSE(cli, argc, argv);
  spdlog::set_default_logger(spdlog::stderr_color_mt("pilot"));  // stdout: --predict's
  cv::setNumThreads(1);  // one core: the figure the car's budget is judged on

  autodrive::pilot::PilotConfig cfg;
  try {
    if (!config_path.empty()) cfg = autodrive::pilot::load_config(config_path);
  } catch (const std::exception &e) {
    std::fprintf(stderr, "autodrive-pilot: %s\n", e.what());
    return 2;
  }
  if (!model_override.empty()) cfg.model = model_override;
  if (!url_override.empty()) cfg.lcm_url = url_override;
  if (!vehicle_override.empty()) cfg.vehicle = vehicle_override;
  if (cfg.model.empty()) {
    std::fprintf(stderr, "autodrive-pilot: no model: give --config or --model\n");
    return 2;
  }
  std::optional<autodrive::pilot::PilotModel> model;
  try {
    model.emplace(cfg.model);
  } catch (const std::exception &e) {
    std::fprintf(stderr, "autodrive-pilot: model refused: %s\n", e.what());
    return 2;
  }
  const auto &s = model->spec();
  spdlog::info("model {} (opset {}): frames {}x{} -> crop {}+{} rows -> {}x{}", cfg.model,
               model->opset(), s.source_width_px, s.source_height_px, s.crop_top_px,
               s.crop_bottom_px, s.width_px, s.height_px);
  if (check_only) return 0;
  if (!predict_images.empty()) {
    try {
      return predict(*model, predict_images, stats_path);
    } catch (const std::exception &e) {
      std::fprintf(stderr, "autodrive-pilot: --predict: %s\n", e.what());
      return 2;
    }
  }
  if (config_path.empty()) {
    std::fprintf(stderr, "autodrive-pilot: driving needs --config\n");
    return 2;
  }
  auto signer =
      autodrive::auth::load_machine_signer("autodrive-pilot", cfg.vehicle, key_file, "pilot");
  if (!signer) return 2;
  cfg.lcm_url = autodrive::instance_lcm_url(cfg.lcm_url);  // AUTODRIVE_INSTANCE
  lcm::LCM lcm(cfg.lcm_url);
  if (!lcm.good()) {
    std::fprintf(stderr, "autodrive-pilot: cannot open LCM at '%s' (multicast route missing?)\n",
                 cfg.lcm_url.c_str());
    return 2;
  }
  std::signal(SIGINT, on_signal);
  std::signal(SIGTERM, on_signal);
  PilotNode node(cfg, lcm, *model, std::move(*signer));
  auto *cam =
      autodrive_lcm::subscribe<autodrive::compressed_image_t, PilotNode, &PilotNode::on_frame>(
          lcm, cfg.vehicle + AUTODRIVE_CH_CAM_FRONT_SUFFIX, &node);
  cam->setQueueCapacity(1);  // the newest frame only: a late frame is worth less than none
  autodrive_lcm::subscribe<autodrive::odometry_t, PilotNode, &PilotNode::on_odom>(
      lcm, cfg.vehicle + AUTODRIVE_CH_ODOM_SUFFIX, &node);
  spdlog::info("{} on {}: listening to {}{}, {}{}; frame timeout {} ms", cfg.vehicle, cfg.lcm_url,
               cfg.vehicle, AUTODRIVE_CH_CAM_FRONT_SUFFIX, cfg.vehicle, AUTODRIVE_CH_ODOM_SUFFIX,
               cfg.frame_timeout_ms);
  const int wait_ms = std::max(1, static_cast<int>(500.0 / cfg.command_rate_hz));
  while (!g_stop) {
    if (lcm.handleTimeout(wait_ms) < 0) break;
    node.tick();
  }
  node.stop_car();
  const nlohmann::json st = node.stats();
  spdlog::info("stopped: {}", st.dump());
  if (!stats_path.empty()) std::ofstream(stats_path) << st.dump(2) << "\n";
  return 0;
}
