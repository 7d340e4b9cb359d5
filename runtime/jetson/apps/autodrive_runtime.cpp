// autodrive-runtime: runs the Jetson runtime components (Nano bridge, RPLIDAR driver,
// cameras, estimator), all of them or a subset (--only), each in its own thread with its own
// LCM instance. They talk only through LCM, so any split across processes behaves the same.
#include <CLI/CLI.hpp>
#include <spdlog/spdlog.h>

#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <set>
#include <sstream>
#include <thread>
#include <vector>

#include <autodrive/nano_bridge/nano_bridge.hpp>
#include <autodrive/camera/camera_driver.hpp>
#include <autodrive/core/config.hpp>
#include <autodrive/estimator/estimator_node.hpp>
#include <autodrive/rplidar/rplidar_driver.hpp>
#include <autodrive/v2v/v2v_node.hpp>

namespace {
std::atomic<bool> g_stop{false};
void on_signal(int) {
  g_stop = true;
}

// After SIGINT/SIGTERM every component has this long to return from run() [ms]; one that does
// not (blocked in a driver call) is named and the process exits anyway, so a stop takes at
// most about a second whatever a component is doing (systemd's TimeoutStopSec is 5 s).
constexpr int kStopGraceMs = 800;

struct Component {
  std::string name;
  std::function<void()> run;
  std::thread thread;
  std::atomic<bool> done{false};
};

// Runs the components until a signal, then waits for them; the process's exit code.
int run_until_signal(std::vector<std::unique_ptr<Component>> &components) {
  for (auto &c : components)
    c->thread = std::thread([p = c.get()] {
      p->run();
      p->done = true;
    });
  while (!g_stop) std::this_thread::sleep_for(std::chrono::milliseconds(20));
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::milliseconds(kStopGraceMs);
  std::string stuck;
  for (auto &c : components) {
    while (!c->done && std::chrono::steady_clock::now() < deadline)
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    if (c->done)
      c->thread.join();
    else
      stuck += (stuck.empty() ? "" : ", ") + c->name;
  }
  if (stuck.empty() && autodrive::camera::stuck_openers() == 0) {
    spdlog::info("autodrive-runtime: stopped");
    return 0;
  }
  // A thread blocked in a driver call cannot be joined, nor may static destructors run under
  // it: say which, and leave at once.
  spdlog::error("autodrive-runtime: {} did not stop within {} ms of the signal; exiting anyway",
                stuck.empty() ? "a camera open" : stuck, kStopGraceMs);
  spdlog::shutdown();
  std::fflush(nullptr);
  std::_Exit(1);
}
}  // namespace

int main(int argc, char **argv) {
  CLI::App app{
      "autodrive-runtime: the Nigel Jetson runtime (Nano bridge, RPLIDAR, cameras, "
      "EKF estimator) over LCM. The same binary drives the car, the simulator's ptys "
      "and the firmware in simavr: only the device paths in the config change."};
  std::string config_path, only, route, level = "info";
  app.add_option("--config", config_path, "YAML config (runtime/jetson/config/nigel_*.yaml)")
      ->required();
  app.add_option("--only", only,
                 "comma-separated subset of: bridge,lidar,camera,estimator,v2v (default: every "
                 "component with a section in the config; v2v with the estimator unless "
                 "v2v_hz is 0)");
  app.add_option("--route", route,
                 "the map's route this car drives, broadcast on V2V as its intent (overrides "
                 "the config's route)");
  app.add_option("--log-level", level, "trace, debug, info, warn, error")->capture_default_str();
  CLI11_PARSE(app, argc, argv);
  spdlog::set_level(spdlog::level::from_str(level));

  autodrive::config::Config config;
  try {
    config = autodrive::config::load(config_path);
  } catch (const autodrive::config::Error &e) {
    spdlog::error("bad config: {}", e.what());
    return 2;
  }
  if (!route.empty()) config.route = route;
  std::set<std::string> want;
  if (only.empty()) {
    if (config.has_bridge) want.insert("bridge");
    if (config.has_lidar) want.insert("lidar");
    if (!config.cameras.empty()) want.insert("camera");
    if (config.has_estimator) want.insert("estimator");
    if (config.has_estimator && config.v2v_hz > 0) want.insert("v2v");
  } else {
    std::stringstream ss(only);
    std::string item;
    while (std::getline(ss, item, ',')) {
      if (item != "bridge" && item != "lidar" && item != "camera" && item != "estimator" &&
          item != "v2v") {
        spdlog::error("--only: unknown component '{}' (bridge, lidar, camera, estimator, v2v)",
                      item);
        return 2;
      }
      want.insert(item);
    }
  }
  if (want.empty()) {
    spdlog::error("{}: no component to run (no bridge/lidar/cameras/estimator section)",
                  config.file);
    return 2;
  }

  // Build every component first so that a bad section fails before anything starts.
  std::vector<std::unique_ptr<Component>> runners;
  auto add = [&runners](const std::string &name, std::function<void()> run) {
    runners.push_back(std::make_unique<Component>());
    runners.back()->name = name;
    runners.back()->run = std::move(run);
  };
  std::unique_ptr<autodrive::bridge::NanoBridge> br;
  std::unique_ptr<autodrive::rplidar::Driver> lidar;
  std::unique_ptr<autodrive::estimator::EstimatorNode> estimator;
  std::unique_ptr<autodrive::v2v::V2vNode> v2v_node;
  std::vector<std::unique_ptr<autodrive::camera::CameraDriver>> cameras;
  auto check = [](const std::string &what, const std::string &err) {
    if (err.empty()) return true;
    spdlog::error("{}: {}", what, err);
    return false;
  };
  if (want.count("bridge")) {
    br = std::make_unique<autodrive::bridge::NanoBridge>(config);
    if (!check("bridge", br->init_error())) return 2;
    add("bridge", [&] { br->run(g_stop); });
  }
  if (want.count("lidar")) {
    lidar = std::make_unique<autodrive::rplidar::Driver>(config);
    if (!check("lidar", lidar->init_error())) return 2;
    add("lidar", [&] { lidar->run(g_stop); });
  }
  if (want.count("estimator")) {
    estimator = std::make_unique<autodrive::estimator::EstimatorNode>(config);
    if (!check("estimator", estimator->init_error())) return 2;
    add("estimator", [&] { estimator->run(g_stop); });
  }
  if (want.count("v2v")) {
    v2v_node = std::make_unique<autodrive::v2v::V2vNode>(config);
    if (!check("v2v", v2v_node->init_error())) return 2;
    add("v2v", [&] { v2v_node->run(g_stop); });
  }
  if (want.count("camera")) {
    if (config.cameras.empty()) {
      spdlog::error("{}: cameras: missing section", config.file);
      return 2;
    }
    for (std::size_t i = 0; i < config.cameras.size(); ++i) {
      cameras.push_back(std::make_unique<autodrive::camera::CameraDriver>(config, i));
      if (!check("camera", cameras.back()->init_error())) return 2;
      autodrive::camera::CameraDriver *c = cameras.back().get();
      add("camera " + config.cameras[i].channel.substr(1), [c] { c->run(g_stop); });
    }
  }
  std::signal(SIGINT, on_signal);
  std::signal(SIGTERM, on_signal);
  std::string names;
  for (const auto &w : want) names += (names.empty() ? "" : ",") + w;
  spdlog::info("autodrive-runtime {}: running {} on {}", config.vehicle.name, names,
               config.lcm_url);
  return run_until_signal(runners);
}
